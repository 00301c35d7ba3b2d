// Surface analysis: weld, count directed edges, find shells, measure their volume, decide
// nesting by ray parity, flip inward shells that are not cavities. Flat arrays only; every
// step is O(n) expected except the per-vertex edge buckets (sorted, small in practice)
// and the nesting tests, which have a budget (kNestingBudget*).
#include "dyncull/objects/surface_orientation.hpp"

#include "vertex_weld.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <utility>
#include <vector>

namespace dyncull {
namespace {

constexpr std::uint32_t kNone = 0xffffffffu;

// Nesting tests (ray against triangle, box against box) allowed per non-degenerate triangle,
// plus a constant: keeps the worst case (many inward shells inside a huge outward one)
// linear; shells left undecided when it runs out count as ambiguous (two-sided).
constexpr std::uint64_t kNestingBudgetPerTriangle = 32;
constexpr std::uint64_t kNestingBudgetBase = 1u << 20;

std::uint32_t findRoot(std::vector<std::uint32_t>& parent, std::uint32_t x) {
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];  // path halving
        x = parent[x];
    }
    return x;
}

bool unite(std::vector<std::uint32_t>& parent, std::uint32_t a, std::uint32_t b) {
    a = findRoot(parent, a);
    b = findRoot(parent, b);
    if (a == b) return false;
    if (a < b) std::swap(a, b);
    parent[a] = b;
    return true;
}

enum class Facing : std::uint8_t { Unusable, Flat, Outward, Inward };
enum class Fate : std::uint8_t { Keep, Flip, Cavity, Ambiguous };

struct Shell {
    glm::dvec3 lo{std::numeric_limits<double>::max()}, hi{-std::numeric_limits<double>::max()};
    double volume = 0.0, area = 0.0;
    bool closed = true, consistent = true;
    Facing facing = Facing::Unusable;
    Fate fate = Fate::Keep;

    glm::dvec3 centre() const { return (lo + hi) * 0.5; }
    double boxVolume() const { const glm::dvec3 e = hi - lo; return e.x * e.y * e.z; }
    bool boxContains(const Shell& o) const {
        return lo.x <= o.lo.x && lo.y <= o.lo.y && lo.z <= o.lo.z && hi.x >= o.hi.x && hi.y >= o.hi.y &&
               hi.z >= o.hi.z;
    }
};

/// Static bounding-volume tree over shell boxes (flat arrays, median splits): finds the
/// shells whose box contains a given box in about O(log m) when few do, so nesting tests
/// stay near-linear with thousands of shells (a mirrored export: every shell inwards).
class ContainerTree {
public:
    ContainerTree(const std::vector<Shell>& shells, std::vector<std::uint32_t> ids) : shells_(shells), ids_(std::move(ids)) {
        if (!ids_.empty()) build(0, ids_.size());
    }
    /// Calls f(shell) for every shell whose box contains `box`; `work` counts nodes visited.
    template <class F>
    void forEachContaining(const Shell& box, std::uint64_t& work, F&& f) const {
        if (nodes_.empty()) return;
        std::uint32_t stack[64];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& n = nodes_[stack[--top]];
            ++work;
            if (!n.box.boxContains(box)) continue;
            if (n.count > 0) {
                for (std::uint32_t i = n.first; i < n.first + n.count; ++i)
                    if (shells_[ids_[i]].boxContains(box)) f(ids_[i]);
            } else {
                stack[top++] = n.first;
                stack[top++] = n.first + 1;
            }
        }
    }

