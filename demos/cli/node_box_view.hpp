// The node-box view: after a frame is drawn, the boxes of the nodes the query scheduler
// decided on, coloured by decision (occluded, queried visible, history, occupancy, ...),
// plus a stats panel and a colour legend drawn with the built-in bitmap font.
#pragma once

#include <string>
#include <vector>

#include "dyncull/viewer/debug_draw.hpp"
#include "dyncull/engine/engine.hpp"
#include "dyncull/viewer/text_overlay.hpp"
#include "dyncull/scheduler/query_scheduler.hpp"

namespace dyncull::cli {

/// Which traced nodes get a box.
struct NodeBoxFilter {
    bool frustumCulled = false;  ///< off-screen boxes clutter the view and say little
    /// false: only final decisions (invisible nodes of any level, drawn leaves); true: also
    /// the visible inner nodes that were refined further.
    bool innerVisible = false;
    /// false: visible objects are shown as one box (their root's decision) and only culled
    /// local-BSP parts get boxes (hundreds of visible part boxes hide the picture); true: all parts.
    bool parts = false;
};

/// Colour of a decision in the node-box view (RGBA, chosen to read on the dark clear colour).
glm::vec4 nodeStateColour(NodeState s);

/// Owns the trace buffer and the GL overlays; needs the engine's context current for its
/// whole life. Borrows nothing between calls.
class NodeBoxView {
public:
    NodeBoxView() = default;

    /// Makes `scheduler` record its decisions of the next frames into this view (on) or
    /// stops it (off; tracing costs CPU time, so only trace while boxes are shown).
    void trace(QueryScheduler& scheduler, bool on) { scheduler.setTrace(on ? &trace_ : nullptr); }
    const std::vector<NodeTrace>& traced() const { return trace_; }

    /// Draws the traced nodes' boxes of the last frame over the engine's framebuffer (x-ray:
    /// hidden edges faded) and returns how many boxes were drawn.
    std::size_t drawBoxes(Engine& engine, const NodeBoxFilter& filter);
    /// Draws `lines` in a translucent panel at the top-left, and (if `legend`) the colour
    /// legend at the bottom-left; `help` (may be empty) goes at the bottom-right.
    void drawText(Engine& engine, const std::vector<std::string>& lines, bool legend, const std::string& help = {});

private:
    std::vector<NodeTrace> trace_;
    DebugDraw lines_;
    TextOverlay text_;
};

/// "fps 58.1  16.2 ms  full  queries 120  parts 340  tris 1.2M"-style number: 1234567 -> "1.23M".
std::string compactCount(double n);

}  // namespace dyncull::cli
