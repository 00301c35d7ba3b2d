// Loop subdivision (C. Loop, 1987, "Smooth Subdivision Surfaces Based on Triangles").
#include "dyncull/objects/loop_subdivision.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

namespace dyncull {
namespace {

struct EdgeUse {
    std::uint64_t key;     // (min vertex << 32) | max vertex
    std::uint32_t opposite;  // the triangle's third vertex
    std::uint32_t tri;
};

Mesh subdivideOnce(const Mesh& in) {
    const std::size_t nv = in.positions.size();
    const std::size_t nt = in.triangleCount();
    std::vector<EdgeUse> uses;
    uses.reserve(nt * 3);
    for (std::uint32_t t = 0; t < nt; ++t)
        for (int e = 0; e < 3; ++e) {
            const std::uint32_t a = in.indices[3 * t + e], b = in.indices[3 * t + (e + 1) % 3];
            const std::uint32_t c = in.indices[3 * t + (e + 2) % 3];
            uses.push_back({(std::uint64_t(std::min(a, b)) << 32) | std::max(a, b), c, t});
        }
    std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) { return x.key < y.key; });

    Mesh out;
    out.name = in.name;
    out.positions.resize(nv);
    // Per old vertex: sum and count of neighbours over all edges, and of crease neighbours.
    std::vector<glm::vec3> ringSum(nv, glm::vec3(0.0f)), creaseSum(nv, glm::vec3(0.0f));
    std::vector<std::uint32_t> ringCount(nv, 0), creaseCount(nv, 0);
    std::vector<std::uint32_t> edgeVertex(uses.size());  // per use: index of the new edge vertex

    for (std::size_t i = 0; i < uses.size();) {
        std::size_t j = i;
        while (j < uses.size() && uses[j].key == uses[i].key) ++j;
        const std::uint32_t a = static_cast<std::uint32_t>(uses[i].key >> 32);
        const std::uint32_t b = static_cast<std::uint32_t>(uses[i].key & 0xffffffffu);
        const glm::vec3 pa = in.positions[a], pb = in.positions[b];
        glm::vec3 p;
        const bool interior = (j - i) == 2;
        if (interior)
            p = 0.375f * (pa + pb) + 0.125f * (in.positions[uses[i].opposite] + in.positions[uses[i + 1].opposite]);
        else
            p = 0.5f * (pa + pb);  // boundary or non-manifold edge: crease rule
        const std::uint32_t v = static_cast<std::uint32_t>(out.positions.size());
        out.positions.push_back(p);
        for (std::size_t k = i; k < j; ++k) edgeVertex[k] = v;
        ringSum[a] += pb; ringSum[b] += pa;
        ++ringCount[a]; ++ringCount[b];
        if (!interior) {
            creaseSum[a] += pb; creaseSum[b] += pa;
            ++creaseCount[a]; ++creaseCount[b];
        }
        i = j;
    }

    for (std::size_t v = 0; v < nv; ++v) {
        const glm::vec3 p = in.positions[v];
        if (creaseCount[v] == 2) {
            out.positions[v] = 0.75f * p + 0.125f * creaseSum[v];
        } else if (creaseCount[v] == 0 && ringCount[v] >= 3) {
            const float n = static_cast<float>(ringCount[v]);
            const float c = 0.375f + 0.25f * std::cos(2.0f * std::numbers::pi_v<float> / n);
            const float beta = (0.625f - c * c) / n;
            out.positions[v] = (1.0f - n * beta) * p + beta * ringSum[v];
        } else {
            out.positions[v] = p;  // corner, crease junction or isolated vertex: keep it
        }
    }

    // Edge vertex of triangle t's edge e, found by binary search on the sorted uses.
    auto edgeVert = [&](std::uint32_t a, std::uint32_t b, std::uint32_t t) {
        const std::uint64_t key = (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
        auto it = std::lower_bound(uses.begin(), uses.end(), key, [](const EdgeUse& u, std::uint64_t k) { return u.key < k; });
        while (it->tri != t) ++it;  // the same edge may be used by a triangle twice only if degenerate
        return edgeVertex[static_cast<std::size_t>(it - uses.begin())];
    };
    out.indices.reserve(nt * 12);
    for (std::uint32_t t = 0; t < nt; ++t) {
        const std::uint32_t a = in.indices[3 * t], b = in.indices[3 * t + 1], c = in.indices[3 * t + 2];
        const std::uint32_t ab = edgeVert(a, b, t), bc = edgeVert(b, c, t), ca = edgeVert(c, a, t);
        const std::uint32_t tris[12] = {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca};
        out.indices.insert(out.indices.end(), tris, tris + 12);
    }
    return out;
}

}  // namespace

Mesh loopSubdivide(const Mesh& mesh, int levels) {
    Mesh m = mesh;
    for (int i = 0; i < levels; ++i) m = subdivideOnce(m);
    computeNormals(m);
    return m;
}

}  // namespace dyncull