private:
    struct Node {
        Shell box;                // only lo/hi used
        std::uint32_t first = 0;  // leaf: first id; inner: left child (right = first + 1)
        std::uint32_t count = 0;  // ids in a leaf, 0 for an inner node
    };
    // Depth <= log2(m / 4) + 1 < 64 since splits are at the median.
    void build(std::size_t first, std::size_t last) {
        struct Task { std::uint32_t node; std::size_t first, last; };
        std::vector<Task> tasks{{0, first, last}};
        nodes_.emplace_back();
        while (!tasks.empty()) {
            const Task t = tasks.back();
            tasks.pop_back();
            Shell b;
            for (std::size_t i = t.first; i < t.last; ++i) {
                b.lo = glm::min(b.lo, shells_[ids_[i]].lo);
                b.hi = glm::max(b.hi, shells_[ids_[i]].hi);
            }
            nodes_[t.node].box = b;
            if (t.last - t.first <= 4) {
                nodes_[t.node].first = std::uint32_t(t.first);
                nodes_[t.node].count = std::uint32_t(t.last - t.first);
                continue;
            }
            const glm::dvec3 e = b.hi - b.lo;
            const int axis = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
            const std::size_t mid = (t.first + t.last) / 2;
            std::nth_element(ids_.begin() + std::ptrdiff_t(t.first), ids_.begin() + std::ptrdiff_t(mid),
                             ids_.begin() + std::ptrdiff_t(t.last), [&](std::uint32_t a, std::uint32_t c) {
                                 return shells_[a].lo[axis] + shells_[a].hi[axis] < shells_[c].lo[axis] + shells_[c].hi[axis];
                             });
            const auto left = std::uint32_t(nodes_.size());
            nodes_[t.node].first = left;
            nodes_.emplace_back();
            nodes_.emplace_back();
            tasks.push_back({left, t.first, mid});
            tasks.push_back({left + 1, mid, t.last});
        }
    }

    const std::vector<Shell>& shells_;
    std::vector<std::uint32_t> ids_;
    std::vector<Node> nodes_;
};

