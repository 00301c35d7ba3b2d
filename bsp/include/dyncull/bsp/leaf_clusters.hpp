// Clusters: runs of a few dozen consecutive triangles inside each local-BSP leaf, each with
// its own object-space box and normal cone, so that the parts the scheduler draws can be
// thinned further by tests too cheap to need a query: back-facing clusters (the normal
// cone), clusters outside the frustum, clusters behind the depth pyramid. Meshlets in the
// sense of meshoptimizer (meshopt_buildMeshlets, meshopt_computeMeshletBounds); the
// granularity below the BSP that "model only what a scene requires" asks for, paid only
// where a scene gains from it (the scheduler's cost model decides per model).
//
// A cluster is a run of consecutive triangles of its leaf, so a part's surviving clusters
// are index ranges of the same split mesh, drawn with one multi-draw, and no index is ever
// moved at run time. buildLocalBsp orders each leaf so that the runs are meshoptimizer's
// meshlets (optimizeLeafOrder); clustersOf cuts any ordering into runs, so trees from a
// cache or a game's hands get clusters too.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/camera.hpp"
#include "dyncull/objects/mesh.hpp"

namespace dyncull {

struct LocalBspNode;

/// The size of a cluster: half meshoptimizer's recommended meshlet limits for GPUs (64
/// vertices, 124 triangles, as in niagara), since on a CPU rasteriser the triangles a
/// tighter box or normal cone saves outweigh the extra per-cluster tests (measured on the
/// swarm at 16/32, 32/64 and 64/124 in docs/BENCHMARKS.md). A multiple of 4 triangles, as
/// meshopt_buildMeshlets requires.
inline constexpr std::uint32_t kClusterMaxVertices = 32;
inline constexpr std::uint32_t kClusterMaxTriangles = 64;

/// One cluster: triangles [firstIndex, firstIndex + indexCount) of the split mesh, all in
/// one leaf. Object space, like the mesh.
struct LeafCluster {
    Aabb box;                  ///< tight box of its triangles' vertices
    /// Normal cone (meshoptimizer): seen from a point p with
    /// dot(normalize(coneApex - p), coneAxis) >= coneCutoff, every triangle of the cluster
    /// faces away from p. coneCutoff > 1 when the normals spread too far to ever say so.
    glm::vec3 coneApex{0.0f};
    glm::vec3 coneAxis{0.0f, 0.0f, 1.0f};
    float coneCutoff = 2.0f;
    std::uint32_t firstIndex = 0;
    std::uint32_t indexCount = 0;

    /// True only if every triangle of the cluster faces away from `eye` (object space, in
    /// double): the cone test with a margin of kConeMargin on the cosine, and an eye at least
    /// 2^-10 of the box's diagonal from the apex, so that triangles nearly edge-on — which the
    /// rasteriser's rounding may still call front-facing — and the float rounding of the apex
    /// itself never make a visible triangle go undrawn.
    bool backFacingFrom(const glm::dvec3& eye) const;
    /// The same for an orthographic view looking along `direction` (object space, any length).
    bool backFacingAlong(const glm::dvec3& direction) const;
    /// Margin on the cone's cosine: about 0.06 degrees.
    static constexpr double kConeMargin = 0x1p-10;
};

/// The eye as an object sees it, for the clusters' normal-cone test: the world-space
/// camera taken into the space of an object with the affine `objectToWorld`, in double
/// (affine maps keep which side of a plane a point is on, mirroring included, as the
/// rasteriser's facing follows the transformed winding). Holds values only.
struct ObjectSpaceEye {
    ObjectSpaceEye() = default;
    ObjectSpaceEye(const Camera& camera, const glm::mat4& objectToWorld) : ortho(camera.orthographic()) {
        const glm::dmat4 toObject = glm::inverse(glm::dmat4(objectToWorld));
        eye = glm::dvec3(toObject * glm::dvec4(glm::dvec3(camera.position), 1.0));
        along = glm::dvec3(toObject * glm::dvec4(glm::dvec3(camera.forward()), 0.0));
    }
    /// True only if every triangle of `c` faces away from the eye (LeafCluster::backFacingFrom).
    bool backFacing(const LeafCluster& c) const { return ortho ? c.backFacingAlong(along) : c.backFacingFrom(eye); }

    bool ortho = false;
    glm::dvec3 eye{0.0}, along{0.0};  ///< the eye point, and the view direction (orthographic)
};

/// Every leaf's clusters, in leaf order, and per node where they start: node i's subtree
/// (a leaf, or an inner node drawn whole) has clusters [nodeFirst[i], nodeFirst[i +
/// subtreeSize]), since nodes and leaf triangles are both stored depth-first. Owned by its
/// LocalBsp, indexed like its nodes (nodeFirst has nodes + 1 entries).
struct LeafClusters {
    std::vector<LeafCluster> clusters;
    std::vector<std::uint32_t> nodeFirst;

    bool builtFor(std::size_t nodeCount) const { return nodeFirst.size() == nodeCount + 1; }
    /// The clusters of node `node`'s subtree; `subtreeSize` is the node's.
    std::span<const LeafCluster> ofSubtree(std::uint32_t node, std::uint32_t subtreeSize) const {
        return {clusters.data() + nodeFirst[node], clusters.data() + nodeFirst[node + subtreeSize]};
    }
};

/// Cuts each leaf's triangles, in their stored order, into runs of at most
/// kClusterMaxTriangles triangles and kClusterMaxVertices distinct vertices (a greedy scan,
/// so a leaf ordered by optimizeLeafOrder gives back meshoptimizer's meshlets), and
/// computes their boxes and normal cones. A tree whose ranges do not fit `mesh` (a
/// hand-built tree without triangles) gets no clusters in its leaves. O(indices).
LeafClusters clustersOf(const Mesh& mesh, const std::vector<LocalBspNode>& nodes);

}  // namespace dyncull
