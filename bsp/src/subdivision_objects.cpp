// From a subdivision to objects: the mesh's triangles in leaf order, and one compact
// model per leaf for the global loose BSP (each leaf one static object, one draw).
// Paper: Scene subdivision for occlusion culling, section 2.1 (a leaf node is a
// subdivision node with exactly one geometry node: here, one object with one part).
#include <optional>

#include "dyncull/bsp/local_bsp.hpp"
#include "dyncull/bsp/subdivision.hpp"

namespace dyncull {

void applyTriangleOrder(Mesh& mesh, Subdivision& sub) {
    if (sub.triangles.empty()) return;
    std::vector<std::uint32_t> ordered(mesh.indices.size());
    for (std::size_t i = 0; i < sub.triangles.size(); ++i) {
        const std::uint32_t t = sub.triangles[i];
        ordered[3 * i] = mesh.indices[3 * t];
        ordered[3 * i + 1] = mesh.indices[3 * t + 1];
        ordered[3 * i + 2] = mesh.indices[3 * t + 2];
    }
    mesh.indices.swap(ordered);
    std::vector<std::uint32_t>().swap(sub.triangles);
}

std::vector<LocalBsp> subdivisionLeafModels(const Mesh& mesh, const Subdivision& sub, FaceMode faces) {
    std::optional<Mesh> withNormals;
    if (mesh.normals.size() != mesh.positions.size()) {
        withNormals = mesh;
        computeNormals(*withNormals);
    }
    const Mesh& m = withNormals ? *withNormals : mesh;
    std::vector<LocalBsp> out;
    // Old vertex -> new vertex of the current leaf; reset through `used` after each leaf.
    std::vector<std::uint32_t> remap(m.positions.size(), kInvalidIndex);
    std::vector<std::uint32_t> used;
    for (std::size_t i = 0; i < sub.nodes.size(); ++i) {
        const SubdivisionNode& node = sub.nodes[i];
        if (!node.isLeaf() || node.triangleCount == 0) continue;
        LocalBsp b;
        b.mesh.name = mesh.name + "/leaf" + std::to_string(out.size());
        b.mesh.indices.reserve(3 * std::size_t(node.triangleCount));
        used.clear();
        for (std::uint32_t k = 0; k < node.triangleCount; ++k) {
            const std::uint32_t t = sub.triangleAt(node.firstTriangle + k);
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t v = m.indices[3 * std::size_t(t) + c];
                if (remap[v] == kInvalidIndex) {
                    remap[v] = static_cast<std::uint32_t>(used.size());
                    used.push_back(v);
                }
                b.mesh.indices.push_back(remap[v]);
            }
        }
        b.mesh.positions.reserve(used.size());
        b.mesh.normals.reserve(used.size());
        for (std::uint32_t v : used) {
            b.mesh.positions.push_back(m.positions[v]);
            b.mesh.normals.push_back(m.normals[v]);
            remap[v] = kInvalidIndex;
        }
        LocalBspNode root;
        root.box = node.box;
        root.indexCount = static_cast<std::uint32_t>(b.mesh.indices.size());
        b.nodes.push_back(root);
        b.stats.trianglesBefore = b.stats.trianglesAfter = node.triangleCount;
        b.stats.leaves = 1;
        b.faces = faces;
        optimizeLeafOrder(b);
        out.push_back(std::move(b));
    }
    return out;
}

}  // namespace dyncull
