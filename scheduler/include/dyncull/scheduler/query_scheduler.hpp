// Front-to-back occlusion culling of the two-level hierarchy with hardware queries:
// the active-node list (scene and object nodes together, refined as traversal proceeds),
// the first visibility test, visibility history, batched queries with non-overlapping
// screen rectangles, the occupancy-map fast accept, and tightened query volumes.
// Papers: Two-level BSP for dynamic occlusion culling, section 3.3-3.4, Algorithms 2-4;
// Staneker et al., Efficient Multiple Occlusion Queries, sections 3-4.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "dyncull/bsp/traversal.hpp"
#include "dyncull/objects/camera.hpp"
#include "dyncull/objects/error.hpp"
#include "dyncull/objects/volume_kind.hpp"
#include "dyncull/scheduler/frame_stats.hpp"
#include "dyncull/scheduler/depth_pyramid.hpp"
#include "dyncull/scheduler/occupancy_map.hpp"
#include "dyncull/scheduler/query_backend.hpp"
#include "dyncull/scheduler/visibility_history.hpp"

namespace dyncull {

/// The culling modes; the CLI names them by toString (parseCullMode reads them back).
enum class CullMode : std::uint8_t {
    Vfc,     ///< `vfc`: frustum culling only
    Simple,  ///< `simple`: the paper's Simple OC, one stop-and-wait query per node in the frustum
    /// `queries`: hardware occlusion queries scheduled as in the two-level paper, with
    /// visibility history, batching, occupancy maps, tight volumes and draw queries, each
    /// switchable for ablation; the approximate settings apply to it. It was `full` until
    /// TwoPhase culled more for less on every bundled scene (docs/BENCHMARKS.md).
    Queries,
    /// `full`, the default conservative mode: the two-phase method of GPU-driven engines.
    /// Draw last frame's visible parts, read the depth back into a farthest-depth pyramid,
    /// test every node against it on the CPU, test what it cannot reject in one batched
    /// raster test, draw what is newly visible (QueryBackend::readDepth and testVolumes;
    /// without them nothing is culled).
    TwoPhase,
};
inline constexpr int kCullModeCount = 4;
const char* toString(CullMode m);
Expected<CullMode> parseCullMode(const std::string& s);

/// Which parts of the method run. The defaults are the method as measured best; each
/// switch turned off is an ablation, and none of them trades pixels for speed.
struct SchedulerFeatures {
    // useHistory for Queries and TwoPhase, the next three for Queries.
    bool useHistory = true;
    bool useBatching = true;
    bool useOccupancyAccept = true;
    bool useTightVolumes = true;
    /// A node waiting for a query (its rectangle overlaps a pending one) also holds back
    /// every farther node whose rectangle overlaps it, so no node is queried before a
    /// nearer waiting node in front of it is resolved. Draws 3-12% fewer triangles but
    /// waits 1.4-4x as long: from as fast to 23% slower on llvmpipe (docs/BENCHMARKS.md),
    /// hence off; a GPU, where overdraw costs more than a stall, may differ.
    bool useWaitOrder = false;
    /// Every part drawn without a query of its own (history, occupancy, near plane,
    /// front-most) is drawn inside a query on its geometry; next frame a part whose
    /// geometry drew no sample is queried again instead of being skipped by history.
    /// Coherent hierarchical culling's query on previously visible leaves (Bittner et al.
    /// 2004, which the two-level paper cites): it catches visible -> hidden at once
    /// instead of after up to history.maxSkipFrames frames, with no volume to rasterise.
    bool useDrawQueries = true;
    /// TwoPhase: a part the depth pyramid cannot reject goes to the backend's batched
    /// raster test (QueryBackend::testVolumes), exact per pixel, before it is drawn; and
    /// the parts drawn early are tested again against the frame's final depth, so a part
    /// that turned hidden is not drawn early next frame. Off: such parts are drawn (the
    /// pyramid alone, an ablation).
    bool useBatchedRaster = true;
    /// TwoPhase, where the PartSink can (PartSink::testsTriangles: the engine's part
    /// renderer): a part that the volume tests let through is tested on its own triangles
    /// before it is drawn (where the cost model expects it to pay), and every draw is
    /// marked with whether it showed a sample, which replaces the volume test against the
    /// final depth. The exact test on the geometry itself, where a volume around it peeks
    /// out from behind occluders the part does not. Off by default: on llvmpipe a test
    /// costs 1.3x drawing the same triangles and a marked draw 1.2x a plain one, so it
    /// loses there (docs/BENCHMARKS.md); it pays where shading, not triangle set-up, is
    /// what drawing costs.
    bool useTriangleTests = false;
    /// Every mode, where the PartSink draws index ranges (PartSink::drawsRanges: the
    /// engine's part renderer): a part is drawn as those of its clusters (leaf_clusters.hpp)
    /// that survive three tests too cheap to need a query, in one multi-draw: facing away
    /// from the eye (the normal cone, for models whose back faces the sink culls), outside
    /// the frustum (for parts crossing it), and, in TwoPhase's late pass, behind the depth
    /// pyramid. Conservative like the part tests: a culled cluster shows no pixel. The cost
    /// model weighs `clusterTestNs` per cluster against the drawing it saves, at each
    /// model's measured rate. Off: whole parts (an ablation).
    bool useClusters = true;
    /// TwoPhase with clusters: the early set at cluster level. Each part drawn early is
    /// drawn as only those clusters whose boxes showed in the final depth of the frame it
    /// was last drawn in (VisibilityHistory::clusterBits, written at each frame's end from a
    /// pyramid of the final depth); its other clusters wait for the late pass, which draws
    /// those the early pass's pyramid cannot reject. The early depth is drawn from fewer
    /// triangles; nothing is culled that the late pass did not test, so it stays
    /// conservative. Costs a second depth readback per frame that tests. Off: parts drawn
    /// early whole (an ablation).
    bool useClusterHistory = true;
    /// Cluster history, where the PartSink marks ranges (PartSink::marksRanges: the engine's
    /// part renderer on a GL with ARB_shader_draw_parameters): a cluster's bit says whether
    /// any of its fragments passed the depth test when it was drawn, instead of whether its
    /// box showed in the final depth. Exact per pixel at draw time, and no second depth
    /// readback; but off by default, since it loses: a cluster whose box peeks past its
    /// occluders while its triangles do not is deferred, the late pass's box test cannot
    /// reject it either, so it is drawn late anyway, after an early pass whose depth now
    /// lacks it (on issue 21's swarm half the early triangles, 1.3x the triangles in all;
    /// docs/BENCHMARKS.md). An ablation, bench mode full-markclusterhist.
    bool useClusterMarks = false;
    /// TwoPhase with cluster history: the late pass's deferred clusters are tested on a
    /// worker thread while the render thread runs the late traversal and its draws (they
    /// depend only on the early pyramid), instead of part by part as they are drawn; and
    /// the frame-end record's tests are shared with a second thread. The same decisions
    /// either way; off: on the render thread (the reference).
    bool useClusterWorker = true;
    /// TwoPhase with clusters: before the parts a round of raster tests let through are
    /// drawn, the pyramid is built again from the depth drawn so far (which that round's
    /// answer has waited for already), so their clusters are tested against it rather
    /// than the early pass's depth. Off: an ablation, bench mode full-noroundpyramid.
    bool useRoundPyramids = true;
    /// TwoPhase: a part tested with its PCA box is projected as a box in the box's own
    /// frame (objectNodeObbFrame), so its per-texel test has the box's front faces' planes
    /// and outline, as an axis-aligned box has, rather than its nearest depth over its
    /// whole footprint rectangle. Off: an ablation, bench mode full-obbpoints.
    bool useObbFrames = true;
    /// TwoPhase with cluster history: once the late pass has drawn the early parts'
    /// deferred clusters (the surfaces that came into view since last frame), the pyramid
    /// is built again from that depth, and the parts waiting for the batched raster test
    /// are tested against it first: on the bunny path nine in ten are hidden behind what
    /// was just drawn, and their footprints are kept from the late traversal, so a test
    /// there costs a fraction of a batched raster test's (TestCosts::testNsPerVolume).
    /// Priced as a round pyramid. Off: an ablation, bench mode full-nolatepyramid.
    bool useLatePyramid = true;
    /// TwoPhase (and clusters): test only where SchedulerTuning::costs expects the test to
    /// pay. Off: every volume the pyramid lets through is tested (an ablation).
    bool useCostModel = true;
    /// TwoPhase with the cost model: while tests are off, the probe every
    /// TestCosts::probeFrames frames draws as an untested frame does and then tests every
    /// part it drew against a pyramid of the final depth; the triangles of those hidden
    /// there are what testing would have saved. Off: the probe is a frame that tests
    /// (early pass, depth read, late pass, raster tests), whose stall costs a frame of a
    /// scene with little to cull about 1.2-1.3x vfc's time (an ablation, bench mode
    /// full-testprobe).
    bool useEndProbes = true;
    /// TwoPhase: where cluster history's record reads the final depth anyway, the parts
    /// drawn early are tested for next frame against that read's pyramid (each volume as
    /// the end probe tests it), not in a batched raster test: one readback and one batch a
    /// frame fewer, for the pyramid's coarser answer (a part it cannot reject is only drawn
    /// early next frame, never culled). Off: the batched raster test, exact per pixel (an
    /// ablation, bench mode full-rasterrefresh).
    bool useRefreshPyramid = true;
    /// TwoPhase with cluster history's record: the record takes what the frame's own
    /// cluster tests learned (a cluster facing away, outside the frustum or behind an
    /// earlier pyramid is hidden in the final depth too, since depth only grows nearer; one
    /// that passed keeps its footprint) and projects only the clusters nobody tested, those
    /// drawn early. Off: the record projects every cluster again (an ablation, bench mode
    /// full-ownrecord).
    bool useLearnedClusters = true;
};

/// Approximate settings (Queries only). Each may drop visible pixels; `dyncull bench`
/// measures how many. The defaults are conservative.
struct SchedulerApproximations {
    /// Cull nodes whose screen rectangle covers fewer than this many pixels (0 = off).
    std::uint32_t smallFeaturePixels = 0;
    /// Decide with the node's previous answer instead of waiting; the query issued now
    /// is read next frame (one frame of latency, no waiting at all).
    bool useLastFrameResults = false;
    /// Issue queries even when their rectangles overlap pending ones (more answers
    /// "visible" than needed; measured, conservative in itself).
    bool batchOverlapping = false;
    /// TwoPhase: the error budget, in percent of the frame's pixels (0 = off). The parts
    /// the batched raster test finds visible may still be culled while the sum of their
    /// volumes' visible samples stays within the budget. Since a volume passes at least as
    /// many samples as its part shows, against depth that only grows nearer, that sum
    /// bounds the pixels the frame loses (FrameStats::claimedErrorPixels). The budget goes
    /// first to the parts that save the most drawing per sample (triangles over samples).
    /// A part culled so is not visible next frame either, so it is tested again then: the
    /// bound holds frame by frame, whatever the history.
    double errorBudgetPercent = 0.0;
    /// With an error budget: a part drawn early whose test against the final depth shows
    /// fewer samples than the whole budget leaves the early set, so the budget may take it
    /// next frame. Off by default: on the bunny swarm it drew 1.5x the parts and was 1.5x
    /// slower than without, since the parts it hands over are missing from the early depth
    /// (docs/BENCHMARKS.md).
    bool budgetEarlySet = false;
    /// With an error budget: the candidates whose samples could fit in it are drawn last,
    /// after being counted again against the depth of everything else drawn, and the
    /// budget is spent on those counts. Off by default: the same parts were culled with and
    /// without the recount on the bunny path and the city (the small parts peek past
    /// silhouettes that the late draws do not cover; docs/BENCHMARKS.md), so it only adds a
    /// batch and a wait.
    bool budgetRecount = false;
};

/// An error budget of `percent` of a `width` x `height` viewport, in whole pixels (rounded
/// down: the budget is never exceeded). The one conversion the scheduler and the
/// measurements use.
inline std::uint64_t errorBudgetPixels(double percent, int width, int height) {
    return static_cast<std::uint64_t>(std::floor(percent / 100.0 * double(width) * double(height)));
}

/// TwoPhase's cost model: a volume the pyramid cannot reject is tested only where the
/// test is expected to pay. Its cost is `testNsPerVolume` plus `testNsPerPixel` per
/// pixel of its screen rectangle; what it saves is the part's triangles times
/// `drawNsPerTriangle`, times the measured rate at which such tests answer "occluded"
/// (kept per kind: parts new this frame, and parts drawn early being tested again).
/// Otherwise the part is simply drawn. A round of raster tests also costs
/// `testNsPerBatch` before its first volume (a sync with the GL and a readback,
/// `bench_volume_tests`), so a frame's candidates get only the rounds their summed
/// margins pay for, and none if they do not pay for one. The same model turns a frame's tests off (no
/// depth readback, no test: every part in the frustum drawn) while the last frame
/// tested culled less drawing than `depthReadNs`, the readback and the stall it causes
/// (the late pass cannot start before the early pass is rasterised); it tests again
/// every `probeFrames` frames to see whether that has changed. Costs in nanoseconds of
/// GL time; the defaults were measured on llvmpipe at 640x360 (`bench_draw_speed`,
/// `bench_volume_tests`, and for the readback `full-hzb` against `vfc` on Sponza;
/// docs/BENCHMARKS.md), and another GL needs its own.
/// A triangle test (useTriangleTests) costs `triangleTestNsPerPart` plus
/// `triangleTestNsPerTriangle` per triangle, and is weighed the same way; the default is
/// 1.3x drawNsPerTriangle, as measured (`bench_draw_speed`: test-hidden against parts),
/// so on llvmpipe only the exploring eighth of the parts is tested. A cluster's tests
/// (useClusters) cost `clusterTestNs` of CPU (the swarm's `ms_clusters` over
/// `cluster_tests`), and a gap of culled clusters between drawn ones is skipped only if
/// its drawing costs more than `drawNsPerRange`, one more range of the multi-draw
/// (`bench_draw_speed`: parts-clusters against parts; nothing measurable on llvmpipe).
/// The pyramid is built again before a round of tested parts is drawn (useRoundPyramids)
/// where their triangles times `roundPyramidCulls`, the share of them that a pyramid of the
/// depth drawn so far culls beyond the early one (27% on the power plant, 39% on the city,
/// 60% on the bunny path), are worth more drawing than `pyramidNs`, a depth read that
/// waits for nothing and the build (`bench_volume_tests`, `bench_depth_pyramid`). Cluster
/// history's record at the frame's end is priced the same: `pyramidNs` (less
/// `testNsPerBatch` where the parts' refresh read that depth already, whose round of raster
/// tests the read replaced) plus
/// `recordNsPerCluster` per cluster it projects (`BM_ClusterRecord`) and
/// `recordNsPerLearned` per cluster whose footprint the frame's own tests handed it
/// (`BM_ClusterRecordLearned`), over the threads that share them (counts, not its time: a
/// timed price swung with the frame).
struct TestCosts {
    double drawNsPerTriangle = 53.0;
    double testNsPerVolume = 2700.0;
    double testNsPerPixel = 1.5;
    double testNsPerBatch = 200000.0;
    double triangleTestNsPerPart = 0.0;
    double triangleTestNsPerTriangle = 69.0;
    double clusterTestNs = 90.0;
    double recordNsPerCluster = 118.0;
    double recordNsPerLearned = 40.0;
    double drawNsPerRange = 0.0;
    double depthReadNs = 400000.0;
    double pyramidNs = 180000.0;
    double roundPyramidCulls = 0.3;
    std::uint32_t probeFrames = 16;
};

/// Numbers that change how fast culling is, never what it draws wrongly.
struct SchedulerTuning {
    HistoryParams history;
    std::uint32_t maxQueriesInFlight = 64;
    int occupancyTileSize = 16;  ///< pixels per tile side of both occupancy maps
    /// Objects that kept their transform this many frames are queried with their exact
    /// transformed local boxes instead of world AABBs (tightened boxes). The paper waits
    /// because shrinking its boxes was costly; transforming 8 corners is not, so the
    /// default tightens at once, moving objects included.
    std::uint32_t tightenAfterFrames = 0;
    /// What object nodes are queried with once tightened (Queries and TwoPhase with useTightVolumes):
    /// the node's stored volume of this kind under the object's matrix. Aabb is the
    /// transformed local box; Auto picks per node (chooseVolume in node_volumes.hpp).
    /// Scene nodes, Simple mode and untightened objects always use world AABBs; frustum
    /// tests, screen rectangles and the occupancy maps always use world AABBs. Auto by
    /// default: it drew no more parts than the boxes on any bundled scene (11% fewer on the
    /// bunny swarm, where it is 9% faster); the same mean time on the power plant, within
    /// noise on the city and Sponza (docs/BENCHMARKS.md). In TwoPhase a part drawn as
    /// clusters takes the better of its two boxes under Auto, whatever autoVolumeSaving:
    /// its clusters' own tests make a k-DOP's extra triangles cost more than they save
    /// (docs/BENCHMARKS.md, "boxes, not k-DOPs, for parts drawn as clusters").
    VolumeChoice volume = VolumeChoice::Auto;
    /// Auto: a k-DOP replaces the node's best box only if it has at least this fraction
    /// less surface area (in [0, 1]). Chosen by measurement: see docs/BENCHMARKS.md.
    float autoVolumeSaving = 0.1f;
    /// A result that has not arrived after this long counts as visible (never cull, never
    /// stall forever). Generous because a query answers only after everything submitted
    /// before it is rasterised, which on a loaded software rasteriser can take a second.
    double queryTimeoutMs = 2000.0;
    /// Simple and Queries: the nodes met first in front-to-back order are drawn without a
    /// query until this percentage of the leaves inside the frustum has been reached (the
    /// front-most leaves are rarely occluded: k-DOP bounding volumes for occlusion, section
    /// 4, which uses about 5% for CAD and 10-15% for architecture). Costs one hierarchical
    /// frustum count per frame; conservative (it only adds draws). 0 = off, at most 100.
    float frontPercent = 0.0f;
    /// TwoPhase: the late pass tests a part's volume at the finest pyramid level where its
    /// screen rectangle spans at most this many texels a side (DepthPyramid::occluded; at
    /// most pyramidSpan^2 reads, in [2, 64]). Finer rejects more parts before the batched
    /// raster test, at 5 us a volume, has to: 16 tested a quarter fewer volumes than 4 on the
    /// bunny path and was faster on every bundled scene; 32 gained nothing more
    /// (docs/BENCHMARKS.md, "pyramid span").
    int pyramidSpan = 16;
    /// The same for a cluster's box (cluster_culling.cpp), in [2, 64]. Reads are cheap next
    /// to the box's projection: 32 drew 7% fewer triangles than 4 on the power plant for 5%
    /// more cluster-test time (docs/BENCHMARKS.md, "cluster span").
    int clusterPyramidSpan = 32;
    /// The same for cluster history's record at the frame's end (cluster_history.cpp), in
    /// [2, 64]: it only chooses next frame's early clusters, so a coarser test costs drawing,
    /// never a wrong pixel. 64 drew 4% fewer triangles than 16 on the city and 2% more time
    /// on the power plant's record; the bunny path's clusters are small enough that both
    /// decide alike (docs/BENCHMARKS.md, "record span").
    int recordPyramidSpan = 16;
    /// TwoPhase: a volume the late pass's pyramid test (pyramidSpan) cannot reject is
    /// tested again texel by texel down to single pixels, its depth over each texel bounded
    /// by its front faces' planes (DepthPyramid::occludedPerTexel), reading at most this
    /// many texels before it gives up; the same for the parts tested against the final
    /// depth. 0: off. In [0, 65536]. 256 hid as much as 1024 on the city in less time, 64
    /// a little less (docs/BENCHMARKS.md, "Per-texel pyramid tests").
    int texelTestTexels = 256;
    /// The same for a cluster's box (cluster_culling.cpp), in [0, 65536].
    int clusterTexelTests = 256;
    /// TwoPhase: the late pass's candidates are tested in this many rounds, front to back
    /// (at least 1, at most 16): each round is tested against the depth of the rounds before
    /// it, whose visible parts are drawn first, at the price of one more wait per round. 2
    /// drew 4% fewer triangles than 1 on the power plant (3 no fewer than 2), 6% on the city
    /// (docs/BENCHMARKS.md, "candidate rounds").
    std::uint32_t candidateRounds = 2;
    /// Measurement, not speed: before each depth read and batched raster test, wait for the
    /// drawing submitted so far (QueryBackend::finishDrawing) and time it apart, and time the
    /// pyramid tests, so that a test's own cost is told apart from the drawing it waits for
    /// (FrameStats::drawWaitMs, pyramidTestMs). Both waits happen anyway inside the read and
    /// the test; splitting them off costs a sync only where the backend would overlap.
    bool splitDrawWaits = false;
    /// With useClusterWorker: cluster history's record at the frame's end shares its tests
    /// with a second thread from the work of this many clusters to project (the clusters
    /// the frame's tests handed on count at TestCosts::recordNsPerLearned against
    /// recordNsPerCluster; a thread costs tens of microseconds to start).
    std::uint32_t recordWorkerClusters = 4096;
    TestCosts costs;
};

/// Everything a QueryScheduler is configured with, grouped by what a setting may change:
/// the mode, which parts of the method run, what may be traded for pixels, and speed.
struct SchedulerParams {
    CullMode mode = CullMode::TwoPhase;
    SchedulerFeatures features;
    SchedulerApproximations approx;
    SchedulerTuning tuning;
};

/// What the scheduler decided for a node reached during a frame (for the node-box view
/// and for tests).
enum class NodeState : std::uint8_t {
    FrustumCulled,      ///< outside the frustum or off screen
    Occluded,           ///< a query answered "occluded" (or last frame's answer, approximately)
    SmallFeature,       ///< culled by the small-feature setting
    VisibleQueried,     ///< a query answered "visible"
    VisibleHistory,     ///< drawn without a query thanks to visibility history
    VisibleOccupancy,   ///< drawn without a query: touched empty screen
    VisibleNear,        ///< drawn without a query: camera inside or near plane crossed
    VisibleFront,       ///< drawn without a query: among the front-most frontPercent leaves
    VisibleVfc,         ///< vfc mode: in the frustum
    VisibleCheaper,     ///< two-phase: drawn untested, since the cost model expects the test to cost more than it saves
    VisibleOccluder,    ///< an occluder-only object (OcclusionRole): drawn whole and untested whenever in the frustum
    ClusterCulled,      ///< decided visible, but none of its clusters survived their tests (SchedulerFeatures::useClusters): not drawn
    BudgetCulled,       ///< visible to its test, culled within the error budget (SchedulerApproximations::errorBudgetPercent)
};
const char* toString(NodeState s);

/// One traced node: which, where (world AABB) and what was decided.
struct NodeTrace {
    NodeRef ref;
    Aabb box;
    NodeState state;
};

/// Validates ranges (e.g. tile size > 0, maxQueriesInFlight > 0, autoVolumeSaving in [0, 1]).
Status validateSchedulerParams(const SchedulerParams& p);

/// The world-space volume Queries and TwoPhase test object node `ref` with once tightened: the node's
/// stored volume of kind chooseVolume(volume, autoSaving) — its local box for Aabb, or
/// when the model has no volumes — under the object's current matrix. Its world AABB
/// (`objects`' worldBox of the node) for a node with no stored vertices.
QueryVolume objectNodeVolume(const SceneObjects& objects, NodeRef ref, VolumeChoice volume, float autoSaving);
/// The kind objectNodeVolume takes for those arguments: Aabb also where the model has no
/// stored volumes.
VolumeKind objectNodeVolumeKind(const SceneObjects& objects, NodeRef ref, VolumeChoice volume, float autoSaving);
/// Where that kind is Aabb, the object-space box whose corners objectNodeVolume transforms:
/// the node's box, or its stored box volume's; empty where it takes the world AABB instead.
Aabb objectNodeBox(const SceneObjects& objects, NodeRef ref, VolumeChoice volume);
/// The affine map from a frame in which a box is [-1, 1]^3 to the space of its 8 `corners`
/// (in boxCorners' order: bit k of the index picks the side along axis k; a PCA box's, whose
/// axes need not be the space's): their centre and half axes, averaged over the corners, so
/// within a rounding or two of every corner. Double.
glm::dmat4 boxFrame(std::span<const glm::vec3, 8> corners);
/// Where objectNodeVolumeKind is Obb: the object's matrix times boxFrame of object node
/// `ref`'s PCA box, object space to world. std::nullopt where the node has no stored PCA box.
std::optional<glm::dmat4> objectNodeObbFrame(const SceneObjects& objects, NodeRef ref);

/// Runs one frame of culling and drawing. Owns the visibility history between frames;
/// borrows the tree, backend and sink for the duration of cullFrame.
class QueryIssuer;
class DeferredQueries;
struct DepthFootprint;
struct ObjectProjection;
class DrawQueries;

class QueryScheduler {
public:
    explicit QueryScheduler(SchedulerParams params = {});
    ~QueryScheduler();
    QueryScheduler(QueryScheduler&&) noexcept;
    QueryScheduler& operator=(QueryScheduler&&) noexcept;

