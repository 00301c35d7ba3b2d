// Brute-force frustum reference for the two-level traversal: a linear scan over objects
// and their local leaves, no hierarchy. Used as the tests' oracle.
// Paper: Two-level BSP for dynamic occlusion culling, section 3.4 (frustum culling first).
#include "dyncull/bsp/traversal.hpp"

namespace dyncull {

std::vector<NodeRef> frustumLeavesBruteForce(const SceneObjects& objects, const Frustum& frustum) {
    std::vector<NodeRef> out;
    for (std::uint32_t i = 0; i < objects.slotCount(); ++i) {
        if (!objects.alive(i)) continue;
        const LocalBsp& model = objects.model(objects.modelOf(i));
        for (std::uint32_t n = 0; n < model.nodes.size(); ++n) {
            const LocalBspNode& node = model.nodes[n];
            // Empty leaves are never drawn (the traversal skips them); the root is kept even
            // when empty-indexed so a single-leaf model is always listed like traversal does.
            if (!node.isLeaf() || (n != 0 && node.indexCount == 0)) continue;
            const Aabb world = n == 0 ? objects.worldBox(i) : transformAabb(objects.matrix(i), node.box);
            if (!frustum.outside(world)) out.push_back({i, n});
        }
    }
    return out;
}

}  // namespace dyncull
