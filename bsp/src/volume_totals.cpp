// World-space totals of the leaf query volumes (see volume_totals.hpp).
// Paper: kdop-bounding-volumes-for-occlusion.txt, section 5.2 (Table 5) and 5.3 (Table 2).
#include "dyncull/bsp/volume_totals.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "dyncull/objects/convex_mesh.hpp"

namespace dyncull {

LeafVolumeTotals leafVolumeTotals(const SceneObjects& objects, VolumeChoice choice, float autoSaving) {
    LeafVolumeTotals t;
    std::vector<glm::vec3> world;
    for (std::uint32_t i = 0; i < objects.slotCount(); ++i) {
        if (!objects.alive(i)) continue;
        const LocalBsp& model = objects.model(objects.modelOf(i));
        const glm::mat4& m = objects.matrix(i);
        for (std::uint32_t n = 0; n < model.nodes.size(); ++n) {
            const LocalBspNode& node = model.nodes[n];
            if (!node.isLeaf() || node.indexCount == 0) continue;
            const VolumeKind kind = chooseVolume(model.volumes, n, choice, autoSaving);
            const NodeVolume& v = model.volumes.get(n, kind);
            if (v.vertexCount == 0) continue;
            world.clear();
            for (const glm::vec3& p : model.volumes.verticesOf(v)) world.push_back(glm::vec3(m * glm::vec4(p, 1.0f)));
            const std::span<const std::uint8_t> tris =
                v.isBox() ? std::span<const std::uint8_t>(kBoxTriangles) : model.volumes.indicesOf(v);
            ++t.leaves;
            ++t.leavesByKind[static_cast<std::size_t>(kind)];
            // A mirroring transform turns the triangles inward: the volume's size is |signed volume|.
            t.volume += std::abs(meshVolume(world, tris));
            t.surfaceArea += meshSurfaceArea(world, tris);
            const std::uint32_t nt = static_cast<std::uint32_t>(tris.size() / 3);
            t.triangles += nt;
            t.maxTriangles = std::max(t.maxTriangles, nt);
        }
    }
    return t;
}

}  // namespace dyncull
