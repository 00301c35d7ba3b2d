// Brute-force check of a subdivision against its mesh: the tests' oracle and the
// subdivision file reader's check (a file is never trusted).
#include "dyncull/bsp/subdivision.hpp"

namespace dyncull {

std::string validateSubdivision(const Mesh& mesh, const Subdivision& sub, std::uint32_t maxLeafTriangles,
                                std::uint32_t maxDepth) {
    const std::size_t tris = mesh.triangleCount();
    const std::size_t n = sub.nodes.size();
    if (n == 0) return "no nodes";
    if (!sub.triangles.empty() && sub.triangles.size() != tris)
        return "triangle order has " + std::to_string(sub.triangles.size()) + " entries for " + std::to_string(tris) +
               " triangles";
    // Each triangle exactly once.
    if (!sub.triangles.empty()) {
        std::vector<std::uint8_t> seen(tris, 0);
        for (std::uint32_t t : sub.triangles) {
            if (t >= tris) return "triangle id " + std::to_string(t) + " out of range";
            if (seen[t]++) return "triangle " + std::to_string(t) + " assigned twice";
        }
    }
    const SubdivisionNode& root = sub.nodes[0];
    if (root.firstTriangle != 0 || root.triangleCount != tris) return "root does not hold every triangle";
    std::vector<std::uint8_t> reached(n, 0);
    reached[0] = 1;
    std::size_t leafTriangles = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const SubdivisionNode& v = sub.nodes[i];
        const std::string at = "node " + std::to_string(i) + ": ";
        if (!reached[i]) return at + "not reachable from the root (or reached twice)";
        if (v.firstTriangle > tris || v.triangleCount > tris - v.firstTriangle) return at + "triangle range out of range";
        if (v.depth > kSubdivisionMaxDepth) return at + "depth out of range";
        if (v.isLeaf()) {
            if (v.firstChild != kInvalidIndex) return at + "leaf with a child index";
            if (v.triangleCount > maxLeafTriangles && v.depth < maxDepth)
                return at + "leaf of " + std::to_string(v.triangleCount) + " triangles above the limit " +
                       std::to_string(maxLeafTriangles) + " at depth " + std::to_string(v.depth);
            leafTriangles += v.triangleCount;
            Aabb box;
            for (std::uint32_t k = 0; k < v.triangleCount; ++k) {
                const std::size_t t = sub.triangleAt(v.firstTriangle + k);
                for (int c = 0; c < 3; ++c) box.extend(mesh.positions[mesh.indices[3 * t + c]]);
            }
            if (!(box.min == v.box.min && box.max == v.box.max) && !(box.empty() && v.box.empty()))
                return at + "box is not the box of its triangles";
            continue;
        }
        if (v.childCount < 2) return at + "inner node with fewer than two children";
        if (v.firstChild <= i || v.firstChild > n || v.childCount > n - v.firstChild) return at + "children out of range";
        // 64-bit sums of 32-bit counts cannot wrap (at most 2^32 children), so a corrupt
        // child count cannot make the tiling check pass by overflow.
        std::uint64_t next = v.firstTriangle;
        Aabb box;
        for (std::uint32_t c = 0; c < v.childCount; ++c) {
            const std::size_t k = v.firstChild + c;
            if (reached[k]) return at + "child " + std::to_string(k) + " has two parents";
            reached[k] = 1;
            if (sub.nodes[k].firstTriangle != next) return at + "children do not tile its triangle range";
            next += sub.nodes[k].triangleCount;
            box.extend(sub.nodes[k].box);
        }
        if (next != std::uint64_t{v.firstTriangle} + v.triangleCount) return at + "children do not tile its triangle range";
        if (!(box.min == v.box.min && box.max == v.box.max)) return at + "box is not the union of its children";
        if (!v.box.empty() && !v.box.finite()) return at + "non-finite box";
    }
    if (leafTriangles != tris) return "leaves hold " + std::to_string(leafTriangles) + " of " + std::to_string(tris) + " triangles";
    return {};
}

}  // namespace dyncull
