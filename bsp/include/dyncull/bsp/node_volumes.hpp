// Query volumes of every local-BSP node, in object space: the AABB, the PCA box and the
// 14-, 18- and 26-DOP boundary meshes, stored once per model in flat arrays. Under a
// rigid or affine object transform only their vertices are transformed; they are never
// recomputed from the geometry.
// Papers: kdop-bounding-volumes-for-occlusion.txt, sections 3.3 (transform the boundary
// vertices, keep the triangles) and 5.2 (volume and surface area of the leaf volumes);
// out-of-core-obb-depth-queries.txt, section 3 (a PCA box per node).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/objects/mesh.hpp"
#include "dyncull/objects/volume_kind.hpp"

namespace dyncull {

struct LocalBspNode;

/// One stored volume. Its vertices are NodeVolumes::vertices[firstVertex, +vertexCount)
/// (object space). triangleCount == 0 marks a box: 8 corners in the bit order of
/// kBoxTriangles (convex_mesh.hpp); otherwise its triangles are
/// NodeVolumes::indices[firstIndex, +3 * triangleCount), numbered from firstVertex,
/// counter-clockwise seen from outside. vertexCount == 0: the node bounds nothing.
struct NodeVolume {
    std::uint32_t firstVertex = 0;
    std::uint32_t firstIndex = 0;
    std::uint8_t vertexCount = 0;
    std::uint8_t triangleCount = 0;
    float surfaceArea = 0.0f;  ///< object space, units²
    float volume = 0.0f;       ///< object space, units³
    bool isBox() const { return triangleCount == 0; }
};

/// Every node's volume of every kind. Owned by its LocalBsp (indexed like its nodes).
struct NodeVolumes {
    std::vector<NodeVolume> entries;   ///< [node * kVolumeKindCount + kind]
    std::vector<glm::vec3> vertices;   ///< object space
    std::vector<std::uint8_t> indices; ///< triangles of the k-DOP meshes
    double buildMs = 0.0;

    bool empty() const { return entries.empty(); }
    std::uint32_t nodeCount() const { return static_cast<std::uint32_t>(entries.size() / kVolumeKindCount); }
    const NodeVolume& get(std::uint32_t node, VolumeKind kind) const {
        return entries[node * kVolumeKindCount + static_cast<std::uint32_t>(kind)];
    }
    std::span<const glm::vec3> verticesOf(const NodeVolume& v) const { return {vertices.data() + v.firstVertex, v.vertexCount}; }
    std::span<const std::uint8_t> indicesOf(const NodeVolume& v) const {
        return {indices.data() + v.firstIndex, 3u * v.triangleCount};
    }
};

/// Computes each node's volumes from the vertices its subtree's triangles reference
/// (each counted once): the node box's corners, fitObbPca, and kdopBoundary of the
/// 14/18/26-DOP intervals. O(indices x depth). A node whose index range or indices do not
/// fit `mesh` (a hand-built tree without triangles) gets its box for every kind.
NodeVolumes buildNodeVolumes(const Mesh& mesh, const std::vector<LocalBspNode>& nodes);

/// The kind `choice` means for `node`. A fixed choice is itself. Auto takes the box (AABB
/// or PCA box, whichever has less surface area; the AABB on a tie) unless the k-DOP with
/// the least surface area saves at least `autoSaving` (a fraction) of the box's area —
/// more triangles only pay when they shrink the rasterised area enough (the threshold is
/// measured by `dyncull bench --volumes`, see docs/BENCHMARKS.md).
VolumeKind chooseVolume(const NodeVolumes& volumes, std::uint32_t node, VolumeChoice choice, float autoSaving);

}  // namespace dyncull
