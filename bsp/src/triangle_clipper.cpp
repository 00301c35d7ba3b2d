// Triangle clipping against an axis-aligned plane (Sutherland-Hodgman, one plane), used by
// the local BSP of "Two-level BSP for dynamic occlusion culling", section 3.1.
#include "triangle_clipper.hpp"

#include <algorithm>
#include <cassert>

namespace dyncull::detail {

void EdgeSplitter::reset(int axis, float plane) {
    cache_.clear();
    axis_ = axis;
    plane_ = plane;
}

std::uint32_t EdgeSplitter::split(std::uint32_t a, std::uint32_t b) {
    // Always interpolate from the lower to the higher index so both triangles sharing the
    // edge compute (and share) the bit-identical point.
    if (a > b) std::swap(a, b);
    const std::uint64_t key = (std::uint64_t{a} << 32) | b;
    const auto [it, inserted] = cache_.try_emplace(key, static_cast<std::uint32_t>(positions_.size()));
    if (!inserted) return it->second;

    const glm::vec3 pa = positions_[a], pb = positions_[b];
    const double t = (double(plane_) - pa[axis_]) / (double(pb[axis_]) - pa[axis_]);
    glm::vec3 p;
    for (int k = 0; k < 3; ++k) {
        const double v = double(pa[k]) + t * (double(pb[k]) - pa[k]);
        // Clamp so rounding never puts the point outside the edge's own box.
        p[k] = std::clamp(float(v), std::min(pa[k], pb[k]), std::max(pa[k], pb[k]));
    }
    p[axis_] = plane_;  // exactly on the plane: child boxes then meet without overlap here
    const glm::vec3 na = normals_[a], nb = normals_[b];
    glm::vec3 n = na + float(t) * (nb - na);
    const float len = glm::length(n);
    n = (len > 0.0f && std::isfinite(len)) ? n / len : na;  // opposite normals: keep one
    positions_.push_back(p);
    normals_.push_back(n);
    splits_.push_back({a, b, float(t)});
    return it->second;
}

namespace {

// Appends polygon `poly` (3 or 4 vertices, convex, in order) as a triangle fan.
void fan(const std::array<std::uint32_t, 4>& poly, int count, std::vector<Triangle>& out) {
    assert(count == 3 || count == 4);
    out.push_back({poly[0], poly[1], poly[2]});
    if (count == 4) out.push_back({poly[0], poly[2], poly[3]});
}

}  // namespace

void clipTriangle(const Triangle& tri, const std::array<int, 3>& sides, EdgeSplitter& splitter,
                  std::vector<Triangle>& below, std::vector<Triangle>& above) {
    std::array<std::uint32_t, 4> lo{}, hi{};
    int nLo = 0, nHi = 0;
    for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3;
        // On-plane vertices (side 0) belong to both pieces; only an edge between strictly
        // opposite sides creates a new vertex, so no piece has a near-duplicate vertex.
        if (sides[i] <= 0) lo[nLo++] = tri[i];
        if (sides[i] >= 0) hi[nHi++] = tri[i];
        if (sides[i] * sides[j] < 0) {
            const std::uint32_t v = splitter.split(tri[i], tri[j]);
            lo[nLo++] = v;
            hi[nHi++] = v;
        }
    }
    fan(lo, nLo, below);
    fan(hi, nHi, above);
}

}  // namespace dyncull::detail
