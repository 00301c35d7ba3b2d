// k-DOP intervals along the fixed directions and their bounding planes.
// Paper: kdop-bounding-volumes-for-occlusion.txt, section 3.3 (the 13 directions; an AABB
// is the 6-DOP of the axes, computed by the same min/max of dot products).
#include "dyncull/objects/kdop.hpp"

#include <algorithm>
#include <cassert>
#include <cfloat>
#include <cmath>

namespace dyncull {
namespace {

glm::dvec3 direction(int i) {
    const auto& d = kKdopDirections[static_cast<std::size_t>(i)];
    return {static_cast<double>(d[0]), static_cast<double>(d[1]), static_cast<double>(d[2])};
}

}  // namespace

int kdopK(KdopType t) {
    switch (t) {
        case KdopType::K14: return 14;
        case KdopType::K18: return 18;
        case KdopType::K26: return 26;
    }
    return 0;
}

bool kdopUses(KdopType t, int i) {
    assert(i >= 0 && i < 13);
    if (i < 3) return true;
    if (i < 7) return t != KdopType::K18;
    return t != KdopType::K14;
}

bool Kdop::contains(const glm::dvec3& p, double eps) const {
    if (empty) return false;
    for (int i = 0; i < 13; ++i) {
        if (!kdopUses(type, i)) continue;
        const glm::dvec3 d = direction(i);
        const double t = glm::dot(d, p), len = glm::length(d);
        if (t < lo[i] - eps * len || t > hi[i] + eps * len) return false;
    }
    return true;
}

Aabb Kdop::aabb() const {
    if (empty) return {};
    return Aabb::fromMinMax(glm::vec3(lo[0], lo[1], lo[2]), glm::vec3(hi[0], hi[1], hi[2]));
}

double Kdop::scale() const {
    double s = 0.0;
    for (int i = 0; i < 3; ++i) s = std::max({s, std::abs(lo[i]), std::abs(hi[i])});
    return s;
}

Kdop computeKdop(KdopType type, std::span<const glm::vec3> points) {
    Kdop k;
    k.type = type;
    if (points.empty()) return k;
    k.empty = false;
    k.lo.fill(DBL_MAX);
    k.hi.fill(-DBL_MAX);
    for (const glm::vec3& pf : points) {
        const glm::dvec3 p(pf);
        // Directions have components -1, 0, 1: sums and differences, no products (3.3).
        const double v[13] = {p.x,       p.y,       p.z,       p.x + p.y + p.z, p.x - p.y + p.z,
                              p.x + p.y - p.z, -p.x + p.y + p.z, p.x + p.y, p.x + p.z, p.y + p.z,
                              p.x - p.y, p.x - p.z, p.y - p.z};
        for (int i = 0; i < 13; ++i) {
            k.lo[i] = std::min(k.lo[i], v[i]);
            k.hi[i] = std::max(k.hi[i], v[i]);
        }
    }
    return k;
}

Kdop restrictKdop(const Kdop& k26, KdopType type) {
    assert(k26.type == KdopType::K26);
    Kdop k = k26;
    k.type = type;
    return k;
}

double kdopPlaneEpsilon(const Kdop& k) {
    // 1e-6 relative is ~16 float ulps: positions rounded to float stay consistent with
    // it, and double arithmetic is 1e10 times finer. The floor keeps a k-DOP of the single
    // point (0,0,0) a (tiny) solid.
    return 1e-6 * std::max(k.scale(), 1e-30);
}

std::vector<KdopPlane> kdopPlanes(const Kdop& k) {
    std::vector<KdopPlane> planes;
    if (k.empty) return planes;
    const double minThickness = 4.0 * kdopPlaneEpsilon(k);
    for (int i = 0; i < 13; ++i) {
        if (!kdopUses(k.type, i)) continue;
        const glm::dvec3 d = direction(i);
        const double len = glm::length(d);
        double lo = k.lo[i] / len, hi = k.hi[i] / len;
        if (hi - lo < minThickness) {
            const double mid = 0.5 * (lo + hi);
            lo = mid - 0.5 * minThickness;
            hi = mid + 0.5 * minThickness;
        }
        planes.push_back({d / len, hi});
        planes.push_back({-d / len, -lo});
    }
    return planes;
}

}  // namespace dyncull
