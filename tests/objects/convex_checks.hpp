// Brute-force checks of convex query volumes, shared by the objects, bsp and scheduler
// tests: closedness (every edge used once in each direction), convexity with outward
// faces (every vertex behind every face's plane), point containment, and the length
// scale their epsilons are taken from.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <utility>

#include <glm/glm.hpp>

namespace dyncull::test {

/// Largest |coordinate| and extent of a point set: float positions carry errors relative
/// to this, so test epsilons are multiples of it.
inline double lengthScale(std::span<const glm::vec3> pts) {
    double s = 0.0;
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const glm::vec3& p : pts) {
        s = std::max({s, std::abs(double(p.x)), std::abs(double(p.y)), std::abs(double(p.z))});
        lo = glm::min(lo, glm::dvec3(p));
        hi = glm::max(hi, glm::dvec3(p));
    }
    if (!pts.empty()) s = std::max(s, glm::length(hi - lo));
    return std::max(s, 1e-30);
}

/// How far (units of length) a vertex may lie in front of triangle abc's plane when the
/// plane is computed from float vertices: `eps`, plus the normal's rounding error (float
/// ulps of the coordinates, `scale`, divided by the triangle's smallest altitude) times
/// the distance `reach` to the farthest vertex tested. Thin slivers get a loose bound.
inline double planeTolerance(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, double eps, double scale,
                             double reach) {
    const double twiceArea = glm::length(glm::cross(b - a, c - a));
    const double longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    const double altitude = longest > 0.0 ? twiceArea / longest : 0.0;
    if (!(altitude > 0.0)) return 1e300;
    return eps + 8.0 * 1.1920929e-7 * scale * reach / altitude;
}

/// Empty if the triangles form a closed, consistently oriented, convex surface whose
/// faces point outward; otherwise what is wrong. `eps`: how far (units of length) a
/// vertex may lie in front of a face plane beyond float noise (planeTolerance); `scale`:
/// the coordinates' magnitude (lengthScale). A mesh smaller than 1000 float ulps of its
/// coordinates has no meaningful orientation in float and is checked for closedness only.
inline std::string checkClosedConvexOutward(std::span<const glm::vec3> v, std::span<const std::uint8_t> idx, double eps,
                                            double scale) {
    if (idx.size() % 3 != 0) return "index count not a multiple of 3";
    if (idx.size() < 12) return "fewer than 4 triangles";
    std::map<std::pair<int, int>, int> directed;
    for (std::size_t t = 0; t < idx.size(); t += 3)
        for (int k = 0; k < 3; ++k) {
            const int a = idx[t + k], b = idx[t + (k + 1) % 3];
            if (a >= static_cast<int>(v.size()) || b >= static_cast<int>(v.size())) return "index out of range";
            if (a == b) return "triangle repeats a vertex";
            ++directed[{a, b}];
        }
    for (const auto& [e, n] : directed) {
        if (n != 1) return "edge " + std::to_string(e.first) + "-" + std::to_string(e.second) + " used " + std::to_string(n) + " times in one direction";
        if (!directed.count({e.second, e.first})) return "edge " + std::to_string(e.first) + "-" + std::to_string(e.second) + " has no twin (open)";
    }
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const glm::vec3& p : v) {
        lo = glm::min(lo, glm::dvec3(p));
        hi = glm::max(hi, glm::dvec3(p));
    }
    const double diameter = glm::length(hi - lo);
    if (diameter < 1000.0 * 1.1920929e-7 * scale) return {};
    double six = 0.0, area = 0.0;
    for (std::size_t t = 0; t < idx.size(); t += 3) {
        const glm::dvec3 a(v[idx[t]]), b(v[idx[t + 1]]), c(v[idx[t + 2]]);
        const glm::dvec3 o(v[0]);
        six += glm::dot(a - o, glm::cross(b - o, c - o));
        area += 0.5 * glm::length(glm::cross(b - a, c - a));
        const glm::dvec3 n = glm::cross(b - a, c - a);
        const double len = glm::length(n);
        const double tol = planeTolerance(a, b, c, eps, scale, diameter);
        if (!(len > 0.0) || tol > diameter) continue;  // sliver: its float normal says nothing
        for (const glm::vec3& p : v) {
            const double d = glm::dot(n / len, glm::dvec3(p) - a);
            if (d > tol)
                return "vertex in front of triangle " + std::to_string(t / 3) + " by " + std::to_string(d) +
                       " > " + std::to_string(tol) + " (not convex or faces inward)";
        }
    }
    // Moving every vertex by float noise changes the volume by about noise x area: a mesh
    // flat at float precision (a planar set far from the origin) may read slightly negative.
    if (six / 6.0 < -8.0 * 1.1920929e-7 * scale * area) return "negative enclosed volume (faces inward)";
    return {};
}

/// True if `p` is behind (or within planeTolerance of) every face plane of a convex mesh.
inline bool insideConvexMesh(std::span<const glm::vec3> v, std::span<const std::uint8_t> idx, const glm::dvec3& p,
                             double eps, double scale) {
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
        const glm::dvec3 a(v[idx[t]]), b(v[idx[t + 1]]), c(v[idx[t + 2]]);
        const glm::dvec3 n = glm::cross(b - a, c - a);
        const double len = glm::length(n);
        if (!(len > 0.0)) continue;
        const double reach = std::max({glm::length(p - a), glm::length(p - b), glm::length(p - c)});
        if (glm::dot(n / len, p - a) > planeTolerance(a, b, c, eps, scale, reach)) return false;
    }
    return true;
}

}  // namespace dyncull::test
