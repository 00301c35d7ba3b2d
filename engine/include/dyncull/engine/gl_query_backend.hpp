// Hardware occlusion queries for the scheduler: each query volume (8 world-space box
// corners, or a convex mesh such as a k-DOP) is drawn with colour and depth writes off
// inside a GL query.
// Conservative by default (GL_ANY_SAMPLES_PASSED_CONSERVATIVE); with a visible-pixel
// threshold N > 0 it uses GL_SAMPLES_PASSED and calls a node visible only if more than
// N samples passed (an approximate setting: it may drop up to N pixels per node).
#pragma once

#include <cstdint>
#include <memory>
#include <deque>
#include <vector>

#include "dyncull/engine/frame_contract.hpp"
#include "dyncull/objects/error.hpp"
#include "dyncull/scheduler/query_backend.hpp"

namespace dyncull {

class GlContext;
namespace detail {
class VolumeTestState;
class BatchedRasterTest;
struct VolumeView;
}  // namespace detail

/// What a volume test adds around a volume's outline for the rasteriser's vertex snapping.
enum class SnappingMargin : std::uint8_t {
    /// Boxes grown across the view direction (their faces facing the eye stay put), other
    /// volumes ringed: the default, and half a box test's triangles.
    GrowBoxes,
    /// Every volume ringed: a flat strip along its screen outline at its nearest depth.
    Ring,
    /// Nothing: not conservative, only to measure what the margin costs and catches.
    None,
};

struct GlQueryParams {
    std::uint32_t visiblePixelThreshold = 0;  ///< 0 = conservative (any sample passes)
    /// glFlush at the end of every batch so the GPU starts on the queries while the CPU
    /// traverses on. On llvmpipe each flush ends a binned scene; off, the first poll of
    /// the batch submits it instead.
    bool flushAfterBatch = true;
    /// How each volume's screen outline is widened by a few 1/256 pixel, because the
    /// rasteriser's vertex snapping can let a part cover a pixel centre just outside its
    /// tight volume's outline (detail::prepareVolume).
    SnappingMargin snapping = SnappingMargin::GrowBoxes;
};

/// Owns GL query objects, a streaming vertex buffer for volumes and a depth-only program.
/// Needs its GL context current whenever it is called; destroyed with another context
/// current, it deletes nothing (its objects die with their own context). Queries are issued
/// against whatever framebuffer is bound, with its depth buffer.
class GlQueryBackend final : public QueryBackend {
public:
    static Expected<std::unique_ptr<GlQueryBackend>> create(GlContext& context, GlQueryParams params = {});
    ~GlQueryBackend() override;

    void beginFrame(const FrameView& view) override;
    void beginBatch() override;
    QueryId issue(const QueryVolume& volume) override;
    void endBatch() override;
    QueryResult poll(QueryId id) override;
    QueryResult wait(QueryId id, double timeoutMs) override;
    void release(QueryId id) override;
    std::uint64_t samples(QueryId id) const override;
    QueryId beginDrawQuery() override;
    void endDrawQuery(QueryId id) override;
    /// glReadPixels of the target's depth inside its viewport (waits for the drawing so far);
    /// false (no early depth) if no target was set or its depth cannot be read (setTarget).
    /// The read framebuffer, pixel-pack buffer and pack parameters are restored.
    bool readDepth(std::vector<float>& depth, int& width, int& height) override;
    void finishDrawing() override;
    /// Where readDepth reads from: the framebuffer and viewport the frame draws into (the
    /// Engine passes the caller's, frame_contract.hpp). Queries and batched tests need no
    /// target: they draw into whatever framebuffer is bound.
    void setTarget(const FrameTarget& target) { target_ = target; hasTarget_ = true; }
    /// The batched raster test: one draw of all volumes into a visibility buffer, read
    /// back once its fence has signalled (batched_raster_test.cpp).
    BatchId testVolumes(std::span<const QueryVolume> volumes, bool countSamples = false) override;
    bool collectVolumes(BatchId id, std::span<QueryResult> out, double waitMs, std::span<std::uint32_t> samples = {}) override;

