// Closed convex triangle meshes as used for query volumes: a small vertex array and
// 8-bit triangle indices into it (a 26-DOP has at most 48 vertices and 92 triangles).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace dyncull {

/// The 12 triangles of a box whose corner i has x from bit 0, y from bit 1 and z from
/// bit 2 of i; counter-clockwise seen from outside when the three edge vectors
/// (corner 1 - corner 0, 2 - 0, 4 - 0) form a right-handed frame.
inline constexpr std::array<std::uint8_t, 36> kBoxTriangles = {
    0, 2, 1, 1, 2, 3,  // z = min
    4, 5, 6, 5, 7, 6,  // z = max
    0, 1, 4, 1, 5, 4,  // y = min
    2, 6, 3, 3, 6, 7,  // y = max
    0, 4, 2, 2, 4, 6,  // x = min
    1, 3, 5, 3, 7, 5,  // x = max
};

/// A convex polyhedron's boundary. Owns its arrays; coordinates in the space of whatever
/// it bounds (object space for node volumes). Triangles are counter-clockwise seen from
/// outside. An empty mesh (no vertices) bounds nothing.
struct ConvexMesh {
    std::vector<glm::vec3> vertices;
    std::vector<std::uint8_t> indices;  ///< 3 per triangle, into `vertices`
    std::size_t triangleCount() const { return indices.size() / 3; }
};

/// Total area of the triangles (units²). Computed in double.
double meshSurfaceArea(std::span<const glm::vec3> vertices, std::span<const std::uint8_t> indices);
/// Signed enclosed volume (units³) by the divergence theorem: positive for a closed mesh
/// whose triangles face outward, negative when they all face inward.
double meshVolume(std::span<const glm::vec3> vertices, std::span<const std::uint8_t> indices);

}  // namespace dyncull
