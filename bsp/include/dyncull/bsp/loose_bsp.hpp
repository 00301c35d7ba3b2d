// Global loose BSP over object world boxes: an object lives in the smallest node whose
// cell fully contains its box (inner nodes included); objects are never split.
// Paper: Two-level BSP for dynamic occlusion culling, section 3.2 (scene partitioning,
// per-frame relinking and lazy reconstruction).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "dyncull/bsp/scene_objects.hpp"
#include "dyncull/objects/aabb.hpp"

namespace dyncull {

struct LooseBspParams {
    std::uint32_t maxObjectsPerLeaf = 4;  ///< split a leaf cell holding more than this
    std::uint32_t maxDepth = 24;
    /// A subtree is rebuilt when its object count differs from what it was built for by
    /// more than this factor (or one child holds nearly everything).
    float imbalanceFactor = 2.0f;
    /// Per-frame wall-clock budget for lazy rebuilds (milliseconds). <= 0 disables them.
    /// Unused budget is saved (up to 64 frames' worth) for a subtree too big for one frame;
    /// one whose estimated cost exceeds even the saved budget runs once the saving is full.
    /// Rebuild decisions depend on measured time, so for bit-identical runs use 0 or a
    /// budget large enough that every pending rebuild fits.
    double rebuildBudgetMs = 0.5;
};

/// One node of the flat node array with a free list; 32-bit indices. Node 0 is the root.
struct LooseBspNode {
    Aabb cell;  ///< the subdivision region (fixed between rebuilds, grows at the root)
    Aabb box;   ///< tight union of everything in the subtree (world space)
    std::uint32_t children[2] = {kInvalidIndex, kInvalidIndex};
    std::uint32_t parent = kInvalidIndex;
    std::uint32_t firstObject = kInvalidIndex;  ///< head of the intrusive list of objects in this node
    std::uint32_t objectCount = 0;      ///< objects linked directly here
    std::uint32_t subtreeObjects = 0;   ///< objects in the whole subtree
    std::uint32_t builtSubtreeObjects = 0;  ///< subtreeObjects when this subtree was last built
    float split = 0.0f;  ///< world-space plane; children[0] is the cell below it
    std::uint8_t axis = 0;
    std::uint8_t depth = 0;
    std::uint8_t flags = 0;  ///< internal bookkeeping (free / dirty / rebuild candidate)
    bool isLeaf() const { return children[0] == kInvalidIndex; }
};

struct LooseBspFrameStats {
    std::uint32_t relinked = 0;  ///< objects that changed node
    std::uint32_t rebuilds = 0;  ///< subtrees rebuilt this frame
    std::uint32_t rootGrowths = 0;
    double updateMs = 0.0;
};

/// Owns its nodes and per-object links; refers to objects by SceneObjects slot index and
/// does not keep a pointer to the SceneObjects (pass the same one to build/update/validate).
/// Split choice: median of the object box centres along the cell's longest axis (other axes
/// tried when that separates nothing) — it keeps the tree balanced for clustered crowds,
/// where the spatial middle would build long chains of nearly empty cells. Objects
/// straddling the plane stay in the node. A node stays a leaf at maxDepth or when no axis
/// sends objects to both sides (e.g. many objects at one position).
class LooseBsp {
public:
    explicit LooseBsp(LooseBspParams params = {}) : params_(params) {}

    /// Builds from scratch over all live objects (consumes added/removed/moved lists).
    void build(SceneObjects& objects);
    /// Per frame: link added, unlink removed, relink moved objects, refit boxes, and spend up
    /// to rebuildBudgetMs on lazy subtree rebuilds. Static objects that did not move cost nothing.
    LooseBspFrameStats update(SceneObjects& objects);

    const std::vector<LooseBspNode>& nodes() const { return nodes_; }
    std::uint32_t root() const { return 0; }
    /// Next object in the node's list, or kInvalidIndex.
    std::uint32_t nextObject(std::uint32_t object) const { return next_[object]; }
    std::uint32_t nodeOf(std::uint32_t object) const { return node_[object]; }

    std::uint32_t depth() const;  ///< deepest live node
    std::uint32_t nodeCount() const;  ///< live nodes (excludes the free list)
    /// Heap bytes held: node array, free list, per-object links and scratch arrays (capacity).
    std::size_t memoryBytes() const;
    /// Checks every invariant (each live object in exactly one node, the smallest containing
    /// it; node boxes contain contents; counts). Returns "" when valid. For tests.
    std::string validate(const SceneObjects& objects) const;

    const LooseBspParams& params() const { return params_; }

private:
    std::uint32_t allocNode();
    void freeSubtreeBelow(std::uint32_t n);
    Aabb buildNode(std::uint32_t n, const SceneObjects& objects, std::uint32_t* begin, std::uint32_t* end);
    void link(std::uint32_t object, std::uint32_t n);
    void unlink(std::uint32_t object);
    std::uint32_t descend(std::uint32_t from, const Aabb& box) const;
    void growRoot(const Aabb& box);
    void addCounts(std::uint32_t from, std::uint32_t to, int delta);
    void markDirty(std::uint32_t n);
    void refitDirty(const SceneObjects& objects);
    float imbalance(std::uint32_t n) const;
    void noteCounts(std::uint32_t n);
    void rebuildSubtree(std::uint32_t n, const SceneObjects& objects);
    std::uint32_t lazyRebuild(const SceneObjects& objects);
    void ensureSlots(std::uint32_t slots);
    void insertObject(std::uint32_t object, const Aabb& box);
    bool relink(std::uint32_t object, const Aabb& box);

    LooseBspParams params_;
    std::vector<LooseBspNode> nodes_;
    std::vector<std::uint32_t> freeNodes_;
    std::vector<std::uint32_t> node_, next_, prev_;  // per object slot
    // Per-frame scratch, kept to reuse capacity (no allocation in steady state).
    std::vector<std::vector<std::uint32_t>> dirtyByDepth_;
    std::vector<std::uint32_t> candidates_, gather_, walk_;
    std::vector<std::pair<float, std::uint32_t>> ranked_;
    float buildMargin_ = 0.0f;      // world units; root cell slack, scaled to the scene
    double rebuildCreditMs_ = 0.0;  // unused rebuild budget saved from earlier frames
    double rebuildNsPerObject_ = 200.0;  // running estimate of rebuild cost
    std::uint32_t rootGrowths_ = 0;
};

}  // namespace dyncull
