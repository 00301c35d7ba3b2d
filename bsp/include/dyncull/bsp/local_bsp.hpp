// Local axis-aligned BSP of one mesh, built once in object space and shared by every
// instance of the mesh (the instance transform is applied at traversal time).
// Paper: Two-level BSP for dynamic occlusion culling, section 3.1 (object partitioning);
// split cost option from Scene subdivision for occlusion culling, section 3.2 (p-HBVO SAH).
#pragma once

#include <span>

#include <cstdint>
#include <limits>
#include <vector>

#include "dyncull/bsp/leaf_clusters.hpp"
#include "dyncull/bsp/node_volumes.hpp"
#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/error.hpp"
#include "dyncull/objects/mesh.hpp"
#include "dyncull/objects/surface_orientation.hpp"

namespace dyncull {

inline constexpr std::uint32_t kInvalidIndex = std::numeric_limits<std::uint32_t>::max();

/// Largest accepted LocalBspParams::maxDepth (bounds the builder's recursion).
inline constexpr std::uint32_t kLocalBspMaxDepth = 64;

enum class SplitMethod : std::uint8_t {
    SpatialMedian,  ///< middle of the longest axis of the node box (the two-level paper)
    Sah,            ///< surface-area heuristic over triangle barycentres (p-HBVO cost)
};

/// Which faces of a model are drawn.
enum class FacePolicy : std::uint8_t {
    /// Decided from the surface (orientSurface): back faces culled only where every shell
    /// is closed and outward, so no hole shows them; inward shells are flipped first.
    Auto,
    /// Culled whatever the surface: an open mesh shows what is behind it through its holes
    /// (inward shells are still flipped). An approximation; compare with Auto to measure it.
    CullBack,
    /// Both sides always; the surface is not analysed.
    TwoSided,
};

/// Defaults tuned on the Stanford bunny (69,451 triangles): 24 leaves, +9.6% triangles
/// with SpatialMedian (22 leaves, +9.6% with Sah); the paper reports 23 parts, +10%.
struct LocalBspParams {
    std::uint32_t maxLeafTriangles = 5000;  ///< stop splitting at or below this many triangles
    std::uint32_t maxDepth = 16;            ///< root has depth 0; at most kLocalBspMaxDepth
    SplitMethod method = SplitMethod::SpatialMedian;
    /// Search window, as a fraction of the node extent along the split axis, in which the
    /// plane may be nudged to cut fewer triangles (0 disables nudging).
    float nudgeFraction = 0.1f;
    FacePolicy faces = FacePolicy::Auto;
    /// Reorder the triangles inside each leaf for the vertex cache and for overdraw
    /// (optimizeLeafOrder); false keeps them in input order (to measure what it gives).
    bool optimizeOrder = true;
    /// With optimizeOrder: the last reordering gathers each leaf's triangles into
    /// meshoptimizer's meshlets, so its clusters are tight; false stops at the cache and
    /// overdraw order (clusters are then cut from it, to measure what the meshlets give).
    bool clusterOrder = true;
};

/// One node. Nodes are stored depth-first (a node's subtree is the contiguous index range
/// [self, self + subtreeSize)), and so are leaf triangles: the triangles of any node's
/// subtree form one contiguous range [firstIndex, firstIndex + indexCount) of
/// LocalBsp::mesh.indices, so a leaf — or a whole visible subtree — is one draw call.
struct LocalBspNode {
    Aabb box;  ///< tight object-space box of the subtree's (clipped) triangles; empty for an empty mesh
    /// [below, above] the plane; invalid for leaves. children[0] == self + 1 always. A vertex
    /// within a tiny band around the plane (1e-5 of the node size) counts as on it, so a
    /// child's box may reach past `split` by that much; triangles in the plane go below.
    std::uint32_t children[2] = {kInvalidIndex, kInvalidIndex};
    std::uint32_t firstIndex = 0;  ///< into LocalBsp::mesh.indices
    std::uint32_t indexCount = 0;  ///< 3 x triangles of the whole subtree
    std::uint32_t subtreeSize = 1;  ///< nodes in this subtree including itself
    float split = 0.0f;  ///< plane position along `axis` (inner nodes)
    std::uint8_t axis = 0;  ///< 0 = x, 1 = y, 2 = z (inner nodes)
    std::uint8_t depth = 0;

