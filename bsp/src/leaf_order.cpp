// Triangle order inside each local-BSP leaf: first for the post-transform vertex cache,
// then for overdraw (triangles likely to be in front drawn first), with meshoptimizer's
// algorithms (Forsyth-style cache optimisation; Sander, Nehab and Barczak, "Fast
// Triangle Reordering for Vertex Locality and Reduced Overdraw", for the overdraw pass),
// and last into meshlets (meshopt_buildMeshlets, weighted towards tight normal cones), each
// meshlet's triangles again in cache order, so that the clusters cut from the leaf
// (leaf_clusters.hpp) are compact and can be back-face culled whole. Each leaf is
// reordered in place, so every node's index range stays as it was.
#include <cassert>
#include <vector>

#include <meshoptimizer.h>

#include "dyncull/bsp/local_bsp.hpp"

namespace dyncull {

namespace {

// Overdraw may trade this much vertex-cache efficiency (ACMR ratio) for fewer hidden
// fragments: meshoptimizer's recommended 1.05.
constexpr float kOverdrawThreshold = 1.05f;
// How much meshlet building favours clusters whose normals agree (back-face culling of a
// whole cluster) over compact ones: meshoptimizer's suggested 0.25 for cone culling.
constexpr float kConeWeight = 0.25f;

// Rewrites `local` (a leaf's triangles, dense vertex numbers) in meshlet order.
void orderAsMeshlets(std::vector<std::uint32_t>& local, const std::vector<glm::vec3>& positions) {
    const std::size_t count = local.size();
    std::vector<meshopt_Meshlet> meshlets(meshopt_buildMeshletsBound(count, kClusterMaxVertices, kClusterMaxTriangles));
    std::vector<unsigned int> meshletVertices(meshlets.size() * kClusterMaxVertices);
    std::vector<unsigned char> meshletTriangles(meshlets.size() * kClusterMaxTriangles * 3);
    meshlets.resize(meshopt_buildMeshlets(meshlets.data(), meshletVertices.data(), meshletTriangles.data(), local.data(),
                                          count, &positions[0].x, positions.size(), sizeof(glm::vec3),
                                          kClusterMaxVertices, kClusterMaxTriangles, kConeWeight));
    std::size_t out = 0;
    std::vector<std::uint32_t> triangles;
    for (const meshopt_Meshlet& m : meshlets) {
        triangles.clear();
        for (std::size_t i = 0; i < std::size_t{m.triangle_count} * 3; ++i)
            triangles.push_back(meshletVertices[m.vertex_offset + meshletTriangles[m.triangle_offset + i]]);
        meshopt_optimizeVertexCache(&local[out], triangles.data(), triangles.size(), positions.size());
        out += triangles.size();
    }
    assert(out == count);
}

}  // namespace

void optimizeLeafOrder(LocalBsp& bsp, bool meshlets) {
    Mesh& mesh = bsp.mesh;
    // Per leaf the vertices are renumbered densely first, so each call costs the leaf's
    // size rather than the whole mesh's vertex count (a mesh may have thousands of leaves).
    std::vector<std::uint32_t> localOf(mesh.positions.size(), kInvalidIndex);
    std::vector<std::uint32_t> globalOf, local, ordered;
    std::vector<glm::vec3> positions;
    for (const LocalBspNode& node : bsp.nodes) {
        if (!node.isLeaf() || node.indexCount < 6) continue;  // nothing to reorder in one triangle
        const std::size_t first = node.firstIndex, count = node.indexCount;
        assert(first + count <= mesh.indices.size());
        globalOf.clear();
        local.resize(count);
        positions.clear();
        for (std::size_t i = 0; i < count; ++i) {
            const std::uint32_t v = mesh.indices[first + i];
            if (localOf[v] == kInvalidIndex) {
                localOf[v] = static_cast<std::uint32_t>(globalOf.size());
                globalOf.push_back(v);
                positions.push_back(mesh.positions[v]);
            }
            local[i] = localOf[v];
        }
        ordered.resize(count);
        meshopt_optimizeVertexCache(ordered.data(), local.data(), count, globalOf.size());
        meshopt_optimizeOverdraw(local.data(), ordered.data(), count, &positions[0].x, positions.size(),
                                 sizeof(glm::vec3), kOverdrawThreshold);
        if (meshlets) orderAsMeshlets(local, positions);
        for (std::size_t i = 0; i < count; ++i) mesh.indices[first + i] = globalOf[local[i]];
        for (const std::uint32_t v : globalOf) localOf[v] = kInvalidIndex;
    }
}

}  // namespace dyncull
