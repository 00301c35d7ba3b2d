// Per-node query volumes of a local BSP (see node_volumes.hpp).
// Papers: kdop-bounding-volumes-for-occlusion.txt, sections 3.3 and 5.2;
// out-of-core-obb-depth-queries.txt, section 3.
#include "dyncull/bsp/node_volumes.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>

#include "dyncull/bsp/local_bsp.hpp"
#include "dyncull/objects/convex_mesh.hpp"
#include "dyncull/objects/kdop.hpp"
#include "dyncull/objects/obb.hpp"

namespace dyncull {
namespace {

class Writer {
public:
    explicit Writer(NodeVolumes& out) : out_(out) {}

    void box(const std::array<glm::vec3, 8>& corners) {
        NodeVolume v;
        v.firstVertex = static_cast<std::uint32_t>(out_.vertices.size());
        v.firstIndex = static_cast<std::uint32_t>(out_.indices.size());
        v.vertexCount = 8;
        out_.vertices.insert(out_.vertices.end(), corners.begin(), corners.end());
        measure(v, std::span<const glm::vec3>(corners), kBoxTriangles);
        out_.entries.push_back(v);
    }
    void mesh(const ConvexMesh& m) {
        assert(m.vertices.size() <= 255 && m.triangleCount() <= 255);
        NodeVolume v;
        v.firstVertex = static_cast<std::uint32_t>(out_.vertices.size());
        v.firstIndex = static_cast<std::uint32_t>(out_.indices.size());
        v.vertexCount = static_cast<std::uint8_t>(m.vertices.size());
        v.triangleCount = static_cast<std::uint8_t>(m.triangleCount());
        out_.vertices.insert(out_.vertices.end(), m.vertices.begin(), m.vertices.end());
        out_.indices.insert(out_.indices.end(), m.indices.begin(), m.indices.end());
        measure(v, m.vertices, m.indices);
        out_.entries.push_back(v);
    }
    void empty() { out_.entries.push_back({}); }

private:
    static void measure(NodeVolume& v, std::span<const glm::vec3> verts, std::span<const std::uint8_t> idx) {
        v.surfaceArea = static_cast<float>(meshSurfaceArea(verts, idx));
        v.volume = static_cast<float>(meshVolume(verts, idx));
    }
    NodeVolumes& out_;
};

std::array<glm::vec3, 8> boxCorners(const Aabb& b) {
    std::array<glm::vec3, 8> c;
    for (int i = 0; i < 8; ++i)
        c[i] = {(i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y, (i & 4) ? b.max.z : b.min.z};
    return c;
}

}  // namespace

NodeVolumes buildNodeVolumes(const Mesh& mesh, const std::vector<LocalBspNode>& nodes) {
    const auto t0 = std::chrono::steady_clock::now();
    NodeVolumes out;
    out.entries.reserve(nodes.size() * kVolumeKindCount);
    out.vertices.reserve(nodes.size() * 100);
    out.indices.reserve(nodes.size() * 600);
    Writer w(out);
    std::vector<std::uint32_t> stamp(mesh.positions.size(), UINT32_MAX);
    std::vector<glm::vec3> points;
    for (std::uint32_t n = 0; n < nodes.size(); ++n) {
        const LocalBspNode& node = nodes[n];
        // Each referenced vertex once: repeated indices must not weight the PCA.
        points.clear();
        bool geometry = std::size_t{node.firstIndex} + node.indexCount <= mesh.indices.size();
        for (std::uint32_t i = node.firstIndex; geometry && i < node.firstIndex + node.indexCount; ++i) {
            const std::uint32_t v = mesh.indices[i];
            if (v >= mesh.positions.size()) {
                geometry = false;
                break;
            }
            if (stamp[v] == n) continue;
            stamp[v] = n;
            points.push_back(mesh.positions[v]);
        }
        if (!geometry && !node.box.empty()) {
            // A tree without (matching) triangles, e.g. built by hand: every kind is the
            // node's box, which bounds whatever the node stands for.
            for (std::uint32_t k = 0; k < kVolumeKindCount; ++k) w.box(boxCorners(node.box));
            continue;
        }
        if (points.empty()) {
            for (std::uint32_t k = 0; k < kVolumeKindCount; ++k) w.empty();
            continue;
        }
        Aabb box;
        for (const glm::vec3& p : points) box.extend(p);
        w.box(boxCorners(box));
        const Obb obb = fitObbPca(points);
        w.box(obb.isAabb ? boxCorners(box) : obb.corners());  // exact corners when it falls back
        const Kdop k26 = computeKdop(KdopType::K26, points);
        w.mesh(kdopBoundary(restrictKdop(k26, KdopType::K14)));
        w.mesh(kdopBoundary(restrictKdop(k26, KdopType::K18)));
        w.mesh(kdopBoundary(k26));
    }
    out.buildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return out;
}

VolumeKind chooseVolume(const NodeVolumes& volumes, std::uint32_t node, VolumeChoice choice, float autoSaving) {
    if (choice != VolumeChoice::Auto) return kindOf(choice);
    const NodeVolume& aabb = volumes.get(node, VolumeKind::Aabb);
    const NodeVolume& obb = volumes.get(node, VolumeKind::Obb);
    const VolumeKind box = obb.surfaceArea < aabb.surfaceArea ? VolumeKind::Obb : VolumeKind::Aabb;
    const float boxArea = std::min(aabb.surfaceArea, obb.surfaceArea);
    VolumeKind dop = VolumeKind::Kdop26;
    for (VolumeKind k : {VolumeKind::Kdop18, VolumeKind::Kdop14})
        if (volumes.get(node, k).surfaceArea < volumes.get(node, dop).surfaceArea) dop = k;
    return volumes.get(node, dop).surfaceArea <= (1.0f - autoSaving) * boxArea ? dop : box;
}

}  // namespace dyncull
