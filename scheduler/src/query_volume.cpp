// Query volumes in world space: boxes (8 corners) and convex node-volume meshes whose
// object-space vertices are transformed while their triangles are kept.
// Paper: kdop-bounding-volumes-for-occlusion.txt, section 3.3 (under rigid motion,
// "update the vertices of the original k-dop, and then render the same triangles").
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "dyncull/objects/convex_mesh.hpp"
#include "dyncull/scheduler/query_backend.hpp"

namespace dyncull {

std::span<const std::uint8_t> QueryVolume::triangles() const {
    if (isBox()) return kBoxTriangles;
    return {indices.data(), 3u * triangleCount};
}

QueryVolume QueryVolume::fromAabb(const Aabb& box) {
    QueryVolume v;
    v.vertexCount = 8;
    for (int i = 0; i < 8; ++i)
        v.vertices[i] = {(i & 1) ? box.max.x : box.min.x, (i & 2) ? box.max.y : box.min.y,
                         (i & 4) ? box.max.z : box.min.z};
    return v;
}

QueryVolume QueryVolume::fromTransformedBox(const glm::mat4& objectToWorld, const Aabb& local) {
    QueryVolume v = fromAabb(local);
    for (std::uint32_t i = 0; i < 8; ++i) v.vertices[i] = glm::vec3(objectToWorld * glm::vec4(v.vertices[i], 1.0f));
    return v;
}

QueryVolume QueryVolume::fromNodeVolume(const glm::mat4& objectToWorld, const NodeVolumes& volumes, const NodeVolume& nv) {
    assert(nv.vertexCount <= kMaxVertices && nv.triangleCount <= kMaxTriangles);
    assert(nv.vertexCount == 0 || !nv.isBox() || nv.vertexCount == 8);
    QueryVolume v;
    const std::span<const glm::vec3> src = volumes.verticesOf(nv);
    v.vertexCount = nv.vertexCount;
    for (std::uint32_t i = 0; i < nv.vertexCount; ++i) v.vertices[i] = glm::vec3(objectToWorld * glm::vec4(src[i], 1.0f));
    const std::span<const std::uint8_t> tri = volumes.indicesOf(nv);
    std::copy(tri.begin(), tri.end(), v.indices.begin());
    v.triangleCount = nv.triangleCount;
    return v;
}

std::uint32_t QueryVolume::enlargedForRounding(const glm::dvec3& eye, std::array<glm::dvec3, kMaxVertices>& out,
                                               bool& asBox) const {
    const std::uint32_t nv = vertexCount;
    glm::dvec3 centre(0.0);
    double magnitude = 0.0;
    const double share = 1.0 / double(nv);
    for (std::uint32_t i = 0; i < nv; ++i) {
        const glm::dvec3 v(vertices[i]);
        centre += v * share;
        magnitude = std::max({magnitude, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    }
    const double slack = magnitude * 0x1p-22, push = slack * std::sqrt(3.0);
    // Scaling about the centre moves every face out by (k - 1) times its distance from the
    // centre and keeps its normal, so k = 1 + push / (nearest face distance) moves each
    // face out by at least `push` (a per-axis push would slide tilted faces along themselves).
    // The nearest face's distance, dot(n, a - centre)^2 / |n|^2 at its least, compared as
    // cross products of the ratios so that only the least takes a square root. In units of
    // a power of two near the magnitude (exact), so that the fifth powers cannot overflow.
    int exponent = 0;
    std::frexp(magnitude, &exponent);
    const double unit = std::ldexp(1.0, exponent), perUnit = std::ldexp(1.0, -exponent);
    const glm::dvec3 scaledCentre = centre * perUnit;
    double bestDot2 = std::numeric_limits<double>::infinity(), bestLen2 = 1.0;
    const std::span<const std::uint8_t> tris = triangles();
    for (std::size_t t = 0; t + 2 < tris.size(); t += 3) {
        const glm::dvec3 a = glm::dvec3(vertices[tris[t]]) * perUnit, b = glm::dvec3(vertices[tris[t + 1]]) * perUnit,
                         c = glm::dvec3(vertices[tris[t + 2]]) * perUnit;
        const glm::dvec3 n = glm::cross(b - a, c - a);
        const double len2 = glm::dot(n, n), d = glm::dot(n, a - scaledCentre), dot2 = d * d;
        if (len2 > 0.0 && dot2 * bestLen2 < bestDot2 * len2) {  // zero-area: no face
            bestDot2 = dot2;
            bestLen2 = len2;
        }
    }
    const double nearest =
        std::isfinite(bestDot2) ? std::sqrt(bestDot2 / bestLen2) * unit : std::numeric_limits<double>::infinity();
    // Thinner than a few roundings (e.g. collapsed flat by them): its vertices' axis-aligned
    // box instead, each face pushed out along its axis; on an axis where the box is flat the
    // corner's index bit says which side it belongs to.
    asBox = !(std::isfinite(nearest) && nearest > 4.0 * push);
    if (asBox) {
        glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
        for (std::uint32_t i = 0; i < nv; ++i) {
            lo = glm::min(lo, glm::dvec3(vertices[i]));
            hi = glm::max(hi, glm::dvec3(vertices[i]));
        }
        for (std::uint32_t i = 0; i < 8; ++i)
            out[i] = glm::dvec3((i & 1u) ? hi.x + push : lo.x - push, (i & 2u) ? hi.y + push : lo.y - push,
                                (i & 4u) ? hi.z + push : lo.z - push) - eye;
        return 8;
    }
    const double k = 1.0 + push / nearest;
    for (std::uint32_t i = 0; i < nv; ++i) out[i] = centre + (glm::dvec3(vertices[i]) - centre) * k - eye;
    return nv;
}

}  // namespace dyncull