    const SchedulerParams& params() const { return params_; }
    void setParams(const SchedulerParams& p) { params_ = p; }

    /// Traverses `tree` front-to-back for `camera` (world space), drawing visible parts
    /// through `sink` and querying through `backend`. Returns the frame's counts and CPU
    /// times (frameMs and updateMs are left for the caller, who owns glFinish and the tree update).
    FrameStats cullFrame(const TwoLevelTree& tree, const FrameView& view, QueryBackend& backend, PartSink& sink);
    /// The same for a camera and viewport whose FrameView is made here.
    FrameStats cullFrame(const TwoLevelTree& tree, const Camera& camera, int width, int height, QueryBackend& backend,
                         PartSink& sink) {
        return cullFrame(tree, FrameView::of(camera, width, height), backend, sink);
    }

    /// Forget all history (e.g. after a camera cut).
    void resetHistory() { history_.clear(); }
    /// When set, every decision of the following frames is appended to `*trace`
    /// (cleared at the start of each frame). The caller owns the vector; nullptr stops.
    void setTrace(std::vector<NodeTrace>* trace) { trace_ = trace; }
    std::uint32_t frameIndex() const { return frame_; }
    /// The visibility record of `ref` (a live node of `objects`), or nullptr if the culler
    /// has none for the object as it is now. Valid until the next cullFrame.
    const NodeHistory* history(NodeRef ref, const SceneObjects& objects) const { return history_.find(ref, objects); }
    /// True if the newest frame tested `ref` (a live node of `objects`) and found it hidden:
    /// it lay in the frustum, reached by the traversal, behind what was drawn. A node never
    /// reached (its subtree culled whole, or outside the frustum) or drawn gives false.
    bool testedHiddenLastFrame(NodeRef ref, const SceneObjects& objects) const {
        const NodeHistory* h = history_.find(ref, objects);
        return h && testedHiddenLastFrame(*h);
    }
    /// The same for a record history() returned.
    bool testedHiddenLastFrame(const NodeHistory& h) const { return frame_ > 0 && h.lastQueryFrame == frame_ && !h.lastVisible; }