    bool isLeaf() const { return children[0] == kInvalidIndex; }
};

struct LocalBspStats {
    std::size_t trianglesBefore = 0;
    std::size_t trianglesAfter = 0;  ///< after clipping and re-triangulation
    std::uint32_t leaves = 0;
    std::uint32_t depth = 0;  ///< deepest leaf depth
    /// Leaves left above maxLeafTriangles (below maxDepth) because no plane on any axis
    /// made progress, i.e. gave both children fewer triangles than the node (degenerate
    /// input: identical, stacked or mostly-cut triangles).
    std::uint32_t stalledLeaves = 0;
    double buildMs = 0.0;  ///< including the node volumes
};

/// A vertex the splitting added where an edge crossed a plane: (1 - t) * vertex a + t * vertex b
/// (indices of earlier vertices of the split mesh, a < b, t in [0, 1]).
struct SplitVertex {
    std::uint32_t a = 0, b = 0;
    float t = 0.0f;
};

/// The split mesh and its tree. Owns both. A mesh at or below maxLeafTriangles gets a
/// single leaf root (no tree), so traversal code never special-cases it.
struct LocalBsp {
    Mesh mesh;  ///< the input re-triangulated along split planes, indices ordered by leaf
    /// Provenance of mesh's vertices, so a game can carry its own vertex attributes through
    /// the split (carryAttributes): the first sourceVertexCount vertices are the input's, at
    /// their indices; vertex sourceVertexCount + i is splitVertices[i]. Both are empty/0 for a
    /// BSP made without them (by hand, or read from a file that does not store them).
    std::uint32_t sourceVertexCount = 0;
    std::vector<SplitVertex> splitVertices;
    std::vector<LocalBspNode> nodes;  ///< nodes[0] is the root
    /// Each node's query volumes (object space), indexed like `nodes`. Filled by
    /// buildLocalBsp; a hand-made or cache-loaded LocalBsp gets them in SceneObjects::addModel.
    NodeVolumes volumes;
    /// Each leaf's clusters (object space). Filled by buildLocalBsp; a hand-made or
    /// cache-loaded LocalBsp gets them in SceneObjects::addModel, cut from its index order.
    LeafClusters clusters;
    /// How the renderer and the ground truth draw `mesh` (see FacePolicy).
    FaceMode faces = FaceMode::TwoSided;
    /// Triangles a draw of the whole model costs when `mesh` only stands for it (a bounds
    /// model, buildBoundsModel), for the scheduler's cost model; 0: the mesh's own.
    std::uint32_t drawTriangles = 0;
    LocalBspStats stats;

    const LocalBspNode& root() const { return nodes[0]; }
    bool hasTree() const { return nodes.size() > 1; }
};

/// Builds the BSP of `mesh` (object space; not modified, not retained). The result owns
/// a copy of the mesh with every original vertex kept at its index, new vertices appended
/// where edges cross split planes (normals interpolated, or computed first when the input
/// has none), and indices reordered by leaf. Splitting stops at maxLeafTriangles, at
/// maxDepth, or when no plane gives both children fewer triangles (stats.stalledLeaves).
/// Every node's query volumes are computed too (buildNodeVolumes). The face mode follows
/// params.faces; with Auto or CullBack, shells wound inwards are flipped before splitting.
/// Errors (never asserts) for an invalid mesh (validateMesh) or parameters:
/// maxLeafTriangles == 0, maxDepth > kLocalBspMaxDepth, nudgeFraction not in [0, 0.5].
/// An empty mesh gives a single empty leaf.
Expected<LocalBsp> buildLocalBsp(const Mesh& mesh, const LocalBspParams& params = {});

/// A model for an object the game draws whole and describes by its bounds only (object
/// space): the mesh is the box (12 outward triangles, so the part renderer can show it),
/// the one part is the whole object, and the cost model counts `triangles` for a draw of it
/// (what the game's object really costs). The draw callback gets the box's index range and
/// draws its own object instead. Errors: an empty or non-finite box, or 0 triangles.
Expected<LocalBsp> buildBoundsModel(const Aabb& bounds, std::uint32_t triangles);

/// A game's per-vertex data for the input mesh (`components` floats per vertex, in vertex
/// order: texture coordinates, tangents, colours, skinning weights...) extended to every
/// vertex of the split mesh, the added ones interpolated along their edges exactly as their
/// positions were, so the index ranges of the BSP's parts can be drawn from the game's own
/// vertex buffer. Errors: components 0, a size that is not sourceVertexCount x components,
/// or a BSP without provenance (see LocalBsp::sourceVertexCount).
Expected<std::vector<float>> carryAttributes(const LocalBsp& bsp, std::span<const float> attributes,
                                             std::uint32_t components);

/// Reorders the triangles inside each leaf of `bsp` for the post-transform vertex cache, then
/// for overdraw, then (with `meshlets`) into meshoptimizer's meshlets, each again in
/// vertex-cache order, so that clustersOf cuts the leaf into tight clusters; every node
/// keeps its index range and triangle set.
void optimizeLeafOrder(LocalBsp& bsp, bool meshlets = true);

}  // namespace dyncull
