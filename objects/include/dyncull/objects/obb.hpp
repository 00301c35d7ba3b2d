// Oriented bounding boxes fitted by principal component analysis of a point set.
// Paper: out-of-core-obb-depth-queries.txt, section 3 (covariance of the points about
// their centroid, its eigenvectors as the box axes); compared with AABBs and k-DOPs in
// kdop-bounding-volumes-for-occlusion.txt, sections 2 and 5.
#pragma once

#include <array>
#include <span>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"

namespace dyncull {

/// A box with orthonormal axes. Same coordinate space as the points it was fitted to.
struct Obb {
    glm::vec3 center{0.0f};
    glm::mat3 axes{1.0f};       ///< columns: unit axes, a right-handed rotation
    glm::vec3 halfExtents{0.0f};  ///< along each axis, >= 0
    bool isAabb = true;         ///< axes are the coordinate axes (the AABB fallback)

    static Obb fromAabb(const Aabb& box);
    /// Corner i = center + sum_k (bit k of i ? +1 : -1) * halfExtents[k] * axes[k]: the
    /// bit order of kBoxTriangles (convex_mesh.hpp), whose winding is outward here.
    std::array<glm::vec3, 8> corners() const;
    float surfaceArea() const;
    float volume() const;
    /// True if `p` lies within the box grown by `eps` (same units) on every side.
    bool contains(const glm::vec3& p, float eps) const;
};

/// The PCA box of `points`: axes from the symmetric eigen-decomposition of their
/// covariance, extents from projecting every point. Robust by construction for planar,
/// collinear, single-point and repeated-point sets (zero or repeated eigenvalues give
/// some orthonormal basis, and the extents still bound every point); when the result is
/// not tighter than the AABB — its surface area, which predicts the rasterised area of a
/// query, is not smaller — the AABB itself is returned (isAabb). Extents are grown by a
/// few float ulps of the coordinates so the float corners still contain every point.
/// An empty span gives a zero box at the origin.
Obb fitObbPca(std::span<const glm::vec3> points);

}  // namespace dyncull
