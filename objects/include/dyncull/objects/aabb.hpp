// Axis-aligned bounding box. Coordinate space is whatever the owner says
// (object space for mesh/local-BSP boxes, world space for objects and scene nodes).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/glm.hpp>

namespace dyncull {

struct Aabb {
    // Empty box: min > max, so the first extend() sets both corners.
    glm::vec3 min{std::numeric_limits<float>::max()};
    glm::vec3 max{-std::numeric_limits<float>::max()};

    static Aabb fromMinMax(const glm::vec3& lo, const glm::vec3& hi) { return {lo, hi}; }

    bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    glm::vec3 center() const { return (min + max) * 0.5f; }
    glm::vec3 extent() const { return max - min; }
    float surfaceArea() const {
        if (empty()) return 0.0f;
        const glm::vec3 e = extent();
        return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
    }
    float volume() const {
        if (empty()) return 0.0f;
        const glm::vec3 e = extent();
        return e.x * e.y * e.z;
    }
    int longestAxis() const {
        const glm::vec3 e = extent();
        return (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
    }

    void extend(const glm::vec3& p) { min = glm::min(min, p); max = glm::max(max, p); }
    void extend(const Aabb& b) {
        if (b.empty()) return;
        min = glm::min(min, b.min);
        max = glm::max(max, b.max);
    }

    bool contains(const glm::vec3& p) const {
        return p.x >= min.x && p.y >= min.y && p.z >= min.z && p.x <= max.x && p.y <= max.y &&
               p.z <= max.z;
    }
    bool contains(const Aabb& b) const {
        return b.min.x >= min.x && b.min.y >= min.y && b.min.z >= min.z && b.max.x <= max.x &&
               b.max.y <= max.y && b.max.z <= max.z;
    }
    bool overlaps(const Aabb& b) const {
        return min.x <= b.max.x && max.x >= b.min.x && min.y <= b.max.y && max.y >= b.min.y &&
               min.z <= b.max.z && max.z >= b.min.z;
    }
    bool finite() const {
        return std::isfinite(min.x) && std::isfinite(min.y) && std::isfinite(min.z) &&
               std::isfinite(max.x) && std::isfinite(max.y) && std::isfinite(max.z);
    }
    /// Grow by `d` on every side (d >= 0).
    Aabb inflated(float d) const { return {min - glm::vec3(d), max + glm::vec3(d)}; }
};

inline Aabb merge(const Aabb& a, const Aabb& b) {
    Aabb r = a;
    r.extend(b);
    return r;
}

/// World box of `box` under the affine transform `m` (Arvo's method: exact AABB of
/// the transformed box, conservative for the contents).
inline Aabb transformAabb(const glm::mat4& m, const Aabb& box) {
    if (box.empty()) return box;
    const glm::vec3 t(m[3]);
    Aabb r{t, t};
    for (int col = 0; col < 3; ++col) {
        for (int row = 0; row < 3; ++row) {
            const float a = m[col][row] * box.min[col];
            const float b = m[col][row] * box.max[col];
            r.min[row] += std::min(a, b);
            r.max[row] += std::max(a, b);
        }
    }
    return r;
}

}  // namespace dyncull
