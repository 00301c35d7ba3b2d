// The scheduler's view of an occlusion-query implementation. The core never includes
// OpenGL: engine/ provides the GL backend (GL_ANY_SAMPLES_PASSED_CONSERVATIVE or
// GL_SAMPLES_PASSED with a threshold); tests provide scripted and software backends.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/bsp/traversal.hpp"
#include "dyncull/bsp/node_volumes.hpp"
#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/camera.hpp"

namespace dyncull {

/// Three states: a query either answered or has not answered yet. Nothing blocks on
/// NotReady while other work is possible.
enum class QueryResult : std::uint8_t { NotReady, Visible, Occluded };

/// A convex query volume in world space, drawn with colour and depth writes off. Either a
/// box — 8 corners, corner i with x from bit 0, y from bit 1, z from bit 2 (an AABB, or a
/// transformed local box or PCA box: a parallelepiped), the fast path — or a convex
/// triangle mesh of up to 48 vertices and 92 triangles (a k-DOP boundary). Holds its data
/// by value (no borrowed pointers), so backends may keep copies.
struct QueryVolume {
    static constexpr std::uint32_t kMaxVertices = 48;
    static constexpr std::uint32_t kMaxTriangles = 92;

    std::array<glm::vec3, kMaxVertices> vertices;  ///< world space, [0, vertexCount) used
    std::uint32_t vertexCount = 0;
    /// 3 per triangle, into `vertices`, counter-clockwise seen from outside (backends do
    /// not rely on it: the GL backend winds each face outward from the centre itself);
    /// [0, 3 * triangleCount) used. 0 triangles: a box.
    std::array<std::uint8_t, 3 * kMaxTriangles> indices;
    std::uint32_t triangleCount = 0;

    bool isBox() const { return triangleCount == 0; }
    /// The used vertices (the 8 corners of a box).
    std::span<const glm::vec3> points() const { return {vertices.data(), vertexCount}; }
    /// The triangles: kBoxTriangles for a box.
    std::span<const std::uint8_t> triangles() const;

    static QueryVolume fromAabb(const Aabb& box);
    /// The object-space box `local` under the affine `objectToWorld` (exact, not re-bounded).
    static QueryVolume fromTransformedBox(const glm::mat4& objectToWorld, const Aabb& local);
    /// A stored node volume (object space, `volumes` owns its data) under the affine
    /// `objectToWorld`: vertices transformed, triangles kept (k-DOP paper, section 3.3).
    /// An empty node volume gives an empty box (vertexCount 0) — callers query such nodes by AABB.
    static QueryVolume fromNodeVolume(const glm::mat4& objectToWorld, const NodeVolumes& volumes, const NodeVolume& v);

    /// The volume grown to cover the float rounding its world coordinates may carry (2 ulp,
    /// 2^-22 of the largest magnitude, per coordinate), as points relative to `eye` in
    /// double: scaled about its centre so that every face moves out by at least that much;
    /// or, thinner than a few roundings, the 8 corners of its vertices' box, each face
    /// pushed out along its axis (`asBox` is then set). Returns the number of points
    /// written. What a backend draws and a CPU test projects, so neither is ever smaller
    /// than the geometry the volume bounds, at 1e7 from the origin too.
    std::uint32_t enlargedForRounding(const glm::dvec3& eye, std::array<glm::dvec3, kMaxVertices>& out, bool& asBox) const;
};

using QueryId = std::uint32_t;
/// Returned by a backend that cannot query a draw (QueryBackend::beginDrawQuery).
inline constexpr QueryId kNoQuery = 0xffffffffu;

using BatchId = std::uint32_t;
/// A sample count that is not known (QueryBackend::collectVolumes): treat as "many".
inline constexpr std::uint32_t kUnknownSamples = 0xffffffffu;
/// Returned by a backend without the batched raster test (QueryBackend::testVolumes).
inline constexpr BatchId kNoBatch = 0xffffffffu;

class QueryBackend {
public:
    virtual ~QueryBackend() = default;

