// Hole capping: boundary loops walked on welded vertices, each closed by a centroid fan.
#include "dyncull/objects/hole_capping.hpp"

#include <algorithm>
#include <cassert>
#include <cstdint>
#include <vector>

#include "vertex_weld.hpp"

namespace dyncull {
namespace {

constexpr std::uint32_t kNone = 0xffffffffu;

struct DirectedEdge {
    std::uint32_t from, to;  // welded ids
    std::uint32_t fromVertex, toVertex;  // mesh vertex indices, to reuse in the cap
    bool operator<(const DirectedEdge& o) const { return from != o.from ? from < o.from : to < o.to; }
};

}  // namespace

HoleCapping capHoles(Mesh& mesh, std::size_t maxLoopEdges) {
    HoleCapping out;
    std::size_t welded = 0;
    const std::vector<std::uint32_t> wid = detail::weldVertices(mesh.positions, welded);

    // Every directed edge of the non-degenerate triangles, sorted: an edge is on the rim
    // when it occurs once and its reverse never does.
    std::vector<DirectedEdge> edges;
    edges.reserve(mesh.indices.size());
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t v[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
        const std::uint32_t w[3] = {wid[v[0]], wid[v[1]], wid[v[2]]};
        if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) continue;  // degenerate: no edges
        for (int k = 0; k < 3; ++k) edges.push_back({w[k], w[(k + 1) % 3], v[k], v[(k + 1) % 3]});
    }
    std::sort(edges.begin(), edges.end());
    auto count = [&](std::uint32_t a, std::uint32_t b) {
        const DirectedEdge key{a, b, 0, 0};
        const auto [lo, hi] = std::equal_range(edges.begin(), edges.end(), key);
        return static_cast<std::size_t>(hi - lo);
    };

    // Rim edges by their start vertex. A consistent manifold rim has exactly one rim edge
    // leaving each rim vertex; a vertex with more is where loops touch.
    std::vector<DirectedEdge> rim;
    for (std::size_t i = 0; i < edges.size(); ++i) {
        const DirectedEdge& e = edges[i];
        const bool single = (i == 0 || edges[i - 1] < e) && (i + 1 == edges.size() || e < edges[i + 1]);
        if (single && count(e.to, e.from) == 0) rim.push_back(e);
    }
    if (rim.empty()) return out;
    std::vector<std::uint32_t> firstOut(welded, kNone), outDegree(welded, 0);
    for (std::uint32_t i = 0; i < rim.size(); ++i) {  // rim is sorted by `from`
        if (firstOut[rim[i].from] == kNone) firstOut[rim[i].from] = i;
        ++outDegree[rim[i].from];
    }

    std::vector<std::uint8_t> used(rim.size(), 0);
    std::vector<std::uint32_t> loop;  // rim edge indices
    for (std::uint32_t start = 0; start < rim.size(); ++start) {
        if (used[start]) continue;
        loop.clear();
        bool simple = true;
        std::uint32_t e = start;
        // Follow rim edges head to tail until the loop returns to its start.
        while (true) {
            used[e] = 1;
            loop.push_back(e);
            const std::uint32_t next = rim[e].to;
            if (outDegree[next] != 1) simple = false;
            if (next == rim[start].from) break;
            const std::uint32_t f = firstOut[next];
            if (f == kNone || used[f]) {  // the rim ends (non-manifold neighbourhood)
                simple = false;
                break;
            }
            e = f;
        }
        if (!simple || loop.size() < 3 || loop.size() > maxLoopEdges) {
            ++out.skippedLoops;
            continue;
        }
        // Centroid in double: a loop far from the origin keeps its precision.
        glm::dvec3 sum(0.0);
        for (const std::uint32_t i : loop) sum += glm::dvec3(mesh.positions[rim[i].fromVertex]);
        const auto centre = static_cast<std::uint32_t>(mesh.positions.size());
        mesh.positions.push_back(glm::vec3(sum / static_cast<double>(loop.size())));
        glm::vec3 normal(0.0f);
        for (const std::uint32_t i : loop) {
            // The surface has a -> b; the cap takes b -> a, so both sides agree on the winding.
            const std::uint32_t a = rim[i].fromVertex, b = rim[i].toVertex;
            mesh.indices.insert(mesh.indices.end(), {b, a, centre});
            normal += glm::cross(mesh.positions[a] - mesh.positions[b], mesh.positions[centre] - mesh.positions[b]);
        }
        if (!mesh.normals.empty()) {
            const float len = glm::length(normal);
            mesh.normals.push_back(len > 0.0f ? normal / len : glm::vec3(0.0f, 0.0f, 1.0f));
        }
        ++out.holes;
        out.triangles += loop.size();
    }
    return out;
}

}  // namespace dyncull
