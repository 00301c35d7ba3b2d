// Ear clipping on the polygon's dominant plane. The plane is chosen from Newell's normal,
// which is robust for slightly non-planar faces; only reflex (and flat) corners can lie
// inside an ear of a simple polygon, so the inside test scans just those.
#include "dyncull/objects/polygon_triangulation.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstddef>

namespace dyncull {
namespace {

// Twice the signed area of triangle abc (> 0 when counter-clockwise).
double cross(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// The inside test runs at most this many point checks (plus a share per corner) before
// the polygon is declared too complex: hostile faces must not take minutes.
constexpr std::size_t kWorkBudget = std::size_t{1} << 25;

}  // namespace

Triangulation triangulatePolygon(std::span<const glm::vec3> corners, std::vector<std::uint32_t>& out,
                                 TriangulationScratch& s) {
    const std::size_t n = corners.size();
    if (n < 3) return Triangulation::ZeroArea;
    if (n > 0xFFFFFFFFu) return Triangulation::TooComplex;  // corners are named by 32-bit indices
    if (n == 3) {
        out.insert(out.end(), {0u, 1u, 2u});
        return Triangulation::Ok;
    }

    glm::dvec3 normal(0.0), lo(corners[0]), hi(corners[0]);
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 a(corners[i]), b(corners[(i + 1) % n]);
        normal.x += (a.y - b.y) * (a.z + b.z);
        normal.y += (a.z - b.z) * (a.x + b.x);
        normal.z += (a.x - b.x) * (a.y + b.y);
        lo = glm::min(lo, a);
        hi = glm::max(hi, a);
    }
    const glm::dvec3 size = hi - lo;
    const double extent = std::max({size.x, size.y, size.z});
    // Corners are floats: a cross product of two edges is only known to about
    // FLT_EPSILON * extent^2, so smaller areas (and squared distances) count as zero.
    const double eps = 8.0 * FLT_EPSILON * extent * extent;
    const glm::dvec3 absN = glm::abs(normal);
    if (!(std::max({absN.x, absN.y, absN.z}) > eps)) return Triangulation::ZeroArea;  // also NaN

    // Drop the normal's largest axis; the other two in cyclic order give a counter-clockwise
    // polygon when that component is positive, so mirror when it is negative.
    const int axis = absN.x >= absN.y && absN.x >= absN.z ? 0 : (absN.y >= absN.z ? 1 : 2);
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const double flip = normal[axis] < 0.0 ? -1.0 : 1.0;
    s.points.resize(n);
    s.prev.resize(n);
    s.next.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 c = glm::dvec3(corners[i]) - lo;  // near the origin: less cancellation
        s.points[i] = glm::dvec2(c[u], flip * c[v]);
        s.prev[i] = static_cast<std::uint32_t>((i + n - 1) % n);
        s.next[i] = static_cast<std::uint32_t>((i + 1) % n);
    }
    const auto& p = s.points;
    auto& prev = s.prev;
    auto& next = s.next;
    auto convex = [&](std::uint32_t i) { return cross(p[prev[i]], p[i], p[next[i]]) > eps; };
    s.reflex.clear();
    for (std::uint32_t i = 0; i < n; ++i)
        if (!convex(i)) s.reflex.push_back(i);

    std::size_t budget = kWorkBudget + 16 * n;
    bool overBudget = false;
    auto near = [&](const glm::dvec2& a, const glm::dvec2& b) {
        const glm::dvec2 d = a - b;
        return d.x * d.x + d.y * d.y <= eps;
    };
    auto isEar = [&](std::uint32_t i) {
        if (!convex(i)) return false;
        const glm::dvec2 &a = p[prev[i]], &b = p[i], &c = p[next[i]];
        for (std::uint32_t r : s.reflex) {
            if (r == prev[i] || r == i || r == next[i]) continue;
            if (budget == 0) {
                overBudget = true;
                return false;
            }
            --budget;
            const glm::dvec2& q = p[r];
            // A duplicate of a corner is not in the way; anything inside or on an edge is.
            if (near(q, a) || near(q, b) || near(q, c)) continue;
            if (cross(a, b, q) >= -eps && cross(b, c, q) >= -eps && cross(c, a, q) >= -eps) return false;
        }
        return true;
    };
    auto dropReflexIfConvex = [&](std::uint32_t i) {
        if (!convex(i)) return;
        const auto it = std::find(s.reflex.begin(), s.reflex.end(), i);
        if (it != s.reflex.end()) s.reflex.erase(it);
    };

    const std::size_t outStart = out.size();
    std::size_t remaining = n;
    std::size_t tried = 0;  // corners tried since the last ear
    std::uint32_t i = 1;    // starting at corner 1 and moving on makes a convex polygon the fan from corner 0
    Triangulation result = Triangulation::Ok;
    while (remaining > 3) {
        if (isEar(i)) {
            const std::uint32_t a = prev[i], c = next[i];
            out.insert(out.end(), {a, i, c});
            next[a] = c;
            prev[c] = a;
            const auto it = std::find(s.reflex.begin(), s.reflex.end(), i);
            if (it != s.reflex.end()) s.reflex.erase(it);
            dropReflexIfConvex(a);
            dropReflexIfConvex(c);
            --remaining;
            tried = 0;
            i = c;
            continue;
        }
        if (overBudget) {
            out.resize(outStart);
            return Triangulation::TooComplex;
        }
        i = next[i];
        if (++tried < remaining) continue;
        // A whole lap without an ear: what is left is flat (drop it) or self-intersecting.
        double area = 0.0;
        std::uint32_t j = i;
        do {
            area += cross(p[i], p[j], p[next[j]]);
            j = next[j];
        } while (j != i);
        if (std::abs(area) <= eps) return result;
        for (j = next[i]; next[j] != i; j = next[j]) out.insert(out.end(), {i, j, next[j]});
        return Triangulation::Tangled;
    }
    const double last = cross(p[prev[i]], p[i], p[next[i]]);
    if (last > eps) out.insert(out.end(), {prev[i], i, next[i]});
    else if (last < -eps) {  // an inverted last triangle only happens when the polygon crosses itself
        out.insert(out.end(), {prev[i], i, next[i]});
        result = Triangulation::Tangled;
    }
    return result;
}

}  // namespace dyncull
