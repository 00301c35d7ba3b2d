// Split-plane selection for the local BSP.
// Spatial median: Two-level BSP for dynamic occlusion culling (Bittner-style object
// partitioning), section 3.1. Surface-area cost: Scene subdivision for occlusion culling,
// section 3.2 (p-HBVO): C = S(left)/S(H) * |left| + S(right)/S(H) * |right|, evaluated
// at triangle barycentres; here binned rather than fully sorted.
#include "split_plane.hpp"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <limits>

namespace dyncull::detail {

float planeEpsilon(const Aabb& box) {
    const glm::vec3 e = box.extent();
    const float extent = std::max({e.x, e.y, e.z, 0.0f});
    const glm::vec3 m = glm::max(glm::abs(box.min), glm::abs(box.max));
    const float magnitude = std::max({m.x, m.y, m.z});
    // A vertex this close to a plane is "on" it: 1e-5 of the node size absorbs the rounding
    // of earlier intersection points without visible overhang, and 8 ulps of the largest
    // coordinate keeps the band meaningful when the mesh sits far from the origin.
    return std::max(1e-5f * extent, 8.0f * FLT_EPSILON * magnitude);
}

void SplitPlanner::loadAxis(std::span<const Triangle> tris, const std::vector<glm::vec3>& positions,
                            int axis) {
    sortedCoords_.resize(tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i) {
        float a = positions[tris[i][0]][axis], b = positions[tris[i][1]][axis],
              c = positions[tris[i][2]][axis];
        if (a > b) std::swap(a, b);
        if (b > c) std::swap(b, c);
        if (a > b) std::swap(a, b);
        sortedCoords_[i] = {a, b, c};
    }
}

SplitCount SplitPlanner::count(float plane, float eps) const {
    SplitCount r;
    for (const glm::vec3& s : sortedCoords_) {
        if (planeSide(s.z, plane, eps) <= 0) {
            ++r.below;  // also takes triangles lying in the plane: a deterministic choice
        } else if (planeSide(s.x, plane, eps) >= 0) {
            ++r.above;
        } else {
            ++r.cut;
            // The side holding two vertices (or one plus the on-plane middle) gets a quad.
            const int mid = planeSide(s.y, plane, eps);
            r.belowTriangles += mid < 0 ? 2 : 1;
            r.aboveTriangles += mid > 0 ? 2 : 1;
        }
    }
    r.belowTriangles += r.below;
    r.aboveTriangles += r.above;
    return r;
}

float SplitPlanner::nudge(float plane, float window, float lo, float hi, float eps,
                          SplitCount& counts) const {
    counts = count(plane, eps);
    if (!(window > 0.0f)) return plane;
    float best = plane;
    // Candidates alternate around the original, nearest first, so ties keep the closest.
    constexpr int kSteps = 3;
    for (int k = 1; k <= kSteps; ++k) {
        for (const float sign : {-1.0f, 1.0f}) {
            const float c = plane + sign * window * float(k) / float(kSteps);
            if (!(c > lo + eps && c < hi - eps)) continue;
            const SplitCount n = count(c, eps);
            if (n.added() < counts.added()) {
                counts = n;
                best = c;
            }
        }
    }
    return best;
}

bool SplitPlanner::sah(std::span<const Triangle> tris, const std::vector<glm::vec3>& positions,
                       SplitPlane& out) {
    triBoxes_.resize(tris.size());
    centroids_.resize(tris.size());
    Aabb cbounds;
    for (std::size_t i = 0; i < tris.size(); ++i) {
        const glm::vec3 a = positions[tris[i][0]], b = positions[tris[i][1]], c = positions[tris[i][2]];
        triBoxes_[i] = Aabb::fromMinMax(glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c)));
        centroids_[i] = (a + b + c) * (1.0f / 3.0f);
        cbounds.extend(centroids_[i]);
    }
    if (cbounds.empty()) return false;

    float bestCost = std::numeric_limits<float>::infinity();
    bool found = false;
    for (int axis = 0; axis < 3; ++axis) {
        const float lo = cbounds.min[axis];
        const float ext = cbounds.max[axis] - lo;
        if (!(ext > 0.0f)) continue;
        std::array<Aabb, kSahBins> boxes{};
        std::array<std::uint32_t, kSahBins> counts{};
        const float scale = float(kSahBins) / ext;
        for (std::size_t i = 0; i < tris.size(); ++i) {
            const int bin = std::clamp(int((centroids_[i][axis] - lo) * scale), 0, kSahBins - 1);
            ++counts[bin];
            boxes[bin].extend(triBoxes_[i]);
        }
        // Right-to-left sweep stores S(right) * |right| per boundary; the left-to-right
        // sweep adds S(left) * |left|. The common 1/S(H) factor does not change the argmin.
        std::array<float, kSahBins> rightCost{};
        Aabb acc;
        std::uint32_t n = 0;
        for (int b = kSahBins - 1; b > 0; --b) {
            acc.extend(boxes[b]);
            n += counts[b];
            rightCost[b] = n ? acc.surfaceArea() * float(n) : -1.0f;
        }
        acc = Aabb{};
        n = 0;
        for (int b = 0; b + 1 < kSahBins; ++b) {
            acc.extend(boxes[b]);
            n += counts[b];
            if (n == 0 || rightCost[b + 1] < 0.0f) continue;  // one side empty: no split
            const float cost = acc.surfaceArea() * float(n) + rightCost[b + 1];
            if (cost < bestCost) {
                bestCost = cost;
                out = {axis, lo + ext * float(b + 1) / float(kSahBins)};
                found = true;
            }
        }
    }
    return found;
}

}  // namespace dyncull::detail
