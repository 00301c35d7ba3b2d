// Internal: clipping of indexed triangles against an axis-aligned plane for the local BSP
// (Two-level BSP for dynamic occlusion culling, section 3.1: "triangles intersecting the
// plane are split up"). Sutherland-Hodgman against a single plane, with a band of
// half-width eps around the plane whose vertices count as lying on it, so no piece is
// ever a sliver between a vertex and an intersection point a rounding error away.
#pragma once

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/bsp/local_bsp.hpp"

namespace dyncull::detail {

using Triangle = std::array<std::uint32_t, 3>;  ///< vertex indices, counter-clockwise

/// Side of a coordinate relative to the plane: -1 below, 0 within eps of it, +1 above.
inline int planeSide(float coord, float plane, float eps) {
    const float d = coord - plane;
    return d < -eps ? -1 : (d > eps ? 1 : 0);
}

/// Creates the vertices where triangle edges cross the current plane, appending to the
/// caller's position/normal arrays (which it does not own). One vertex per crossed edge:
/// the two triangles sharing an edge get the same new vertex, so the mesh stays indexed.
class EdgeSplitter {
public:
    EdgeSplitter(std::vector<glm::vec3>& positions, std::vector<glm::vec3>& normals, std::vector<SplitVertex>& splits)
        : positions_(positions), normals_(normals), splits_(splits) {}

    /// Starts a new plane (axis 0..2, position in object space); forgets shared vertices.
    void reset(int axis, float plane);
    /// Vertex on the plane along edge (a, b); a and b must be strictly on opposite sides.
    std::uint32_t split(std::uint32_t a, std::uint32_t b);

private:
    std::vector<glm::vec3>& positions_;
    std::vector<glm::vec3>& normals_;
    std::vector<SplitVertex>& splits_;  // one per vertex appended: where on which edge
    std::unordered_map<std::uint64_t, std::uint32_t> cache_;  // reused: clear() keeps buckets
    int axis_ = 0;
    float plane_ = 0.0f;
};

/// Clips `tri` whose vertex sides (planeSide) are `sides` — at least one -1 and one +1 —
/// and appends the fan-triangulated pieces below the plane to `below` and those above to
/// `above`, preserving the winding. Each side gets 1 or 2 triangles.
void clipTriangle(const Triangle& tri, const std::array<int, 3>& sides, EdgeSplitter& splitter,
                  std::vector<Triangle>& below, std::vector<Triangle>& above);

}  // namespace dyncull::detail