    /// A guess for streaming's read-ahead, not a culling decision: how far world box `box`
    /// lay from showing in the newest depth pyramid (two-phase's depth of the newest frame,
    /// under that frame's view), in pixels: 0 if it showed there as it was, or reached the
    /// near plane; else the first of 1, 2, 4, ... `maxPixels` by which its pixel rectangle,
    /// grown on every side, reaches a texel farther than its nearest depth (a box hidden
    /// just behind a silhouette shows when the view moves that far); `kFarFromShowing` if
    /// none does. nullopt if there is no pyramid or the box lay off that frame's screen.
    std::optional<float> pixelsFromShowing(const Aabb& box, int maxPixels) const;
    static constexpr float kFarFromShowing = 1e30f;

    /// One frame's borrowed state, passed through every stage (cull_frame.hpp).
    struct Frame;

private:
    // Stages shared by the modes (query_scheduler.cpp).
    enum class FirstTest : std::uint8_t { Invisible, Visible, NeedQuery };
    /// Which of a part's clusters a draw considers: all, in the early pass with cluster
    /// history only those that showed at the end of last frame (the others are deferred),
    /// and in the late pass only the deferred ones.
    enum class ClusterPass : std::uint8_t { All, Early, Deferred };
    /// Algorithm 3: frustum, near plane, front-most leaves, small features, history.
    FirstTest firstVisibilityTest(Frame& f, NodeRef ref, const Aabb& box, NodeHistory& h);
    struct Visit {
        NodeRef ref;
        Aabb box;  // world space
        FirstTest test;
    };
    /// Pops the nearest node off active_ and runs the first visibility test on it.
    Visit visitNearest(Frame& f);
    /// Algorithm 4: draws part `ref` or pushes its children. `untested`: decided visible
    /// without a query this frame (gets a draw query).
    void processVisible(Frame& f, NodeRef ref, NodeHistory& h, bool untested);
    void drawNode(Frame& f, NodeRef ref, bool untested, ClusterPass pass = ClusterPass::All);
    /// Pushes `ref`'s children front to back onto active_ (the nearest on top), leaving out
    /// objects with a role, which the traversal never reaches (object_roles.cpp).
    void pushChildren(Frame& f, NodeRef ref);
    /// The volume Queries tests `ref` with: its world box, or once its object is still
    /// (tightenAfterFrames) its own volume.
    QueryVolume queryVolume(const Frame& f, NodeRef ref, const Aabb& worldBox) const;

