// PCA-fitted oriented bounding boxes. Paper: out-of-core-obb-depth-queries.txt, section 3
// (equations 1-3: covariance S = D^T D / (n - 1) of the centred points, eigenvectors as
// the box frame at the centroid).
#include "dyncull/objects/obb.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>

#include "dyncull/objects/symmetric_eigen.hpp"

namespace dyncull {

Obb Obb::fromAabb(const Aabb& box) {
    Obb o;
    if (box.empty()) return o;
    o.center = box.center();
    o.halfExtents = 0.5f * box.extent();
    return o;
}

std::array<glm::vec3, 8> Obb::corners() const {
    std::array<glm::vec3, 8> c;
    for (int i = 0; i < 8; ++i) {
        glm::vec3 p = center;
        for (int k = 0; k < 3; ++k) p += ((i >> k) & 1 ? 1.0f : -1.0f) * halfExtents[k] * axes[k];
        c[i] = p;
    }
    return c;
}

float Obb::surfaceArea() const {
    const glm::vec3 e = 2.0f * halfExtents;
    return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
}

float Obb::volume() const { return 8.0f * halfExtents.x * halfExtents.y * halfExtents.z; }

bool Obb::contains(const glm::vec3& p, float eps) const {
    const glm::vec3 d = p - center;
    for (int k = 0; k < 3; ++k)
        if (std::abs(glm::dot(d, axes[k])) > halfExtents[k] + eps) return false;
    return true;
}

Obb fitObbPca(std::span<const glm::vec3> points) {
    if (points.empty()) return {};
    Aabb aabb;
    glm::dvec3 mean(0.0);
    for (const glm::vec3& p : points) {
        aabb.extend(p);
        mean += glm::dvec3(p);
    }
    mean /= static_cast<double>(points.size());
    // Covariance about the centroid (two passes: exact centring keeps far-from-origin sets accurate).
    // The 1/(n-1) factor of equation 1 scales eigenvalues only, not eigenvectors, so it is left out.
    glm::dmat3 cov(0.0);
    for (const glm::vec3& p : points) {
        const glm::dvec3 d = glm::dvec3(p) - mean;
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r <= c; ++r) cov[c][r] += d[r] * d[c];
    }
    const SymmetricEigen3 eig = symmetricEigen3(cov);

    glm::dvec3 lo(DBL_MAX), hi(-DBL_MAX);
    for (const glm::vec3& p : points) {
        const glm::dvec3 d = glm::dvec3(p) - mean;
        for (int k = 0; k < 3; ++k) {
            const double t = glm::dot(d, eig.vectors[k]);
            lo[k] = std::min(lo[k], t);
            hi[k] = std::max(hi[k], t);
        }
    }
    Obb o;
    o.isAabb = false;
    glm::dvec3 center = mean;
    for (int k = 0; k < 3; ++k) {
        center += 0.5 * (lo[k] + hi[k]) * eig.vectors[k];
        o.axes[k] = glm::vec3(eig.vectors[k]);
    }
    o.center = glm::vec3(center);
    // Float corners are center + sums of three float products: a few ulps of the largest
    // coordinate magnitude off. 8 ulps of padding keeps every point inside them.
    const float coord = std::max({std::abs(aabb.min.x), std::abs(aabb.min.y), std::abs(aabb.min.z),
                                  std::abs(aabb.max.x), std::abs(aabb.max.y), std::abs(aabb.max.z)});
    const float pad = 8.0f * FLT_EPSILON * coord;
    for (int k = 0; k < 3; ++k) o.halfExtents[k] = static_cast<float>(0.5 * (hi[k] - lo[k])) + pad;

    const Obb box = Obb::fromAabb(aabb);
    // Not tighter (within float noise): the AABB is exact, needs no padding and keeps the
    // fast axis-aligned paths.
    if (!(o.surfaceArea() < box.surfaceArea() * (1.0f - 1e-5f))) return box;
    return o;
}

}  // namespace dyncull