    /// Start of a frame: the view whose camera-relative view-projection query volumes are
    /// drawn with, and the viewport in pixels (FrameView, derived once per frame).
    virtual void beginFrame(const FrameView& view) = 0;
    /// Brackets a group of queries issued together, so state (colour/depth masks,
    /// the volume shader) is switched once per batch rather than once per query.
    virtual void beginBatch() = 0;
    /// Draws `volume` depth-tested against what is drawn so far. A backend may draw it
    /// enlarged (GlQueryBackend does, to cover float rounding far from the origin); one that
    /// would then reach the near plane must answer Visible without drawing. The scheduler
    /// queries no box within 2^-21 of its coordinates of the near plane (QueryScheduler::projectRect).
    virtual QueryId issue(const QueryVolume& volume) = 0;
    virtual void endBatch() = 0;
    /// Non-blocking.
    virtual QueryResult poll(QueryId id) = 0;
    /// Blocks until the result is available or `timeoutMs` passed; a result that never
    /// arrives within the bound is reported Visible (never cull, never stall forever).
    virtual QueryResult wait(QueryId id, double timeoutMs) = 0;
    /// Returns the query object to the backend's pool. Every issued id is released once.
    virtual void release(QueryId id) = 0;
    /// Number of samples that passed for an answered query (0 if unknown). Used by
    /// threshold settings and statistics.
    virtual std::uint64_t samples(QueryId) const { return 0; }
    /// A query on the geometry itself (coherent hierarchical culling's query on a
    /// previously visible leaf): counts the samples of what is drawn through the PartSink
    /// until endDrawQuery, with the same answer rule as issue(). Outside a batch, one at a
    /// time; answered, released and timed out like any query. kNoQuery if the backend
    /// cannot (the default), and the scheduler then relies on visibility history alone.
    virtual QueryId beginDrawQuery() { return kNoQuery; }
    virtual void endDrawQuery(QueryId) {}
    /// Reads the depth of everything drawn so far this frame into `depth` (width x height
    /// window depths, reversed Z, rows from the bottom; resized as needed), waiting for
    /// the drawing to finish. false if the backend cannot (the default): the two-phase mode
    /// then culls nothing by occlusion.
    virtual bool readDepth(std::vector<float>& depth, int& width, int& height) {
        (void)depth, (void)width, (void)height;
        return false;
    }
    /// Blocks until everything submitted so far has been drawn (glFinish). Only for
    /// measurement (SchedulerTuning::splitDrawWaits); the default returns at once.
    virtual void finishDrawing() {}
    /// The batched raster test (NVIDIA's gl_occlusion_culling sample): every volume is
    /// drawn in one pass against the depth drawn so far, and each fragment that passes
    /// marks its volume visible. The answer rule is issue()'s (exact per pixel, enlarged
    /// volumes, a volume reaching the near plane is Visible), but hundreds of volumes cost
    /// one draw and one small readback. Outside a batch and a draw query. The volumes are
    /// copied; kNoBatch if the backend cannot (the default). With `countSamples` each
    /// volume's passing samples are counted too (collectVolumes' `samples`), which the
    /// error budget needs; a count costs an atomic add per fragment instead of a store.
    virtual BatchId testVolumes(std::span<const QueryVolume> volumes, bool countSamples = false) {
        (void)volumes, (void)countSamples;
        return kNoBatch;
    }
    /// Collects a batch into `out` (one entry per volume, in order: Visible or Occluded)
    /// and releases it, returning true. With `waitMs` 0 it never blocks and returns false
    /// while the answer is not ready; with `waitMs` > 0 it waits that long and then answers
    /// every volume Visible (never cull, never stall forever). Every batch is collected once.
    /// `samples`, if not empty (one per volume), gets each volume's samples that passed the
    /// depth test when the batch counted them: at least the pixels of anything inside the
    /// volume that the depth drawn so far leaves visible. kUnknownSamples for a volume whose
    /// count is unknown (not counted, reaching the near plane, not drawn, timed out).
    virtual bool collectVolumes(BatchId id, std::span<QueryResult> out, double waitMs,
                                std::span<std::uint32_t> samples = {}) {
        (void)id, (void)out, (void)waitMs, (void)samples;
        return false;
    }
};

/// A part as drawn: `part` names the object slot of SceneObjects and the local-BSP node
/// (a leaf, or an inner node whose whole subtree is drawn at once), and [firstIndex,
/// firstIndex + indexCount) is that node's range of its model's split mesh.
struct PartRange {
    NodeRef part;
    std::uint32_t firstIndex = 0;
    std::uint32_t indexCount = 0;
};

/// A range [firstIndex, firstIndex + indexCount) of a model's split mesh.
struct IndexRange {
    std::uint32_t firstIndex = 0;
    std::uint32_t indexCount = 0;
};

/// What the scheduler calls to draw an object part. A sink that draws the parts itself
/// (the engine's part renderer) may also test them on their own triangles, the strictest
/// conservative test there is: a part none of whose fragments passes the depth test now
/// shows nothing if drawn later, since depth only grows nearer.
class PartSink {
public:
    virtual ~PartSink() = default;
    virtual void drawPart(NodeRef part, std::uint32_t firstIndex, std::uint32_t indexCount) = 0;