    std::uint32_t countFrustumLeaves(const Frame& f) const;

    // The modes.
    void runVfc(Frame& f);
    void runSimple(Frame& f);
    void runQueries(Frame& f);   // hardware_queries.cpp
    void runTwoPhase(Frame& f);  // two_phase.cpp
    // Objects with an OcclusionRole (object_roles.cpp): occluder-only ones drawn before the
    // mode's traversal, occludee-only ones tested against the final depth and drawn after.
    void drawOccluders(Frame& f);
    void drawOccludees(Frame& f);

    // Queries' stages (hardware_queries.cpp).
    /// A node that needs a query: accepted by the occupancy map, issued, or made to wait.
    void queryOrWait(Frame& f, NodeRef ref, const Aabb& box, NodeHistory& h);
    /// The occupancy-map fast accept: a rectangle touching screen where nothing has been
    /// drawn cannot be hidden; draws the node and returns true.
    bool acceptByOccupancy(Frame& f, NodeRef ref, const Aabb& box, const ScreenRect& rect);
    /// The one-frame-latency setting: decides by the node's previous answer at once and
    /// issues a query to be read in a later frame.
    void decideByLastAnswer(Frame& f, NodeRef ref, const Aabb& box, NodeHistory& h);
    /// Records a query's answer and draws or culls its node.
    void finishQuery(Frame& f, NodeRef ref, QueryResult r);
    /// Issues the query of node `ref` (world box `box`, covering `rect`) now.
    void issueQuery(Frame& f, NodeRef ref, const Aabb& box, const ScreenRect& rect);
    /// useWaitOrder in effect: a waiting node holds back farther nodes it overlaps.
    bool keepsWaitOrder() const { return params_.features.useWaitOrder && !params_.approx.batchOverlapping; }
    /// Issues queries for waiting nodes, nearest first, that can now be issued; true if any was.
    bool retryWaiting(Frame& f);
    /// Records the answers of the latency setting's queries that have arrived (non-blocking).
    void collectLatent(Frame& f);

