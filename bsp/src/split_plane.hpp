// Internal: choice of the axis-aligned split plane of one local-BSP node.
// Spatial median (Two-level BSP for dynamic occlusion culling, section 3.1) or the
// p-HBVO surface-area cost (Scene subdivision for occlusion culling, section 3.2),
// optionally nudged to a nearby position that cuts fewer triangles.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"
#include "triangle_clipper.hpp"

namespace dyncull::detail {

struct SplitPlane {
    int axis = 0;
    float position = 0.0f;  ///< object space, along `axis`
};

/// What a plane does to a node's triangles (sides by planeSide with the node's eps).
struct SplitCount {
    std::uint32_t below = 0;  ///< triangles entirely on or below the plane (incl. coplanar)
    std::uint32_t above = 0;  ///< triangles entirely on or above it, with one vertex above
    std::uint32_t cut = 0;    ///< triangles with vertices strictly on both sides
    std::uint32_t belowTriangles = 0;  ///< triangles the below child gets after clipping
    std::uint32_t aboveTriangles = 0;  ///< triangles the above child gets after clipping
    std::uint32_t added() const { return belowTriangles + aboveTriangles - below - above - cut; }
};

/// Half-width of the band around a plane in which a vertex counts as on the plane, for a
/// node whose content box is `box`.
float planeEpsilon(const Aabb& box);

/// Scratch buffers reused from node to node so the build does no per-node allocation.
class SplitPlanner {
public:
    /// Loads the node's triangles' coordinates along `axis` (sorted per triangle).
    void loadAxis(std::span<const Triangle> tris, const std::vector<glm::vec3>& positions, int axis);
    /// Counts for the loaded axis at `plane`.
    SplitCount count(float plane, float eps) const;
    /// Best plane within +-window of `plane` on the loaded axis (a handful of candidates,
    /// kept strictly inside [lo + eps, hi - eps]): the one adding the fewest triangles,
    /// the original on ties. Writes its counts to `counts`.
    float nudge(float plane, float window, float lo, float hi, float eps, SplitCount& counts) const;

    /// p-HBVO cost over triangle barycentres, binned (kSahBins per axis), all three axes.
    /// Returns false when every barycentre coincides (no plane separates anything).
    bool sah(std::span<const Triangle> tris, const std::vector<glm::vec3>& positions, SplitPlane& out);

    static constexpr int kSahBins = 32;

private:
    std::vector<glm::vec3> sortedCoords_;  // per triangle: lowest, middle, highest coordinate
    std::vector<Aabb> triBoxes_;
    std::vector<glm::vec3> centroids_;
};

}  // namespace dyncull::detail