    const GlQueryParams& params() const { return params_; }
    void setParams(const GlQueryParams& p) { params_ = p; }
    std::size_t poolSize() const { return queries_.size(); }
    std::size_t inUse() const { return queries_.size() - free_.size(); }
    /// Error if the volume buffers could not be (re)allocated in the current frame
    /// (GL_OUT_OF_MEMORY): from then until the next beginFrame every issue() returns a
    /// query that is already Visible without touching GL (never culls, never waits), and
    /// the next beginFrame allocates again at the last size that worked.
    const Status& frameStatus() const { return frameStatus_; }

private:
    GlQueryBackend(GlContext& context, GlQueryParams params);
    QueryResult fetch(QueryId id);
    QueryId acquireSlot();
    /// A free query object for the current threshold's target, marked live and unanswered.
    QueryId startQuery();
    /// A query that is already answered Visible, drawing nothing.
    QueryId answeredVisible();
    /// (Re)allocates a streaming buffer with glNamedBufferData; on failure records the
    /// error in frameStatus_ and enters the degraded state.
    bool allocate(std::uint32_t buffer, std::size_t bytes, const char* what);

    struct Slot {
        std::uint32_t name = 0;  // GL query object
        std::uint32_t target = 0;  // GL_ANY_SAMPLES_PASSED_CONSERVATIVE or GL_SAMPLES_PASSED
        std::uint64_t samples = 0;
        std::uint64_t begun = 0;        // serial of its last glBeginQuery (0: never begun)
        std::uint64_t releaseMark = 0;  // beginSerial_ when it was last released
        QueryResult result = QueryResult::NotReady;
        bool live = false;
    };
    GlContext& context_;
    GlQueryParams params_;
    std::vector<Slot> queries_;
    // Released slots, oldest first. A slot's GL query object is begun again only once a
    // query begun after its release has answered (answeredSerial_ > releaseMark). Mesa
    // llvmpipe (22.3) frees a scene's fence when its last reference goes, and a reused
    // query drops one, but it learns the fence is complete from a counter read without
    // the fence's mutex while a rasteriser thread may still be signalling it: reusing the
    // query at once let that thread write into freed memory (heap corruption). A query
    // begun after the release lies in a later scene, so its answer proves every thread
    // has left the earlier fence (docs/RELIABILITY.md, "Heap corruption in llvmpipe").
    std::deque<QueryId> free_;
    std::uint64_t beginSerial_ = 0;     // glBeginQuery calls so far
    std::uint64_t answeredSerial_ = 0;  // largest `begun` of a query seen answered
    std::uint32_t program_ = 0, vao_ = 0, vbo_ = 0, ibo_ = 0;
    int locViewProj_ = -1;
    std::uint32_t vboCapacity_ = 0;  // vertices
    std::uint32_t vboUsed_ = 0;      // vertices written this frame
    std::uint32_t iboCapacity_ = 0;  // 8-bit indices
    std::uint32_t iboUsed_ = 0;      // indices written this frame
    glm::mat4 viewProj_{1.0f};       // camera-relative (Camera::viewProjectionRelative)
    std::unique_ptr<detail::VolumeView> view_;  // this frame's camera; volumes are uploaded relative to its eye
    int subpixelBits_ = 4;                      // GL_SUBPIXEL_BITS (4 is GL's minimum)
    std::unique_ptr<detail::VolumeTestState> rasterState_;  // entered by beginBatch, left by endBatch
    std::unique_ptr<detail::BatchedRasterTest> batches_;    // testVolumes / collectVolumes
    std::vector<QueryId> batchQuery_;  // per batch in flight: the query bracketing its draw
    bool inBatch_ = false;
    bool inDrawQuery_ = false;
    bool degraded_ = false;  // an allocation failed this frame: queries answer Visible
    Status frameStatus_;
    FrameTarget target_;
    bool hasTarget_ = false;
};

}  // namespace dyncull