    /// Whether drawPartRanges draws several ranges as cheaply as one (a multi-draw), so the
    /// scheduler may draw a part as its surviving clusters (false: the default, e.g. a
    /// game's own draws, which get whole parts).
    virtual bool drawsRanges() const { return false; }
    /// Draws part `part` as `ranges`: ascending, disjoint, non-empty, all inside the part's
    /// own range (its clusters that survived the scheduler's tests). The part counts as
    /// drawn once, with draw marks as drawPart's.
    virtual void drawPartRanges(NodeRef part, std::span<const IndexRange> ranges) {
        for (const IndexRange& r : ranges) drawPart(part, r.firstIndex, r.indexCount);
    }
    /// Draws more `ranges` of a part that drawPartRanges drew earlier this frame (the late
    /// pass's share of its clusters: SchedulerFeatures::useClusterHistory), as
    /// drawPartRanges draws them, without counting the part again. Only called where
    /// drawsRanges() is true; the default draws them through drawPartRanges.
    virtual void drawMorePartRanges(NodeRef part, std::span<const IndexRange> ranges) { drawPartRanges(part, ranges); }
    /// Whether models with FaceMode::CullBack are drawn with their back faces culled now, so
    /// a cluster facing away from the eye shows nothing (false: the default).
    virtual bool cullsBackFaces() const { return false; }

    /// Whether the two calls below work, where drawsRanges() does (false: the default).
    virtual bool marksRanges() const { return false; }
    /// From now until readRangeMarks, every range drawn by drawPartRanges and
    /// drawMorePartRanges also records whether any of its fragments passed the depth test as
    /// it was drawn (drawPart's draws record nothing): which clusters of a part showed.
    virtual void beginRangeMarks() {}
    /// Those records, one per range drawn since beginRangeMarks, in call and range order:
    /// Visible if a fragment passed, else Occluded; ends the marking. Waits for the drawing.
    virtual void readRangeMarks(std::span<QueryResult> out) { std::fill(out.begin(), out.end(), QueryResult::Visible); }

    /// Whether the three calls below work (false: the default, e.g. a game's own draws).
    virtual bool testsTriangles() const { return false; }
    /// From now to the end of the frame, every drawPart also records whether any fragment
    /// of the part passed the depth test as it was drawn: the batched counterpart of a
    /// query on the draw.
    virtual void beginDrawMarks() {}
    /// Those records, one per drawPart since beginDrawMarks in call order: Visible if a
    /// fragment passed, else Occluded. Waits for the drawing. `out` has one entry per draw.
    virtual void readDrawMarks(std::span<QueryResult> out) { std::fill(out.begin(), out.end(), QueryResult::Visible); }
    /// Draws `parts` as drawPart would (the same positions, the same face culling) with
    /// colour and depth writes off, against the depth drawn so far, and answers in `out`
    /// (one per part, in order; waits for the drawing): Visible if any fragment passed.
    /// Nothing is drawn into the image. A sink that cannot answers Visible.
    virtual void testParts(std::span<const PartRange> parts, std::span<QueryResult> out) {
        (void)parts;
        std::fill(out.begin(), out.end(), QueryResult::Visible);
    }
};

}  // namespace dyncull