    SchedulerParams params_;
    VisibilityHistory history_;
    std::uint32_t frame_ = 0;
    std::vector<std::uint32_t> stillSince_;  // per object slot: first frame of its current transform (seen lazily)
    std::vector<std::uint64_t> lastPlacement_;  // per object slot: SceneObjects::placedAt when last seen
    std::vector<NodeTrace>* trace_ = nullptr;  // the caller's, between setTrace calls

    // Buffers reused across frames (their contents live for one frame).
    std::vector<NodeRef> active_;  // stack: back() is the nearest unprocessed node
    std::vector<NodeRef> scratch_;
    std::vector<std::pair<float, std::uint32_t>> roleOrder_;  // (distance, slot)

    // Queries. The occupancy maps of drawn rectangles and of waiting nodes' rectangles;
    // the queries awaited this frame; nodes waiting to be queried, nearest first.
    OccupancyMap drawnMap_, waitingMap_;
    struct Waiting {
        float dist2;  // squared distance from the eye to the box centre
        NodeRef ref;
        Aabb box;
        ScreenRect rect;
    };
    std::vector<Waiting> waiting_;
    bool answeredSinceRetry_ = false;  // a query finished since waiting nodes were last retried
    std::unique_ptr<QueryIssuer> queries_;
    std::unique_ptr<DeferredQueries> latent_;  // useLastFrameResults: read when they answer
    std::unique_ptr<DrawQueries> drawQueries_;  // useDrawQueries