double maxAbs(const glm::dvec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

/// Ray parity of `p` against the triangles `tris` (welded geometry in `mesh`): 1 inside,
/// 0 outside, -1 undecided (the ray grazes an edge or vertex within tolerance, or `p` lies on
/// the surface). Exact float inputs, differences in double (exact for coordinates within
/// 2^29 of each other's magnitude; the query point, a centroid, is
/// rounded once), triple products with about 1e-15 relative error; the
/// 1e-12 tolerance leaves a wide margin, so a decided answer is right for a closed shell
/// that does not intersect itself; near-misses are reported undecided rather than guessed.
/// Limits: a self-intersecting container can give either parity; and the caller tests one
/// point on the inner shell, so two shells that intersect each other (partly inside) get
/// the answer of that point.
int rayParity(const Mesh& mesh, const std::uint32_t* tris, std::size_t count, const glm::dvec3& p,
              const glm::dvec3& d, std::uint64_t& work) {
    constexpr double kTol = 1e-12;
    bool inside = false;
    work += count;
    for (std::size_t i = 0; i < count; ++i) {
        const std::size_t t = std::size_t(tris[i]) * 3;
        const glm::dvec3 A = glm::dvec3(mesh.positions[mesh.indices[t]]) - p;
        const glm::dvec3 B = glm::dvec3(mesh.positions[mesh.indices[t + 1]]) - p;
        const glm::dvec3 C = glm::dvec3(mesh.positions[mesh.indices[t + 2]]) - p;
        const double a = maxAbs(A), b = maxAbs(B), c = maxAbs(C), dm = maxAbs(d);
        // The ray's line passes through the triangle iff it sees the three edges turning the
        // same way: signs of d . (A x B), d . (B x C), d . (C x A).
        const double s[3] = {glm::dot(d, glm::cross(A, B)), glm::dot(d, glm::cross(B, C)),
                             glm::dot(d, glm::cross(C, A))};
        const double tol[3] = {kTol * dm * a * b, kTol * dm * b * c, kTol * dm * c * a};
        bool pos = false, neg = false, zero = false;
        for (int k = 0; k < 3; ++k) {
            if (s[k] > tol[k]) pos = true;
            else if (s[k] < -tol[k]) neg = true;
            else zero = true;
        }
        if (pos && neg) continue;  // clearly misses
        if (zero) return -1;       // through an edge or vertex, or in the triangle's plane
        // Inside the cone: the hit is in front iff det(A, B, C) has the cones' sign.
        const double det = glm::dot(A, glm::cross(B, C));
        if (std::abs(det) <= kTol * a * b * c * 3.0) return -1;  // p on the triangle
        if ((det > 0.0) == pos) inside = !inside;
    }
    return inside ? 1 : 0;
}

struct Analysis {
    SurfaceReport report;
    std::vector<std::uint32_t> flipTriangles;  ///< triangles orientSurface swaps
};

Analysis analyse(const Mesh& mesh) {
    const auto t0 = std::chrono::steady_clock::now();
    assert(validateMesh(mesh).empty());
    Analysis out;
    SurfaceReport& r = out.report;
    const std::size_t triCount = mesh.triangleCount();
    r.triangles = triCount;
    // Edge entries pack (t << 1) and edge offsets are 32-bit: 3 * triangles must fit.
    if (triCount > 0xffffffffu / 3) throw std::length_error("analyseSurface: more than 1,431,655,765 triangles");
    const std::vector<std::uint32_t> wid = detail::weldVertices(mesh.positions, r.weldedVertices);

    // Directed edges bucketed by their lower welded vertex (counting sort): entry =
    // (higher vertex << 32) | (triangle << 1) | (lower -> higher is the triangle's direction).
    std::vector<std::uint32_t> offset(r.weldedVertices + 1, 0);
    std::vector<bool> degenerate(triCount, false);
    for (std::size_t t = 0; t < triCount; ++t) {
        const std::uint32_t v[3] = {wid[mesh.indices[3 * t]], wid[mesh.indices[3 * t + 1]], wid[mesh.indices[3 * t + 2]]};
        if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
            degenerate[t] = true;
            ++r.degenerateTriangles;
            continue;
        }
        for (int k = 0; k < 3; ++k) ++offset[std::min(v[k], v[(k + 1) % 3]) + 1];
    }
    std::partial_sum(offset.begin(), offset.end(), offset.begin());
    std::vector<std::uint64_t> entries(offset.back());
    {
        std::vector<std::uint32_t> fill(offset.begin(), offset.end() - 1);
        for (std::uint32_t t = 0; t < triCount; ++t) {
            if (degenerate[t]) continue;
            const std::uint32_t v[3] = {wid[mesh.indices[3 * t]], wid[mesh.indices[3 * t + 1]], wid[mesh.indices[3 * t + 2]]};
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t u = v[k], w = v[(k + 1) % 3];
                const std::uint32_t lo = std::min(u, w), hi = std::max(u, w);
                entries[fill[lo]++] = (std::uint64_t(hi) << 32) | (std::uint64_t(t) << 1) | (u < w ? 1u : 0u);
            }
        }
    }

    // Group equal edges; join their triangles into shells; remember one triangle per
    // problem edge to blame its shell once shells are known.
    std::vector<std::uint32_t> parent(triCount);
    std::iota(parent.begin(), parent.end(), 0u);
    std::vector<std::uint32_t> openTris, misTris;              // boundary/non-manifold, misoriented
    std::vector<std::pair<std::uint32_t, std::uint32_t>> boundary;  // welded ends, for holes
    for (std::size_t lo = 0; lo + 1 < offset.size(); ++lo) {
        const auto first = entries.begin() + offset[lo], last = entries.begin() + offset[lo + 1];
        std::sort(first, last);  // by higher vertex, then triangle: buckets hold a vertex's valence
        for (auto g = first; g != last;) {
            const std::uint32_t hi = std::uint32_t(*g >> 32);
            auto e = g;
            std::size_t forward = 0;
            for (; e != last && std::uint32_t(*e >> 32) == hi; ++e) forward += *e & 1u;
            const std::size_t uses = std::size_t(e - g);
            const std::uint32_t t = std::uint32_t(*g) >> 1;
            ++r.edges;
            for (auto o = g + 1; o != e; ++o) unite(parent, t, std::uint32_t(*o) >> 1);
            if (uses == 1) {
                ++r.boundaryEdges;
                openTris.push_back(t);
                boundary.emplace_back(std::uint32_t(lo), hi);
            } else if (uses > 2) {
                ++r.nonManifoldEdges;
                openTris.push_back(t);
            } else if (forward != 1) {
                ++r.misorientedEdges;
                misTris.push_back(t);
            }
            g = e;
        }
    }
    entries = {};
    offset = {};

    // Holes: connected groups of boundary edges (loops touching at a vertex count as one).
    if (!boundary.empty()) {
        std::vector<std::uint32_t> vparent(r.weldedVertices, kNone);
        std::size_t vertices = 0, joins = 0;
        for (const auto& [a, b] : boundary)
            for (std::uint32_t v : {a, b})
                if (vparent[v] == kNone) {
                    vparent[v] = v;
                    ++vertices;
                }
        for (const auto& [a, b] : boundary) joins += unite(vparent, a, b);
        r.holes = vertices - joins;
    }

    // Shells: dense ids per union-find root, and their triangles (CSR).
    std::vector<std::uint32_t> shellOf(triCount, kNone);
    std::uint32_t shellCount = 0;
    for (std::uint32_t t = 0; t < triCount; ++t) {
        if (degenerate[t]) continue;
        const std::uint32_t root = findRoot(parent, t);
        if (shellOf[root] == kNone) shellOf[root] = shellCount++;  // root <= t: set before use
        shellOf[t] = shellOf[root];
    }
    parent = {};
    r.shells = shellCount;
    std::vector<std::uint32_t> shellStart(shellCount + 1, 0), shellTris(triCount - r.degenerateTriangles);
    for (std::uint32_t t = 0; t < triCount; ++t)
        if (shellOf[t] != kNone) ++shellStart[shellOf[t] + 1];
    std::partial_sum(shellStart.begin(), shellStart.end(), shellStart.begin());
    {
        std::vector<std::uint32_t> fill(shellStart.begin(), shellStart.end() - 1);
        for (std::uint32_t t = 0; t < triCount; ++t)
            if (shellOf[t] != kNone) shellTris[fill[shellOf[t]]++] = t;
    }

    std::vector<Shell> shells(shellCount);
    for (std::uint32_t t : openTris) shells[shellOf[t]].closed = false;
    for (std::uint32_t t : misTris) shells[shellOf[t]].consistent = false;
    for (std::uint32_t t = 0; t < triCount; ++t) {
        if (shellOf[t] == kNone) continue;
        Shell& s = shells[shellOf[t]];
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3 p(mesh.positions[mesh.indices[3 * t + k]]);
            s.lo = glm::min(s.lo, p);
            s.hi = glm::max(s.hi, p);
        }
    }
    // Signed volume (divergence theorem) relative to the shell's own box centre, in double:
    // with coordinates of 1e6 and a unit-sized shell, products about the origin would lose
    // the volume in rounding.
    for (std::uint32_t t = 0; t < triCount; ++t) {
        if (shellOf[t] == kNone) continue;
        Shell& s = shells[shellOf[t]];
        const glm::dvec3 c = s.centre();
        const glm::dvec3 a = glm::dvec3(mesh.positions[mesh.indices[3 * t]]) - c;
        const glm::dvec3 b = glm::dvec3(mesh.positions[mesh.indices[3 * t + 1]]) - c;
        const glm::dvec3 d = glm::dvec3(mesh.positions[mesh.indices[3 * t + 2]]) - c;
        s.volume += glm::dot(a, glm::cross(b, d)) / 6.0;
        s.area += 0.5 * glm::length(glm::cross(b - a, d - a));
    }
    for (Shell& s : shells) {
        r.closedShells += s.closed;
        if (!s.closed || !s.consistent) continue;
        // Zero volume: mean thickness |V| / area within 4 float ulps of the shell's own extent,
        // i.e. flat to the precision the shape carries (two coincident opposite triangles: 0).
        const double extent = std::max({s.hi.x - s.lo.x, s.hi.y - s.lo.y, s.hi.z - s.lo.z});
        const double eps = s.area * extent * std::ldexp(1.0, -21);
        s.facing = std::abs(s.volume) <= eps ? Facing::Flat : s.volume > 0.0 ? Facing::Outward : Facing::Inward;
    }

    // Inward shells, largest box first, so a container's own fate is settled before the shells
    // it may contain (a container's box contains theirs; equal boxes: lower index first).
    std::vector<std::uint32_t> inward;
    for (std::uint32_t i = 0; i < shellCount; ++i)
        if (shells[i].facing == Facing::Inward) inward.push_back(i);
    std::sort(inward.begin(), inward.end(), [&](std::uint32_t a, std::uint32_t b) {
        const double va = shells[a].boxVolume(), vb = shells[b].boxVolume();
        return va != vb ? va > vb : a < b;
    });
    // Directions with no simple ratios between components: an axis-aligned or diagonal ray
    // would run along the edges and faces of boxes and grids, the commonest modelled shapes.
    static constexpr double kDirs[4][3] = {
        {0.5377, 0.2630, 0.8010}, {-0.3897, 0.8481, 0.3589}, {0.6133, -0.7152, 0.3352}, {-0.2719, -0.4356, -0.8582}};
    const std::uint64_t budget = kNestingBudgetBase + kNestingBudgetPerTriangle * shellTris.size();
    std::uint64_t work = 0;
    std::vector<bool> processed(shellCount, false);
    std::vector<std::uint32_t> containerIds;  // possible containers: closed, consistent, not flat
    if (!inward.empty())
        for (std::uint32_t i = 0; i < shellCount; ++i)
            if (shells[i].facing == Facing::Outward || shells[i].facing == Facing::Inward) containerIds.push_back(i);
    const ContainerTree tree(shells, std::move(containerIds));
    for (std::uint32_t si : inward) {
        Shell& s = shells[si];
        const std::uint32_t* sTris = shellTris.data() + shellStart[si];
        const std::size_t sCount = shellStart[si + 1] - shellStart[si];
        bool cavity = false, undecided = work > budget;
        if (!undecided)
            tree.forEachContaining(s, work, [&](std::uint32_t ti) {
                const Shell& o = shells[ti];
                // Containers face outwards: outward shells, and inward ones already flipped.
                const bool outward = o.facing == Facing::Outward || (processed[ti] && o.fate == Fate::Flip);
                if (cavity || ti == si || !outward) return;
                if (work > budget) {
                    undecided = true;
                    return;
                }
                // From the centroids of up to 4 triangles of s (not vertices: a cavity touching
                // its container at a corner is common), 4 directions each: the first decided
                // answer wins; none decided leaves s ambiguous (two-sided).
                int answer = -1;
                for (int vk = 0; vk < 4 && answer < 0; ++vk) {
                    const std::size_t t = 3 * std::size_t(sTris[(sCount - 1) * std::size_t(vk) / 3]);
                    const glm::dvec3 p = (glm::dvec3(mesh.positions[mesh.indices[t]]) +
                                          glm::dvec3(mesh.positions[mesh.indices[t + 1]]) +
                                          glm::dvec3(mesh.positions[mesh.indices[t + 2]])) / 3.0;
                    for (int dk = 0; dk < 4 && answer < 0; ++dk)
                        answer = rayParity(mesh, shellTris.data() + shellStart[ti], shellStart[ti + 1] - shellStart[ti],
                                           p, glm::dvec3(kDirs[dk][0], kDirs[dk][1], kDirs[dk][2]), work);
                }
                if (answer == 1) cavity = true;
                else if (answer < 0) undecided = true;
            });
        s.fate = cavity ? Fate::Cavity : undecided ? Fate::Ambiguous : Fate::Flip;
        processed[si] = true;
    }

    bool cull = shellCount > 0;
    for (std::uint32_t i = 0; i < shellCount; ++i) {
        const Shell& s = shells[i];
        const bool flip = s.fate == Fate::Flip;
        r.signedVolume += flip ? -s.volume : s.volume;
        r.flippedShells += flip;
        r.cavityShells += s.fate == Fate::Cavity;
        r.ambiguousShells += s.fate == Fate::Ambiguous;
        r.zeroVolumeShells += s.facing == Facing::Flat;
        if (s.facing == Facing::Unusable || s.facing == Facing::Flat || s.fate == Fate::Ambiguous) cull = false;
        if (flip) out.flipTriangles.insert(out.flipTriangles.end(), shellTris.begin() + shellStart[i],
                                           shellTris.begin() + shellStart[i + 1]);
    }
    r.mode = cull ? FaceMode::CullBack : FaceMode::TwoSided;
    r.analyseMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return out;
}

