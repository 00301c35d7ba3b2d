// Subdividing a static model (one triangle soup, e.g. a CAD model or a whole power plant
// merged into one mesh) into subdivision entities that become the objects of the global
// loose BSP. Every method assigns each whole triangle to exactly one leaf (no triangle is
// ever split) and orders triangles so that every subtree is one contiguous range.
// Paper: Scene subdivision for occlusion culling (Bartz, Meißner, Hüttner), section 3:
//   p-HBVO (3.2)   bsp/src/subdivide_phbvo.cpp   SAH over barycentres, sorted or binned
//   D-BVS (3.1)    bsp/src/subdivide_dbvs.cpp    slabs along the largest dimension
//   octree (3.4)   bsp/src/subdivide_octree.cpp  load-balanced planes (SGI opoptimize)
//   grid (3.3)     bsp/src/subdivide_octree.cpp  regular octree (ORSD, counting triangles)
// and section 4's collapse of binary trees to 4-ary ones (bsp/src/subdivision_collapse.cpp).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dyncull/bsp/local_bsp.hpp"
#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/error.hpp"
#include "dyncull/objects/mesh.hpp"

namespace dyncull {

enum class SubdivisionMethod : std::uint8_t {
    Phbvo,   ///< binary, surface-area cost over triangle barycentres (paper 3.2)
    Dbvs,    ///< n-ary slabs along the largest dimension, planes moved, big triangles pulled up (3.1)
    Octree,  ///< 8 children, split planes at the median barycentre on x, then y, then z (3.4)
    Grid,    ///< regular octree: octants of a cube, triangles by barycentre (3.3)
};
const char* toString(SubdivisionMethod m);
/// "phbvo", "dbvs", "octree" or "grid"; the error lists them.
Expected<SubdivisionMethod> parseSubdivisionMethod(const std::string& name);

struct SubdivisionParams {
    SubdivisionMethod method = SubdivisionMethod::Phbvo;
    /// The paper's Max_Triangles_Per_Subdivision_Entity: a node with at most this many
    /// triangles is a leaf. Leaves exceed it only at maxDepth (stats.oversizedLeaves).
    std::uint32_t maxLeafTriangles = 2000;
    /// The paper's Max_Subdivision_Depth (root depth 0), at most kSubdivisionMaxDepth.
    std::uint32_t maxDepth = 32;
    /// p-HBVO: nodes with more triangles than this evaluate the SAH at bin boundaries
    /// (sahBins per axis); smaller nodes sort their barycentres on all three axes and
    /// evaluate every position, as the paper does.
    std::uint32_t exactBelow = 4096;
    std::uint32_t sahBins = 32;  ///< 2 .. 256
    /// D-BVS: a plane may move by up to this fraction of the slab width to cut fewer
    /// triangles, in [0, 0.5).
    float planeMove = 0.25f;
    /// D-BVS: a triangle longer than this many slab widths along the split axis is pulled
    /// up into its own child of the node instead of stretching a slab's box (0 disables).
    float pullUpWidths = 1.0f;
    /// > 0: collapse the finished tree so inner nodes have up to this many children
    /// (4 turns p-HBVO's binary tree into the paper's quad tree). 0 keeps the tree.
    std::uint32_t collapseTo = 0;
    /// Worker threads (1 .. 64). The result does not depend on it.
    unsigned threads = 2;
};

inline constexpr std::uint32_t kSubdivisionMaxDepth = 48;

/// Checks every parameter's range; the message names the parameter.
Status validateSubdivisionParams(const SubdivisionParams& params);

/// One subdivision entity. Children of a node are contiguous in Subdivision::nodes and
/// always come after it; a node's triangles are the contiguous range
/// [firstTriangle, firstTriangle + triangleCount) of Subdivision::triangles, which its
/// children tile in order.
struct SubdivisionNode {
    Aabb box;  ///< tight box of the subtree's triangles, in the mesh's space
    std::uint32_t firstChild = kInvalidIndex;
    std::uint32_t childCount = 0;  ///< 0 for a leaf
    std::uint32_t firstTriangle = 0;
    std::uint32_t triangleCount = 0;
    std::uint32_t depth = 0;  ///< root 0; a collapsed tree keeps the depth of the tree it came from
    bool isLeaf() const { return childCount == 0; }
};

struct SubdivisionStats {
    std::uint32_t nodes = 0;
    std::uint32_t leaves = 0;
    std::uint32_t inner = 0;            ///< nodes - leaves (the paper's "subdivision nodes")
    std::uint32_t depth = 0;            ///< deepest leaf
    std::uint32_t largestLeaf = 0;      ///< triangles
    std::uint32_t oversizedLeaves = 0;  ///< leaves above maxLeafTriangles because of maxDepth
    std::uint32_t maxChildren = 0;
    double buildMs = 0.0;
    /// Peak bytes of the builder's own arrays (per-triangle barycentres, boxes and order,
    /// node arrays, scratch), excluding the input mesh.
    std::size_t workBytes = 0;
};

/// Owns its nodes and triangle order. Triangle ids index the source mesh (id t is
/// indices[3t .. 3t+2]) until applyTriangleOrder makes the order the mesh's own.
struct Subdivision {
    SubdivisionMethod method = SubdivisionMethod::Phbvo;
    std::vector<SubdivisionNode> nodes;    ///< nodes[0] is the root; empty mesh: one empty leaf
    std::vector<std::uint32_t> triangles;  ///< triangle ids in leaf order (empty after applyTriangleOrder)
    SubdivisionStats stats;

