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

#include "cull_frame.hpp"

namespace dyncull {

namespace {
/// True if cluster `c` of an object with `matrix` (prepared as `object`) shows nothing:
/// outside the frustum (if `frustum`: its part crosses it), or behind the depth pyramid (if
/// `pyramid`). A cluster the eye is inside of or that reaches the near plane is visible
/// (boxDepth says so); one off screen is not.
bool clusterHidden(const QueryScheduler::Frame& f, const DepthPyramid* pyramid, const glm::mat4& matrix, const ObjectProjection& object,
                   const LeafCluster& c, bool frustum) {
    if (frustum && f.frustum().outside(transformAabb(matrix, c.box))) return true;
    if (!pyramid) return false;
    DepthFootprint fp;
    if (!f.screen.boxDepth(object, matrix, c.box, fp)) return false;
    // A pyramid exists only for a single-sample target: a cluster covering no pixel centre draws nothing.
    return fp.centres.empty() || pyramid->occluded(fp.centres, fp.nearest);
}
}  // namespace

bool QueryScheduler::cullClusters(Frame& f, NodeRef ref, const LocalBsp& model, const LocalBspNode& n, ClusterPass pass) {
    clusterRanges_.clear();
    clusterRangeIds_.clear();
    lastDeferred_ = 0;
    if (!params_.features.useClusters || ref.isSceneNode() || !f.sink.drawsRanges() || !model.clusters.builtFor(model.nodes.size()))
        return false;
    const std::span<const LeafCluster> clusters = model.clusters.ofSubtree(ref.node, n.subtreeSize);
    if (clusters.empty()) return false;
    const SceneObjects& objs = f.objects;
    if (f.recordClusterBits && pass != ClusterPass::Deferred) clusterParts_.push_back(ref);  // its bits are written at the frame's end
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
    double& rate = clusterCulledRate_[modelId];
    const std::uint32_t triangles = n.indexCount / 3;
    bool tested = split;
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

    const auto t0 = SchedulerClock::now();
    const glm::mat4& matrix = objs.matrix(ref.object);
    const ObjectProjection object = pyramid ? f.screen.objectProjection(matrix) : ObjectProjection{};
    const std::span<const std::uint64_t> shown = split ? history_.clusterBits(ref.object, objs) : std::span<const std::uint64_t>{};
    const std::uint32_t firstCluster = model.clusters.nodeFirst[ref.node];
    const ObjectSpaceEye eye(f.camera(), matrix);
    // What the tests culled (less the gaps drawn after all), what is left to the other
    // pass, and what is drawn; gap*: the run of undrawn clusters since the last drawn one.
    std::uint64_t culledTriangles = 0, gapTriangles = 0, deferredTriangles = 0, drawnTriangles = 0;
    std::uint32_t culledClusters = 0, gapClusters = 0, deferred = 0, drawn = 0;
    for (std::uint32_t i = 0; i < clusters.size(); ++i) {
        const LeafCluster& c = clusters[i];
        // Deferred: drawn early already. Early: hidden last frame, left to the late pass
        // if it faces the eye and is in the frustum.
        const bool otherPass = split && clusterBit(shown, firstCluster + i) == (pass == ClusterPass::Deferred);
        const bool drawnEarly = pass == ClusterPass::Deferred && otherPass;
        bool culled = !drawnEarly && cones && eye.backFacing(c);
        if (!drawnEarly && !culled && (frustum || pyramid)) culled = clusterHidden(f, pyramid ? &pyramid_ : nullptr, matrix, object, c, frustum);
        if (culled) {
            ++culledClusters;
            culledTriangles += c.indexCount / 3;
        } else if (otherPass) {
            if (!drawnEarly) {
                ++deferred;
                deferredTriangles += c.indexCount / 3;
            }
        }
        if (culled || otherPass) {
            ++gapClusters;
            gapTriangles += c.indexCount / 3;
            continue;
        }
        ++drawn;
        drawnTriangles += c.indexCount / 3;
        // A gap of culled clusters between two drawn ones costs one more range of the
        // multi-draw: skipped only where it saves more drawing than a range costs, and
        // always when it holds clusters the other pass draws.
        IndexRange* last = clusterRanges_.empty() ? nullptr : &clusterRanges_.back();
        if (last && !split && !f.markClusters && double(gapTriangles) * params_.tuning.costs.drawNsPerTriangle < params_.tuning.costs.drawNsPerRange) {
            last->indexCount = c.firstIndex + c.indexCount - last->firstIndex;
            culledClusters -= gapClusters;  // drawn after all (without a split every gap cluster was culled)
            culledTriangles -= gapTriangles;
        } else {
            clusterRanges_.push_back({c.firstIndex, c.indexCount});
            if (f.markClusters) clusterRangeIds_.push_back(firstCluster + i);
        }
        gapClusters = 0;
        gapTriangles = 0;
    }
    if (tested) f.stats.clusterTests += static_cast<std::uint32_t>(clusters.size());
    lastDeferred_ = deferred;
    if (pass == ClusterPass::Early) {
        f.stats.clustersDeferred += deferred;
        deferredTriangles_ += deferredTriangles;
    } else if (pass == ClusterPass::Deferred) {
        f.stats.deferredClustersDrawn += drawn;
        deferredTriangles_ -= std::min(deferredTriangles_, drawnTriangles);
    }
    f.stats.clustersCulled += culledClusters;
    f.stats.clusterTrianglesCulled += culledTriangles;
    if (!split && tested) rate += 0.02 * (double(culledTriangles) / double(triangles > 0 ? triangles : 1) - rate);
    f.stats.clusterMs += msSince(t0);
    return true;
}

}  // namespace dyncull