    // TwoPhase (two_phase.cpp): the early pass's depth and its pyramid, reused across
    // frames; the parts for the batched raster test and its answers.
    std::vector<float> depth_;
    DepthPyramid pyramid_;
    std::optional<FrameView> pyramidView_;  // the view pyramid_ was built under; none: not built
    // Parts for the batched raster test. Their volumes are rebuilt batch by batch
    // (testedVolume) rather than kept: a k-DOP is 860 bytes, and a frame without history
    // has tens of thousands of candidates.
    std::vector<NodeRef> candidates_, refresh_;
    std::vector<NodeRef> allCandidates_;  // every candidate while they are tested in rounds
    double candidateMarginNs_ = 0.0;      // this frame's candidates' testMarginNs, summed
    // Per entry of candidates_ (until testCandidates): its footprint and testMarginNs, as
    // the late traversal computed them.
    std::vector<DepthFootprint> candidateFootprints_;
    std::vector<double> candidateMargins_;
    /// SchedulerFeatures::useLatePyramid: after the deferred clusters are drawn, the
    /// pyramid built again from that depth and candidates_ tested against it; the hidden
    /// ones are settled as occluded, and only the others go to the raster test.
    void testCandidatesOnLateDepth(Frame& f);
    std::uint32_t lastCandidateBatchFrame_ = 0;  // the last frame whose candidates were raster-tested
    /// How many rounds of raster tests this frame's candidates get: candidateRounds (at
    /// most one per candidate), fewer where their summed margins do not pay for each
    /// round's TestCosts::testNsPerBatch, 0 if not one (then they are drawn untested),
    /// but 1 every probeFrames frames so the rate of occluded answers stays measured.
    std::size_t candidateRoundsPaid(const Frame& f) const;
    /// The volume `ref` is tested with in two-phase (world space): its world box for a
    /// scene node or without tight volumes, else its own volume under its object's matrix.
    QueryVolume testedVolume(const Frame& f, NodeRef ref) const;
    /// The autoSaving testedVolume passes to objectNodeVolume for object node `ref`.
    float testedAutoSaving(const Frame& f, NodeRef ref) const;
    /// testedVolume(f, ref)'s footprint (ScreenProjection::volumeDepth), a box's computed
    /// from its centre and axes without building the volume (ScreenProjection::boxDepth);
    /// false if it reaches the near plane. With `planes` off, a box's planes and outline
    /// are left out (pyramidHides makes them where its span test cannot decide).
    bool testedFootprint(const Frame& f, NodeRef ref, DepthFootprint& out, bool planes = true) const;
    /// The cost model's measured rates of "occluded" answers, for parts new this frame and
    /// for parts drawn early and tested again (moving averages over frames), and for the
    /// triangle tests of parts whose volumes passed.
    double candidateOccludedRate_ = 0.5, refreshOccludedRate_ = 0.5, triangleOccludedRate_ = 0.5;
    // useTriangleTests: this frame's marked draws in order, the parts to test on their
    // triangles, and the answers of either.
    std::vector<NodeRef> markedDraws_;
    std::vector<PartRange> triangleTests_;
    std::vector<QueryResult> triangleAnswers_;
    /// The early pass: last frame's visible parts drawn, frustum-culled; true if any was.
    bool drawEarlySet(Frame& f);
    /// Reads the frame's depth back and builds pyramid_ from it (counted and timed in the
    /// frame's stats; pyramidView_ follows). False if the backend cannot read it at the
    /// frame's size: pyramidView_ is cleared, and nothing may be tested against pyramid_.
    bool buildPyramid(Frame& f);
    /// With SchedulerTuning::splitDrawWaits: waits for the drawing so far, timed into
    /// FrameStats::drawWaitMs. Nothing otherwise.
    void splitDrawWait(Frame& f);
    /// The late pass: every node tested against the pyramid (if `haveDepth`), the parts it
    /// lets through collected for the raster test (if this frame is `testing`) or drawn.
    void lateTraversal(Frame& f, bool testing, bool haveDepth, bool triangles);
    /// The batched raster test of candidates_, drawing the visible ones (or sending them
    /// on to triangle tests).
    void testCandidates(Frame& f, bool triangles);
    /// SchedulerFeatures::useRoundPyramids: the pyramid built again from the depth drawn so
    /// far, for the clusters of the parts about to be drawn, where TestCosts expects it to pay.
    void refreshClusterPyramid(Frame& f);
    /// refresh_ tested against the final depth: a part hidden there is not drawn early next frame.
    void testRefresh(Frame& f);
    /// The pyramid built from the frame's final depth, read at most once a frame (the
    /// refresh and the record share it); false if the depth could not be read.
    bool readFinalPyramid(Frame& f);
    /// With an error budget that hands the early set to it (budgetEarlySet): the refresh
    /// needs each part's samples, which only the batched raster test counts.
    bool budgetTakesEarlySet() const { return params_.approx.errorBudgetPercent > 0.0 && params_.approx.budgetEarlySet; }
    /// refresh_ tested against a pyramid of the final depth (readFinalPyramid: the record
    /// uses it too), their answers recorded and the hidden ones' triangles counted
    /// in culledTriangles_: the cost model's probe (SchedulerFeatures::useEndProbes), and
    /// the refresh where the record reads the final depth anyway (useRefreshPyramid).
    /// False if the depth could not be read (nothing recorded).
    bool testOnFinalPyramid(Frame& f);
    /// The late pass's pyramid test of a volume's footprint: at pyramidSpan, then texel by
    /// texel (SchedulerTuning::texelTestTexels). True if hidden behind the pyramid. `fp` is
    /// `ref`'s footprint; its planes are made here if they were left out and are needed.
    bool pyramidHides(Frame& f, NodeRef ref, DepthFootprint& fp) const;
    /// True if a triangle test of `ref` is expected to save more drawing than it costs.
    bool worthTriangleTest(const Frame& f, NodeRef ref);
    /// Tests triangleTests_ (PartSink::testParts), draws the visible ones, records the answers.
    void testTriangles(Frame& f);
    /// Reads this frame's draw marks into each drawn part's history.
    void readDrawMarks(Frame& f);
    /// The drawing (ns) that the last frame with tests saved, and that frame's number.
    double savedNs_ = 1e300;
    std::uint32_t lastTestedFrame_ = 0;
    std::uint64_t culledTriangles_ = 0;  // this frame, by the pyramid and the raster tests
    /// Triangles under `ref`: its subtree's for an object node, its objects' for a scene node.
    std::uint64_t subtreeTriangles(const Frame& f, NodeRef ref);
    std::vector<std::uint32_t> scratchIndices_;  // subtreeTriangles' stack
    /// What testing part `ref`, whose volume covers `rect`, is expected to save in drawing
    /// less what the test costs (ns, TestCosts), given that a fraction `occludedRate` of
    /// such tests cull; the batch's own cost (testNsPerBatch) is not in it.
    double testMarginNs(const Frame& f, NodeRef ref, const ScreenRect& rect, double occludedRate);
    /// True if testMarginNs is positive (always, without the cost model).
    bool worthTesting(const Frame& f, NodeRef ref, const ScreenRect& rect, double occludedRate);
    /// True for the new parts tested this frame whatever the cost model expects.
    bool exploring(NodeRef ref) const;
    std::vector<QueryVolume> rasterVolumes_;  // one batch's volumes (kRasterBatchVolumes at most)
    std::vector<BatchId> rasterBatches_;
    std::vector<QueryResult> rasterAnswers_;
    std::vector<std::uint32_t> rasterSamples_;  // with `countSamples`
    /// One batched raster test of `parts`' volumes, answers in rasterAnswers_ (all Visible
    /// if the backend has no such test) and with `countSamples` each volume's samples in
    /// rasterSamples_, waiting for them: nothing else is left to do.
    void rasterTest(Frame& f, const std::vector<NodeRef>& parts, bool countSamples = false);
    /// The error budget (budget_culling.cpp): turns the Visible answers of candidates_
    /// that fit in the frame's budget into Occluded, marking them in budgetCulled_, and
    /// charges their samples to the frame's claim.
    void spendErrorBudget(Frame& f);
    /// The error budget in whole pixels of this frame's viewport.
    std::uint64_t errorBudgetPixels(const Frame& f) const;
    /// Per candidate, this frame: decided by its answer, culled within the budget, or
    /// waiting to be counted again (budgetRecount).
    enum : std::uint8_t { kBudgetNo, kBudgetCulled, kBudgetLater };
    std::vector<std::uint8_t> budgetCulled_;
    std::vector<NodeRef> waitingParts_;
    /// Culls, draws or hands on to triangle tests each candidate by its answer (all
    /// "visible" if not `tested`: the cost model drew them untested).
    void settleCandidates(Frame& f, bool triangles, bool tested = true);
    std::vector<std::pair<double, std::uint32_t>> budgetOrder_;  // (drawing saved per sample, candidate)