    /// Triangle id at position `i` of the leaf order.
    std::uint32_t triangleAt(std::uint32_t i) const { return triangles.empty() ? i : triangles[i]; }
};

/// Subdivides `mesh` (not modified, not retained). Deterministic: the same mesh and
/// parameters give the same result for any thread count. Errors (never asserts) for an
/// invalid mesh (validateMesh), more than 2^32-2 triangles, or parameters out of range.
Expected<Subdivision> subdivide(const Mesh& mesh, const SubdivisionParams& params);

/// Collapses inner nodes so each has at most `maxChildren` (>= 2) children: repeatedly
/// replaces the child with the largest box surface (an inner one) by its own children
/// while the count allows. Leaves and the triangle order are unchanged.
void collapseSubdivision(Subdivision& sub, std::uint32_t maxChildren);

/// Recomputes the count fields of sub.stats (nodes, leaves, inner, depth, largestLeaf,
/// oversizedLeaves, maxChildren) from the nodes; buildMs and workBytes are kept.
void recountSubdivisionStats(Subdivision& sub, std::uint32_t maxLeafTriangles);

/// Reorders mesh.indices into the subdivision's leaf order and clears sub.triangles, so
/// node ranges index the mesh's triangles directly. `mesh` must be the subdivided mesh.
void applyTriangleOrder(Mesh& mesh, Subdivision& sub);

/// One model per leaf, in node order: the leaf's triangles as a compact mesh (only the
/// vertices it uses, normals copied, computed first when `mesh` has none) with a
/// single-leaf local BSP, so each leaf is one object and one draw. Mesh space becomes the
/// objects' world space (identity transforms). Names are "<mesh name>/leaf<i>". Each leaf
/// is drawn with `faces`, the whole mesh's face mode (a leaf alone is an open piece), and
/// its triangles are in optimizeLeafOrder's order.
std::vector<LocalBsp> subdivisionLeafModels(const Mesh& mesh, const Subdivision& sub,
                                            FaceMode faces = FaceMode::TwoSided);

/// Checks every invariant against `mesh`, by brute force (the tests' oracle and the file
/// reader's check): each triangle exactly once; children contiguous, after their parent,
/// tiling its range; leaf limits (maxLeafTriangles unless at maxDepth); boxes finite and
/// equal to the union of their triangles' boxes. Returns "" when valid, else the first problem.
std::string validateSubdivision(const Mesh& mesh, const Subdivision& sub, std::uint32_t maxLeafTriangles,
                                std::uint32_t maxDepth);

/// p-HBVO cost of a split, without the common 1/S(H): S(left) |left| + S(right) |right|,
/// boxes over whole triangles.
struct PhbvoSplit {
    int axis = -1;          ///< -1: no split separates anything (all barycentres equal)
    std::uint32_t left = 0; ///< triangles in the left part (barycentres sorted on `axis`)
    float cost = 0.0f;
};
/// The paper's exact evaluation: barycentres sorted on each axis, every position tried
/// (O(n log n)). `tris` are triangle ids of `mesh`. Exposed for tests.
PhbvoSplit phbvoBestSplitSorted(const Mesh& mesh, std::span<const std::uint32_t> tris);
/// Brute-force reference of phbvoBestSplitSorted: every position of every axis with the
/// boxes recomputed from scratch (O(n^2)); the tests' oracle. In bsp/src/brute_force.cpp.
PhbvoSplit phbvoBestSplitBruteForce(const Mesh& mesh, std::span<const std::uint32_t> tris);

}  // namespace dyncull
