// Cluster culling: a part the traversal decided to draw is drawn as those of its clusters
// (runs of about a hundred triangles, leaf_clusters.hpp) that survive tests far cheaper
// than any query, in one multi-draw: the normal-cone back-face test (Wihlidal, "Optimizing
// the Graphics Pipeline with Compute", 2016), the frustum, and in the two-phase late pass
// the depth pyramid, as GPU-driven engines cull meshlets (niagara; see
// ../shared/notes/batched-occlusion-tests.md). The finer level of "model only what a scene
// requires": the BSP's parts stay the unit of queries and history, clusters are tested
// only through these cheap paths, and only where the measured savings pay for the tests.

#include "cull_frame.hpp"

namespace dyncull {


bool QueryScheduler::cullClusters(Frame& f, NodeRef ref, const LocalBsp& model, const LocalBspNode& n) {
    clusterRanges_.clear();
    if (!params_.features.useClusters || ref.isSceneNode() || !f.sink.drawsRanges() || !model.clusters.builtFor(model.nodes.size()))
        return false;
    const std::span<const LeafCluster> clusters = model.clusters.ofSubtree(ref.node, n.subtreeSize);
    if (clusters.empty()) return false;
    const SceneObjects& objs = f.objects;
    // Which tests can cull anything here: cones only where back faces are culled, the
    // frustum only for a part crossing it, the pyramid only after the early pass.
    const bool cones = model.faces == FaceMode::CullBack && f.sink.cullsBackFaces();
    const bool frustum = f.frustum().classify(f.tree.worldBox(ref)) != Frustum::Side::Inside;
    const bool pyramid = f.clusterPyramid;
    if (!cones && !frustum && !pyramid) return false;
    if (!cones && !pyramid && clusters.size() == 1) return false;  // the part's own frustum test said it all

    // The cost model: a model's clusters are tested while the drawing they were measured
    // to save (its rate of culled triangles) exceeds the tests' cost; one part in eight
    // is tested regardless, so the rate stays measured.
    const ModelId modelId = objs.modelOf(ref.object);
    if (clusterCulledRate_.size() <= modelId) clusterCulledRate_.resize(modelId + 1, 0.5);
    double& rate = clusterCulledRate_[modelId];
    const std::uint32_t triangles = n.indexCount / 3;
    if (params_.features.useCostModel && !exploring(ref) &&
        rate * triangles * params_.tuning.costs.drawNsPerTriangle < double(clusters.size()) * params_.tuning.costs.clusterTestNs)
        return false;

    const auto t0 = SchedulerClock::now();
    const glm::mat4& matrix = objs.matrix(ref.object);
    // The eye in the object's space (affine maps keep which side of a plane a point is on,
    // mirroring included, as the rasteriser's facing follows the transformed winding).
    const glm::dmat4 toObject = glm::inverse(glm::dmat4(matrix));
    const bool ortho = f.camera().orthographic();
    const glm::dvec3 eye = glm::dvec3(toObject * glm::dvec4(glm::dvec3(f.camera().position), 1.0));
    const glm::dvec3 along = glm::dvec3(toObject * glm::dvec4(glm::dvec3(f.camera().forward()), 0.0));
    std::uint64_t culledTriangles = 0, gapTriangles = 0;
    std::uint32_t culledClusters = 0, gapClusters = 0;
    for (const LeafCluster& c : clusters) {
        bool culled = cones && (ortho ? c.backFacingAlong(along) : c.backFacingFrom(eye));
        if (!culled && (frustum || pyramid)) {
            const Aabb world = transformAabb(matrix, c.box);
            culled = frustum && f.frustum().outside(world);
            if (!culled && pyramid && !world.contains(f.camera().position)) {
                ScreenRect rect;
                float nearest = 1.0f;
                // A cluster reaching the near plane is visible; one off screen shows nothing.
                if (f.screen.volumeDepth(QueryVolume::fromTransformedBox(matrix, c.box), rect, nearest))
                    culled = rect.empty() || pyramid_.occluded(rect, nearest);
            }
        }
        if (culled) {
            ++gapClusters;
            gapTriangles += c.indexCount / 3;
            continue;
        }
        // A gap of culled clusters between two drawn ones costs one more range of the
        // multi-draw: skipped only where it saves more drawing than a range costs.
        IndexRange* last = clusterRanges_.empty() ? nullptr : &clusterRanges_.back();
        if (last && double(gapTriangles) * params_.tuning.costs.drawNsPerTriangle < params_.tuning.costs.drawNsPerRange) {
            last->indexCount = c.firstIndex + c.indexCount - last->firstIndex;
        } else {
            clusterRanges_.push_back({c.firstIndex, c.indexCount});
            culledClusters += gapClusters;
            culledTriangles += gapTriangles;
        }
        gapClusters = 0;
        gapTriangles = 0;
    }
    culledClusters += gapClusters;  // after the last drawn one: costs no range
    culledTriangles += gapTriangles;
    f.stats.clusterTests += static_cast<std::uint32_t>(clusters.size());
    f.stats.clustersCulled += culledClusters;
    f.stats.clusterTrianglesCulled += culledTriangles;
    f.stats.clusterMs += msSince(t0);
    rate += 0.02 * (double(culledTriangles) / double(triangles > 0 ? triangles : 1) - rate);
    return true;
}

}  // namespace dyncull
