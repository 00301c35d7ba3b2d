// A streamed model (dyncull subdivide --memory-mb: a node file and a geometry file) as
// objects of an Engine whose geometry is read and uploaded only when a leaf is drawn, under
// two budgets: leaves in main memory (a LeafCache with read-ahead) and leaves in GL buffers
// (least recently drawn released first). Each leaf is one static object whose model is a
// unit box (Engine::addBoundsModel, shared by the leaves of one triangle count) scaled and
// placed on the leaf's box, so culling and queries never need the geometry.
// Paper: Out-of-core interactive display of large meshes using an oriented bounding
// box-based hardware depth query, section 5 (runtime memory management).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "dyncull/engine/engine.hpp"
#include "dyncull/streaming/leaf_cache.hpp"
#include "dyncull/streaming/streamed_model.hpp"

namespace dyncull {

/// What a frame does with a visible leaf whose geometry is not in main memory.
enum class StreamLate : std::uint8_t {
    Wait,  ///< read it at once and draw it: conservative, the stall is counted (default)
    Draw,  ///< skip it this frame, read it first, draw it in the first frame it is there
    Skip,  ///< skip it, and leave it to the read-ahead: measures the prediction alone
};
const char* toString(StreamLate late);
/// "wait", "draw" or "skip".
Expected<StreamLate> parseStreamLate(const std::string& name);

struct StreamingOptions {
    /// Leaf geometry in main memory, bytes (LeafCache budget; leaves are kept compact,
    /// CompactLeaf: 10 bytes a vertex, 6 or 12 a triangle). 0: every leaf is read at creation
    /// and stays (in core, the reference streaming is measured against).
    std::size_t memoryBytes = std::size_t{256} << 20;
    /// Leaf geometry in GL buffers, bytes; 0: no limit.
    std::size_t gpuBytes = std::size_t{64} << 20;
    StreamLate late = StreamLate::Wait;
    /// Read-ahead: the frustum of the camera moved on by its last motion, with the field of
    /// view widened by this factor (>= 1), is what the next frames may show.
    float widenFov = 1.3f;
};

/// One frame's streaming, from beginFrame to endFrame.
struct StreamingFrameStats {
    std::size_t memoryResidentBytes = 0;  ///< leaves in main memory at the end of the frame
    std::size_t gpuResidentBytes = 0;     ///< leaves in GL buffers at the end of the frame
    std::uint64_t bytesRead = 0;          ///< chunk bytes read from the geometry file (both threads)
    std::uint64_t loads = 0;
    std::uint64_t evictions = 0;          ///< from main memory
    std::uint64_t gpuEvictions = 0;
    std::uint64_t uploads = 0;
    /// Drawn leaves that were not in GL buffers and were found in main memory (hits) or not
    /// (misses): the read-ahead's record.
    std::uint64_t hits = 0, misses = 0;
    double stallMs = 0.0;      ///< reading leaves on the render thread (StreamLate::Wait)
    std::uint32_t late = 0;    ///< visible leaves not drawn for want of geometry (Draw, Skip)
    std::uint32_t overflow = 0;  ///< leaves drawn from a transient upload: GL budget full of this frame's leaves
};

/// Borrows the Engine (which must have EngineOptions::partRenderer) and sets its draw
/// callback, which points into this object; call beginFrame before and endFrame after each
/// frame. Destroy the Engine first (its renderer frees the uploaded leaves), or call
/// detach() and then destroy this first: the destructor itself never touches the Engine.
class StreamedObjects {
public:
    /// Reads and checks the node file (the geometry file is checked leaf by leaf as read)
    /// and adds one object per leaf. Errors: the files (naming them), a leaf larger than
    /// either budget, no part renderer, or the engine's own errors.
    static Expected<std::unique_ptr<StreamedObjects>> create(Engine& engine, const std::filesystem::path& nodePath,
                                                             const StreamingOptions& options);
    ~StreamedObjects();
    /// Clears the engine's draw callback and releases the leaves' GL buffers (the
    /// objects stay, drawn as their boxes). The context must be current.
    void detach();
    StreamedObjects(const StreamedObjects&) = delete;
    StreamedObjects& operator=(const StreamedObjects&) = delete;

    /// Before a frame drawn from `camera` (world space): hands the read-ahead its list of
    /// leaves not kept in GL buffers through the frame (only last frame's leaves are kept):
    /// those drawn last frame first, then those in the current or
    /// predicted frustum, ordered by the main view's culler history (most recently visible,
    /// then tested hidden last frame) and then nearest first. A culler without history for
    /// the leaves (another scheduler culls them) leaves the order nearest first.
    void beginFrame(const Camera& camera);
    /// After the frame (renderFrame or several views of it): its streaming counters, or the
    /// first error a draw met (a corrupt leaf, naming the file and the leaf).
    Expected<StreamingFrameStats> endFrame();

    /// Changes what a frame does with late leaves from now on (a measurement's reference
    /// pass waits for every leaf while the measured modes skip).
    void setLate(StreamLate late);
    const StreamedModel& model() const;
    /// The leaf an object of this set shows, if it is one.
    std::optional<std::uint32_t> leafOf(ObjectHandle object) const;
    /// The leaf the object in slot `slot` shows, if it is one of this set's.
    std::optional<std::uint32_t> leafOfSlot(std::uint32_t slot) const;
    /// Reads a leaf straight from the file, outside both budgets and counters (ground truth),
    /// as the draws show it (through its compact form: positions within half a 16-bit step of
    /// the file's; compact_leaf.hpp).
    Status readLeaf(std::uint32_t leaf, Mesh& out) const;
    /// Totals since creation.
    const LeafCacheStats cacheStats() const;
    std::size_t peakGpuBytes() const;

private:
    struct State;
    explicit StreamedObjects(std::unique_ptr<State> s);
    std::unique_ptr<State> s_;
};

}  // namespace dyncull