std::string countOf(std::size_t n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
}

}  // namespace

std::string SurfaceReport::summary() const {
    const std::size_t usable = triangles - degenerateTriangles;
    std::string s;
    if (triangles == 0) return "empty (no triangles, nothing to draw): two-sided";
    if (usable == 0) return "all " + countOf(triangles, "triangle", "triangles") + " degenerate: two-sided";
    auto add = [&s](const std::string& part) { s += (s.empty() ? "" : ", ") + part; };
    if (mode == FaceMode::CullBack) {
        s = "closed, consistent, outward";
        std::string detail;
        auto more = [&detail](const std::string& part) { detail += (detail.empty() ? "" : ", ") + part; };
        if (shells > 1) more(countOf(shells, "shell", "shells"));
        if (flippedShells) more(std::to_string(flippedShells) + " flipped");
        if (cavityShells) more(countOf(cavityShells, "cavity", "cavities"));
        if (!detail.empty()) s += " (" + detail + ")";
        s += ": cull back faces";
    } else {
        if (boundaryEdges)
            add("open (" + countOf(boundaryEdges, "boundary edge", "boundary edges") + " in " +
                countOf(holes, "hole", "holes") + ")");
        if (nonManifoldEdges) add("non-manifold (" + countOf(nonManifoldEdges, "edge", "edges") + ")");
        if (misorientedEdges) add("inconsistent (" + countOf(misorientedEdges, "misoriented edge", "misoriented edges") + ")");
        if (zeroVolumeShells) add(countOf(zeroVolumeShells, "flat closed shell", "flat closed shells") + " (zero volume)");
        if (ambiguousShells) add(countOf(ambiguousShells, "inward shell", "inward shells") + " of undecided nesting");
        if (s.empty()) add("undecided");
        s += ": two-sided";
        if (flippedShells) s += " (" + std::to_string(flippedShells) + " closed shells flipped outward)";
    }
    if (degenerateTriangles) s += "; " + countOf(degenerateTriangles, "degenerate triangle", "degenerate triangles") + " ignored";
    return s;
}

SurfaceReport analyseSurface(const Mesh& mesh) { return analyse(mesh).report; }

SurfaceReport orientSurface(Mesh& mesh) {
    const auto t0 = std::chrono::steady_clock::now();
    Analysis a = analyse(mesh);
    for (std::uint32_t t : a.flipTriangles) std::swap(mesh.indices[3 * std::size_t(t) + 1], mesh.indices[3 * std::size_t(t) + 2]);
    a.report.analyseMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return a.report;
}

}  // namespace dyncull
