// The interactive viewer behind `dyncull run SCENE --window`: follow the scene's camera path
// or fly freely, switch culling modes and ablation switches at run time, and show the
// node-box view and a stats line. Input comes from an InputSource so a test can script it.
//
// Keys: 1/2/3 vfc/simple/full; P path <-> free flight (starts on the path); B node boxes;
// F frustum-culled boxes; I refined inner boxes; L local-BSP part boxes; H/O/T history/occupancy/tight volumes
// (full mode); WASD move, Q/C down, E/Space up, right mouse button or M held/toggled for
// mouse look, Shift x4 / Ctrl x1/4 speed while held, +/- change base speed; Esc quits.
//
// Each mode has its own QueryScheduler, so switching keeps every mode's visibility history
// (switching back to full resumes with warm history instead of re-querying everything).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "dyncull/viewer/window_context.hpp"
#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/engine/engine.hpp"
#include "dyncull/viewer/input.hpp"
#include "node_box_view.hpp"

namespace dyncull::cli {

/// Where the viewer's input comes from, one InputFrame per rendered frame.
class InputSource {
public:
    virtual ~InputSource() = default;
    virtual InputFrame poll() = 0;
    /// Mouse look: hide and lock the cursor (false releases it). Only windows have one.
    virtual void setCursorCaptured(bool /*captured*/) {}
};

/// Input of a window (WindowContext::takeInput).
class ContextInput final : public InputSource {
public:
    explicit ContextInput(WindowContext& window) : window_(window) {}
    InputFrame poll() override { return window_.takeInput(); }
    void setCursorCaptured(bool captured) override { window_.setCursorCaptured(captured); }

private:
    WindowContext& window_;
};

/// A fixed script: the key presses of each frame (frame 0 = the first poll) and keys held
/// over frame ranges; everything else is idle. For tests and demos.
class ScriptedInput final : public InputSource {
public:
    void pressAt(std::uint64_t frame, Key key) { presses_.push_back({frame, key}); }
    /// Holds `key` during frames [first, last].
    void holdDuring(std::uint64_t first, std::uint64_t last, Key key) { holds_.push_back({first, last, key}); }
    void mouseAt(std::uint64_t frame, glm::vec2 delta, bool rightButton) { mouse_.push_back({frame, delta, rightButton}); }
    InputFrame poll() override;

private:
    struct Press { std::uint64_t frame; Key key; };
    struct Hold { std::uint64_t first, last; Key key; };
    struct Mouse { std::uint64_t frame; glm::vec2 delta; bool right; };
    std::vector<Press> presses_;
    std::vector<Hold> holds_;
    std::vector<Mouse> mouse_;
    std::uint64_t frame_ = 0;
};

struct InteractiveOptions {
    SchedulerParams params;       ///< starting mode and switches (shared by the modes)
    std::uint64_t maxFrames = 0;  ///< stop after this many frames (0: until Esc or the window closes)
    bool boxes = false;           ///< start with the node-box view on
    bool text = true;             ///< stats panel, legend and help
};

/// What the viewer is doing; read after each step by tests and by the caller's summary.
struct InteractiveState {
    CullMode mode = CullMode::TwoPhase;
    bool followPath = true;
    bool boxes = false;
    bool mouseLook = false;          ///< M toggle (the right button also looks while held)
    NodeBoxFilter filter;
    bool useHistory = true, useOccupancy = true, useTight = true;
    std::uint64_t framesRendered = 0;
    std::uint64_t sceneFrame = 0;    ///< animation clock: advances every frame
    std::uint64_t pathFrame = 0;     ///< camera-path position: advances only while following
    Camera camera;                   ///< camera of the last frame, world space
    float speedScale = 1.0f;         ///< +/- multiplier of the base flight speed
    FrameStats last;
    double fps = 0.0;                ///< smoothed over recent frames (wall clock between steps)
    std::size_t boxesDrawn = 0;
    bool quit = false;
};

/// Owns one QueryScheduler per mode and the overlays; borrows the engine and scene, which
/// must outlive it (the engine's context current on every call).
class InteractiveViewer {
public:
    InteractiveViewer(Engine& engine, DemoScene& scene, const InteractiveOptions& options);

    /// One frame: apply `input`, move the scene and the camera (`dtSeconds` of wall time
    /// drive free flight), render with the current mode, draw the overlays. Does not present.
    /// Errors come from the scene (update/camera) and leave the viewer usable.
    Status step(const InputFrame& input, double dtSeconds);

    const InteractiveState& state() const { return state_; }
    /// Flight speed with no modifier held, world units per second (from the scene's size).
    float baseSpeed() const { return baseSpeed_; }

private:
    void applyKeys(const InputFrame& input);
    void fly(const InputFrame& input, double dt);
    SchedulerParams paramsFor(CullMode mode) const;
    std::vector<std::string> statsLines() const;

    Engine& engine_;
    DemoScene& scene_;
    InteractiveOptions options_;
    InteractiveState state_;
    std::array<std::unique_ptr<QueryScheduler>, kCullModeCount> schedulers_;  // indexed by CullMode
    NodeBoxView view_;
    float yaw_ = 0.0f, pitch_ = 0.0f;  // free-flight orientation, radians
    float baseSpeed_ = 1.0f;
};

/// Runs the viewer until Esc, the window's close button, or options.maxFrames; presents
/// each frame. Returns the frames rendered, or the first scene error.
Expected<std::uint64_t> runInteractive(GlContext& context, Engine& engine, DemoScene& scene, InputSource& input,
                                       const InteractiveOptions& options, InteractiveState* finalState = nullptr);

}  // namespace dyncull::cli
