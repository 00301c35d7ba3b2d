// Cluster culling: a part the traversal decided to draw is drawn as those of its clusters
// (runs of about a hundred triangles, leaf_clusters.hpp) that survive tests far cheaper
// than any query, in one multi-draw: the normal-cone back-face test (Wihlidal, "Optimizing
// the Graphics Pipeline with Compute", 2016), the frustum, and in the two-phase late pass
// the depth pyramid, as GPU-driven engines cull meshlets (niagara; see
// ../shared/notes/batched-occlusion-tests.md). The finer level of "model only what a scene
// requires": the BSP's parts stay the unit of queries and history, clusters are tested
// only through these cheap paths, and only where the measured savings pay for the tests.
// With cluster history (cluster_history.cpp) a draw takes only one pass's share of a part's
// clusters: in the early pass those that showed last frame, in the late pass the others.

#include <algorithm>
#include <cassert>

#include "cluster_selection.hpp"

namespace dyncull {

namespace {
/// What clusterTest found: hidden without a projection (outside the frustum), hidden by
/// the pyramid (or covering no pixel centre), reaching the near plane (shows), in front
/// and not rejected (its footprint filled in), or neither (no pyramid to test against).
enum class ClusterTest : std::uint8_t { Hidden, Behind, Crossing, Passed, Untested };

/// Whether cluster `c` of an object with `matrix` (prepared as `object`) shows nothing:
/// outside the frustum (if `frustum`: its part crosses it), or behind the depth pyramid (if
/// `pyramid`: at `span`, then texel by texel reading at most `texels`, 0 for not). A
/// cluster the eye is inside of or that reaches the near plane is visible (boxDepth says
/// so); one off screen is not.
ClusterTest clusterTest(const QueryScheduler::Frame& f, const DepthPyramid* pyramid, int span, int texels, const glm::mat4& matrix,
                        const ObjectProjection& object, const LeafCluster& c, bool frustum, ScreenRect& centres, float& nearest) {
    if (frustum && f.frustum().outside(transformAabb(matrix, c.box))) return ClusterTest::Hidden;
    if (!pyramid) return ClusterTest::Untested;
    BoxCorners corners;
    if (!f.screen.boxCentres(object, c.box, centres, nearest, texels > 0 ? &corners : nullptr)) return ClusterTest::Crossing;
    // A pyramid exists only for a single-sample target: a cluster covering no pixel centre draws nothing.
    if (centres.empty() || pyramid->occluded(centres, nearest, span)) return ClusterTest::Behind;
    if (texels == 0) return ClusterTest::Passed;
    DepthPlanes planes;
    f.screen.frontFacePlanes(object, corners, planes);
    return pyramid->occludedPerTexel(centres, nearest, planes, texels) ? ClusterTest::Behind : ClusterTest::Passed;
}
}  // namespace

bool QueryScheduler::cullClusters(Frame& f, NodeRef ref, const LocalBsp& model, const LocalBspNode& n, ClusterPass pass,
                                  std::uint32_t recordIndex) {
    clusterRanges_.clear();
    clusterRangeIds_.clear();
    lastDeferred_ = 0;
    ClusterJob job;
    bool tested = false;
    if (!planClusters(f, ref, model, n, pass, job, tested)) return false;
    if (pass == ClusterPass::Deferred) job.recordIndex = recordIndex;
    if (!selection_) selection_ = std::make_unique<ClusterSelection>();
    ClusterSelection& sel = *selection_;
    selectClusters(f, job, sel);
    if (tested) f.stats.clusterTests += static_cast<std::uint32_t>(job.clusters.size());
    if (!job.split && tested) {
        const std::uint32_t triangles = n.indexCount / 3;
        double& rate = clusterCulledRate_[f.objects.modelOf(ref.object)];
        rate += 0.02 * (double(sel.culledTriangles) / double(triangles > 0 ? triangles : 1) - rate);
    }
    takeSelection(f, job, sel);
    return true;
}

bool QueryScheduler::drawsAsClusters(const Frame& f, NodeRef ref, const LocalBsp& model) const {
    return params_.features.useClusters && !ref.isSceneNode() && f.sink.drawsRanges() && model.clusters.builtFor(model.nodes.size());
}

bool QueryScheduler::planClusters(Frame& f, NodeRef ref, const LocalBsp& model, const LocalBspNode& n, ClusterPass pass,
                                  ClusterJob& job, bool& tested) {
    if (!drawsAsClusters(f, ref, model)) return false;
    const std::span<const LeafCluster> clusters = model.clusters.ofSubtree(ref.node, n.subtreeSize);
    if (clusters.empty()) return false;
    const SceneObjects& objs = f.objects;
    if (f.recordClusterBits && pass != ClusterPass::Deferred) {  // its bits are written at the frame's end
        job.recordIndex = static_cast<std::uint32_t>(clusterParts_.size());
        clusterParts_.push_back(ref);
        clusterPartLearned_.push_back(kInvalidIndex);
    }
    // Which tests can cull anything here: cones only where back faces are culled, the
    // frustum only for a part crossing it, the pyramid only after the early pass.
    bool cones = model.faces == FaceMode::CullBack && f.sink.cullsBackFaces();
    bool frustum = f.frustum().classify(f.tree.worldBox(ref)) != Frustum::Side::Inside;
    bool pyramid = f.clusterPyramid;
    // With cluster history the early pass draws the clusters that showed last frame and
    // the late pass the others: a split no cost model may turn off.
    const bool split = pass != ClusterPass::All;
    const ModelId modelId = objs.modelOf(ref.object);
    if (clusterCulledRate_.size() <= modelId) clusterCulledRate_.resize(modelId + 1, 0.5);
    const double rate = clusterCulledRate_[modelId];
    const std::uint32_t triangles = n.indexCount / 3;
    tested = split;
    if (!split) {
        // The cost model: a model's clusters are tested while the drawing they were
        // measured to save (its rate of culled triangles) exceeds the tests' cost; one
        // part in eight is tested regardless, so the rate stays measured.
        tested = (cones || frustum || pyramid) &&
                 (cones || pyramid || clusters.size() > 1) &&  // else the part's own frustum test said it all
                 (!params_.features.useCostModel || exploring(ref) ||
                  rate * triangles * params_.tuning.costs.drawNsPerTriangle >= double(clusters.size()) * params_.tuning.costs.clusterTestNs);
        // Untested, it is drawn whole; unless its clusters are marked, which needs them apart.
        if (!tested && !f.markClusters) return false;
        if (!tested) cones = frustum = pyramid = false;
    }
    const glm::mat4& matrix = objs.matrix(ref.object);
    job.clusters = clusters;
    job.firstBit = model.clusters.nodeFirst[ref.node];
    job.shown = split ? history_.clusterBits(ref.object, objs) : std::span<const std::uint64_t>{};
    job.matrix = matrix;
    job.object = pyramid ? f.screen.objectProjection(matrix) : ObjectProjection{};
    job.eye = ObjectSpaceEye(f.camera(), matrix);
    job.pass = pass;
    job.split = split;
    job.cones = cones;
    job.frustum = frustum;
    job.pyramid = pyramid;
    job.markRanges = f.markClusters;
    // Only tests against a pyramid learn enough to spare the record a projection.
    job.keepLearned = f.recordClusterBits && !f.markClusters && pyramid && params_.features.useLearnedClusters;
    return true;
}

void QueryScheduler::selectClusters(const Frame& f, const ClusterJob& job, ClusterSelection& out) const {
    const auto t0 = SchedulerClock::now();
    out.ranges.clear();
    out.rangeIds.clear();
    out.culledTriangles = out.deferredTriangles = out.drawnTriangles = 0;
    out.culledClusters = out.deferred = out.drawn = out.pyramidTests = 0;
    const ClusterPass pass = job.pass;
    const std::uint32_t firstCluster = job.firstBit;
    const std::span<const LeafCluster> clusters = job.clusters;
    const DepthPyramid* pyramid = job.pyramid ? &pyramid_ : nullptr;
    out.learned.assign(job.keepLearned ? clusters.size() : 0, LearnedCluster{});
    LearnedCluster scratch;
    // What the tests culled (less the gaps drawn after all) and, per run of undrawn
    // clusters since the last drawn one (gap*), what a merged range would draw.
    std::uint64_t gapTriangles = 0;
    std::uint32_t gapClusters = 0;
    for (std::uint32_t i = 0; i < clusters.size(); ++i) {
        const LeafCluster& c = clusters[i];
        // Deferred: drawn early already. Early: hidden last frame, left to the late pass
        // if it faces the eye and is in the frustum.
        const bool otherPass = job.split && clusterBit(job.shown, firstCluster + i) == (pass == ClusterPass::Deferred);
        const bool drawnEarly = pass == ClusterPass::Deferred && otherPass;
        bool culled = false;
        if (!drawnEarly) {
            LearnedCluster& learned = job.keepLearned ? out.learned[i] : scratch;
            ClusterTest test = job.cones && job.eye.backFacing(c) ? ClusterTest::Hidden : ClusterTest::Untested;
            if (test == ClusterTest::Untested && (job.frustum || pyramid))
                test = clusterTest(f, pyramid, params_.tuning.clusterPyramidSpan, params_.tuning.clusterTexelTests, job.matrix,
                                   job.object, c, job.frustum, learned.centres, learned.nearest);
            culled = test == ClusterTest::Hidden || test == ClusterTest::Behind;
            out.pyramidTests += test == ClusterTest::Behind || test == ClusterTest::Passed;
            learned.fate = culled ? LearnedCluster::Fate::Hidden
                           : test == ClusterTest::Crossing ? LearnedCluster::Fate::Crossing
                           : test == ClusterTest::Passed   ? LearnedCluster::Fate::Projected
                                                           : LearnedCluster::Fate::Untested;
        }
        if (culled) {
            ++out.culledClusters;
            out.culledTriangles += c.indexCount / 3;
        } else if (otherPass) {
            if (!drawnEarly) {
                ++out.deferred;
                out.deferredTriangles += c.indexCount / 3;
            }
        }
        if (culled || otherPass) {
            ++gapClusters;
            gapTriangles += c.indexCount / 3;
            continue;
        }
        ++out.drawn;
        out.drawnTriangles += c.indexCount / 3;
        // A gap of culled clusters between two drawn ones costs one more range of the
        // multi-draw: skipped only where it saves more drawing than a range costs, and
        // always when it holds clusters the other pass draws.
        IndexRange* last = out.ranges.empty() ? nullptr : &out.ranges.back();
        if (last && !job.split && !job.markRanges &&
            double(gapTriangles) * params_.tuning.costs.drawNsPerTriangle < params_.tuning.costs.drawNsPerRange) {
            last->indexCount = c.firstIndex + c.indexCount - last->firstIndex;
            out.culledClusters -= gapClusters;  // drawn after all (without a split every gap cluster was culled)
            out.culledTriangles -= gapTriangles;
        } else {
            out.ranges.push_back({c.firstIndex, c.indexCount});
            if (job.markRanges) out.rangeIds.push_back(firstCluster + i);
        }
        gapClusters = 0;
        gapTriangles = 0;
    }
    out.ms = msSince(t0);
}

void QueryScheduler::takeSelection(Frame& f, const ClusterJob& job, ClusterSelection& sel) {
    lastDeferred_ = sel.deferred;
    if (job.pass == ClusterPass::Early) {
        f.stats.clustersDeferred += sel.deferred;
        deferredTriangles_ += sel.deferredTriangles;
    } else if (job.pass == ClusterPass::Deferred) {
        f.stats.deferredClustersDrawn += sel.drawn;
        deferredTriangles_ -= std::min(deferredTriangles_, sel.drawnTriangles);
    }
    f.stats.clustersCulled += sel.culledClusters;
    f.stats.clusterTrianglesCulled += sel.culledTriangles;
    f.stats.clusterPyramidTests += sel.pyramidTests;
    f.stats.clusterMs += sel.ms;
    if (job.keepLearned && job.recordIndex != kInvalidIndex) {
        assert(job.recordIndex < clusterPartLearned_.size() && sel.learned.size() == job.clusters.size());
        // A part tested in both passes (early, then its deferred clusters) is learned from the
        // deferred pass, the only one with a pyramid.
        clusterPartLearned_[job.recordIndex] = static_cast<std::uint32_t>(learnedClusters_.size());
        learnedClusters_.insert(learnedClusters_.end(), sel.learned.begin(), sel.learned.end());
    }
    clusterRanges_.swap(sel.ranges);
    clusterRangeIds_.swap(sel.rangeIds);
}

}  // namespace dyncull
