// Query volumes in world space: boxes (8 corners) and convex node-volume meshes whose
// object-space vertices are transformed while their triangles are kept.
// Paper: kdop-bounding-volumes-for-occlusion.txt, section 3.3 (under rigid motion,
// "update the vertices of the original k-dop, and then render the same triangles").
#include <algorithm>
#include <cassert>

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

}  // namespace dyncull
