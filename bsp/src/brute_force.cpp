// Brute-force frustum reference for the two-level traversal: a linear scan over objects
// and their local leaves, no hierarchy. Used as the tests' oracle.
// Paper: Two-level BSP for dynamic occlusion culling, section 3.4 (frustum culling first).
// Also the O(n^2) p-HBVO split search (Scene subdivision for occlusion culling, 3.2).
#include <algorithm>
#include <limits>

#include "dyncull/bsp/subdivision.hpp"
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

PhbvoSplit phbvoBestSplitBruteForce(const Mesh& mesh, std::span<const std::uint32_t> tris) {
    auto centroid = [&](std::uint32_t t) {
        return (mesh.positions[mesh.indices[3 * t]] + mesh.positions[mesh.indices[3 * t + 1]] +
                mesh.positions[mesh.indices[3 * t + 2]]) *
               (1.0f / 3.0f);
    };
    auto boxOf = [&](std::uint32_t t) {
        Aabb b;
        for (int c = 0; c < 3; ++c) b.extend(mesh.positions[mesh.indices[3 * t + c]]);
        return b;
    };
    PhbvoSplit best{-1, 0, std::numeric_limits<float>::infinity()};
    const std::size_t n = tris.size();
    for (int axis = 0; axis < 3; ++axis) {
        std::vector<std::uint32_t> s(tris.begin(), tris.end());
        std::sort(s.begin(), s.end(), [&](std::uint32_t a, std::uint32_t b) {
            const float ca = centroid(a)[axis], cb = centroid(b)[axis];
            return ca != cb ? ca < cb : a < b;
        });
        for (std::size_t i = 1; i < n; ++i) {  // left = s[0, i)
            if (!(centroid(s[i - 1])[axis] < centroid(s[i])[axis])) continue;
            Aabb left, right;
            for (std::size_t k = 0; k < i; ++k) left.extend(boxOf(s[k]));
            for (std::size_t k = i; k < n; ++k) right.extend(boxOf(s[k]));
            const float cost = left.surfaceArea() * float(i) + right.surfaceArea() * float(n - i);
            if (cost < best.cost) best = {axis, static_cast<std::uint32_t>(i), cost};
        }
    }
    if (best.axis < 0) best.cost = 0.0f;
    return best;
}

}  // namespace dyncull
