// Global loose BSP over object world boxes: an object lives in the smallest node whose
// cell fully contains its box (inner nodes included); objects are never split.
// Paper: Two-level BSP for dynamic occlusion culling, section 3.2 (scene partitioning,
// per-frame relinking and lazy reconstruction).
#pragma once

#include <cstdint>
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
    double rebuildBudgetMs = 0.5;  ///< per-frame time budget for lazy rebuilds
};

/// Flat node array with a free list; 32-bit indices. Node 0 is the root.
struct LooseBspNode {
    Aabb cell;  ///< the subdivision region (fixed between rebuilds, grows at the root)
    Aabb box;   ///< tight union of everything in the subtree (world space)
    std::uint32_t children[2] = {kInvalidIndex, kInvalidIndex};
    std::uint32_t parent = kInvalidIndex;
    std::uint32_t firstObject = kInvalidIndex;  ///< head of the intrusive list of objects in this node
    std::uint32_t objectCount = 0;      ///< objects linked directly here
    std::uint32_t subtreeObjects = 0;   ///< objects in the whole subtree
    std::uint32_t builtSubtreeObjects = 0;  ///< subtreeObjects when this subtree was last built
    float split = 0.0f;
    std::uint8_t axis = 0;
    std::uint8_t depth = 0;
    bool isLeaf() const { return children[0] == kInvalidIndex; }
};

struct LooseBspFrameStats {
    std::uint32_t relinked = 0;  ///< objects that changed node
    std::uint32_t rebuilds = 0;  ///< subtrees rebuilt this frame
    std::uint32_t rootGrowths = 0;
    double updateMs = 0.0;
};

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
    std::size_t memoryBytes() const;  ///< nodes + per-object links
    /// Checks every invariant (each live object in exactly one node, the smallest containing
    /// it; node boxes contain contents; counts). Returns "" when valid. For tests.
    std::string validate(const SceneObjects& objects) const;

private:
    LooseBspParams params_;
    std::vector<LooseBspNode> nodes_;
    std::vector<std::uint32_t> freeNodes_;
    std::vector<std::uint32_t> node_, next_, prev_;  // per object slot
};

}  // namespace dyncull