    // useClusters (cluster_culling.cpp): the ranges of the part being drawn, and per model
    // the measured fraction of tested triangles that the cluster tests culled (a moving average).
    std::vector<IndexRange> clusterRanges_;
    std::vector<double> clusterCulledRate_;
    /// Tests the clusters of part `ref` (node `n` of `model`) where they may pay, leaving
    /// the survivors in clusterRanges_ (adjacent ones merged, unless the frame marks
    /// clusters: then one range per cluster, its index in clusterRangeIds_); false if the
    /// part is to be drawn whole.
    /// `recordIndex`: for a deferred pass, the part's entry in clusterParts_ (the early
    /// pass's), which its tests' LearnedCluster go to.
    bool cullClusters(Frame& f, NodeRef ref, const LocalBsp& model, const LocalBspNode& n, ClusterPass pass,
                      std::uint32_t recordIndex = kInvalidIndex);
    // The steps of cullClusters (cluster_selection.hpp): which tests, decided on the render
    // thread (false: the part is drawn whole); the tests, safe on any thread; their counts
    // into the stats and cost model.
    struct ClusterJob;
    struct ClusterSelection;
    struct DeferredSelection;
    struct LearnedCluster;
    /// Whether part `ref` of `model` is drawn as clusters (useClusters, a sink that draws
    /// ranges, a model with clusters), whatever the tests then decide.
    bool drawsAsClusters(const Frame& f, NodeRef ref, const LocalBsp& model) const;
    bool planClusters(Frame& f, NodeRef ref, const LocalBsp& model, const LocalBspNode& n, ClusterPass pass, ClusterJob& job,
                      bool& tested);
    void selectClusters(const Frame& f, const ClusterJob& job, ClusterSelection& out) const;
    void takeSelection(Frame& f, const ClusterJob& job, ClusterSelection& sel);
    /// SchedulerFeatures::useClusterWorker: starts selecting the deferred clusters on a
    /// worker thread (after the early pyramid is built); drawDeferredClusters reads its
    /// selections as they are written, and joinDeferredSelection ends it with the late pass.
    void startDeferredSelection(Frame& f);
    void joinDeferredSelection();
    std::unique_ptr<DeferredSelection> deferredSelection_;
    std::unique_ptr<ClusterSelection> selection_;  // cullClusters' scratch
    // useClusterHistory: the parts drawn early that deferred clusters, and every part whose
    // clusters were drawn or tested this frame (their bits are written at the frame's end).
    struct DeferredPart {
        NodeRef ref;
        bool drawn;                 ///< some of its clusters were drawn early
        std::uint32_t trace;        ///< its entry in the frame's trace, or kInvalidIndex
        std::uint32_t recordIndex;  ///< its entry in clusterParts_, or kInvalidIndex
    };
    std::vector<DeferredPart> deferredParts_;
    std::vector<NodeRef> clusterParts_;
    // SchedulerFeatures::useLearnedClusters: for each entry of clusterParts_, the offset of
    // its clusters' LearnedCluster in learnedClusters_ (kInvalidIndex: none tested this
    // frame); written as the tests are taken, read by the record.
    std::vector<std::uint32_t> clusterPartLearned_;
    std::vector<LearnedCluster> learnedClusters_;
    std::uint32_t lastDeferred_ = 0;  // clusters the last cullClusters call deferred
    /// Cluster history's cost model: this frame's deferred triangles that the late pass did
    /// not draw, the drawing they saved the last frame that used bits (ns), the last
    /// recording's price (ns, TestCosts: readback and tests), and that recording's frame.
    std::uint64_t deferredTriangles_ = 0;
    double clusterBitsSavedNs_ = 1e300, clusterRecordNs_ = 0.0;
    std::uint32_t lastClusterRecordFrame_ = ~0u - 1;  // none yet: one past it is no frame's "last frame" either
    /// The late pass's share of the early parts: their deferred clusters that the pyramid
    /// cannot reject, drawn.
    void drawDeferredClusters(Frame& f);
    /// At the frame's end: the final depth read back into the pyramid and every cluster of
    /// clusterParts_ tested against it, into the parts' cluster bits (with
    /// useClusterWorker, the later half of the clusters on a second thread).
    void recordClusterVisibility(Frame& f);
    /// The record's verdicts for `parts`' clusters in order, 1 where a cluster shows: reads
    /// only the frame, the pyramid and the objects, so two threads can share the parts.
    /// `first`: the index in clusterParts_ of `parts`' first (their LearnedCluster). Returns
    /// how many clusters it compared with the pyramid (FrameStats::clusterPyramidTests).
    std::uint32_t recordVerdicts(const Frame& f, std::size_t first, std::span<const NodeRef> parts, bool sinkCullsBackFaces,
                                 std::vector<std::uint8_t>& shown) const;
    std::vector<std::uint8_t> recordShown_, recordShownLate_;
    std::vector<double> recordPartNs_;  // each of clusterParts_' share of the record (TestCosts, ns)
    // useClusterMarks: the cluster each range of clusterRanges_ is (its index in its
    // model's clusters), and every cluster drawn this frame in the order its mark comes back.
    struct MarkedCluster {
        std::uint32_t object;   ///< index in SceneObjects (no object is removed mid-frame)
        std::uint32_t cluster;  ///< index in its model's LocalBsp::clusters
    };
    std::vector<std::uint32_t> clusterRangeIds_;
    std::vector<MarkedCluster> markedClusters_;
    std::vector<QueryResult> clusterMarks_;
    /// After a draw of clusterRanges_ for part `ref` while marking clusters: their marks' order.
    void noteMarkedRanges(NodeRef ref);
    /// At the frame's end: the marks of every cluster drawn, into the bits of clusterParts_
    /// (a cluster of theirs not drawn, or drawn and hidden, is cleared).
    void readClusterMarks(Frame& f);
};

}  // namespace dyncull
