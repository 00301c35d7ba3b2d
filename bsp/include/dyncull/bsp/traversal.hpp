// Front-to-back traversal of the two-level hierarchy (global loose BSP, then each object's
// local BSP with its transform applied). The scheduler drives it; nothing here draws.
// Paper: Two-level BSP for dynamic occlusion culling, section 3.3 (traversing the structures)
// and Algorithm 4 (ProcessVisibleNode ordering).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/bsp/loose_bsp.hpp"
#include "dyncull/bsp/scene_objects.hpp"
#include "dyncull/objects/camera.hpp"

namespace dyncull {

/// A node of either level: object == kInvalidIndex names loose-BSP node `node`;
/// otherwise `node` is a local-BSP node of object slot `object`'s model.
struct NodeRef {
    std::uint32_t object = kInvalidIndex;
    std::uint32_t node = kInvalidIndex;
    bool isSceneNode() const { return object == kInvalidIndex; }
    friend bool operator==(const NodeRef&, const NodeRef&) = default;
    /// By object slot, then node (the order of visible sets and drawn-part lists).
    friend bool operator<(const NodeRef& a, const NodeRef& b) {
        return a.object != b.object ? a.object < b.object : a.node < b.node;
    }
};

/// A mixed 32-bit hash of a node (multiplicative, per field), for spreading per-node work
/// such as re-tests over frames.
inline std::uint32_t hashNode(NodeRef r) { return (r.object * 2654435761u) ^ (r.node * 2246822519u); }

/// Read-only view over a scene's two levels. Cheap to construct each frame; does not own.
class TwoLevelTree {
public:
    TwoLevelTree(const LooseBsp& scene, const SceneObjects& objects) : scene_(&scene), objects_(&objects) {}

    NodeRef root() const { return {kInvalidIndex, scene_->root()}; }
    /// World-space box of the node (local boxes transformed by the object's matrix).
    Aabb worldBox(NodeRef ref) const;
    /// True for a local-BSP leaf: drawable as one index range.
    bool isDrawable(NodeRef ref) const;
    /// Children to process once `ref` is known visible, front-to-back for eye position `eye`
    /// (world space), appended to `out`: for a scene node its near child, its objects
    /// (as their local roots) sorted by box-centre distance, then its far child; for a
    /// local inner node its near then far child; nothing for a leaf. Empty children skipped.
    void expand(NodeRef ref, const glm::vec3& eye, std::vector<NodeRef>& out) const;

    const LooseBsp& scene() const { return *scene_; }
    const SceneObjects& objects() const { return *objects_; }

private:
    const LooseBsp* scene_;
    const SceneObjects* objects_;
};

/// Visitor-style iterator: yields nodes front-to-back; after each yielded node the caller
/// says whether to descend into it. Used by vfc mode and tests; the occlusion scheduler
/// uses TwoLevelTree::expand directly to interleave queries.
class FrontToBackIterator {
public:
    FrontToBackIterator(const TwoLevelTree& tree, const glm::vec3& eye);
    /// Next node, or false when done. Starts with the root (nothing at all for an empty scene).
    bool next(NodeRef& out);
    /// Descend into the node last returned by next() (otherwise its subtree is skipped).
    void descend();

private:
    const TwoLevelTree* tree_;
    glm::vec3 eye_;
    std::vector<NodeRef> stack_;
    std::vector<NodeRef> scratch_;
    NodeRef current_;
};

/// Brute-force reference: every non-empty local leaf (indexCount > 0; a single-leaf root is
/// always included) of every live object whose own world box (leaf box under the object's
/// matrix) is not outside the frustum, by a linear scan of objects (no hierarchy), in slot
/// then node order. Equals the drawable nodes FrontToBackIterator yields when the caller
/// descends exactly into the nodes not outside the frustum (boxes nest, classify is monotone).
/// The tests' oracle. Returns a new vector (owned by the caller).
std::vector<NodeRef> frustumLeavesBruteForce(const SceneObjects& objects, const Frustum& frustum);

}  // namespace dyncull
