// Clusters of consecutive triangles inside local-BSP leaves, with their boxes and normal
// cones (meshoptimizer's meshopt_computeClusterBounds; Wihlidal, "Optimizing the Graphics
// Pipeline with Compute", 2016, for the cone test).
#include "dyncull/bsp/leaf_clusters.hpp"

#include <cassert>

#include <meshoptimizer.h>

#include "dyncull/bsp/local_bsp.hpp"

namespace dyncull {

namespace {

bool rangesFit(const Mesh& mesh, const std::vector<LocalBspNode>& nodes) {
    for (const LocalBspNode& n : nodes) {
        if (n.firstIndex > mesh.indices.size() || n.indexCount > mesh.indices.size() - n.firstIndex) return false;
        for (std::uint32_t i = n.firstIndex; i < n.firstIndex + n.indexCount; ++i)
            if (mesh.indices[i] >= mesh.positions.size()) return false;
    }
    return true;
}

LeafCluster boundsOf(const Mesh& mesh, std::uint32_t first, std::uint32_t count) {
    LeafCluster c;
    c.firstIndex = first;
    c.indexCount = count;
    for (std::uint32_t i = first; i < first + count; ++i) c.box.extend(mesh.positions[mesh.indices[i]]);
    const meshopt_Bounds b = meshopt_computeClusterBounds(mesh.indices.data() + first, count, &mesh.positions[0].x,
                                                          mesh.positions.size(), sizeof(glm::vec3));
    // meshoptimizer answers cutoff 1 for a cone it will not vouch for (normals wider than
    // a hemisphere, or only zero-area triangles); 2 can never be reached by a cosine.
    const bool useful = b.cone_cutoff < 1.0f && (b.cone_axis[0] != 0.0f || b.cone_axis[1] != 0.0f || b.cone_axis[2] != 0.0f);
    if (useful) {
        c.coneApex = {b.cone_apex[0], b.cone_apex[1], b.cone_apex[2]};
        c.coneAxis = {b.cone_axis[0], b.cone_axis[1], b.cone_axis[2]};
        c.coneCutoff = b.cone_cutoff;
    }
    return c;
}

}  // namespace

bool LeafCluster::backFacingFrom(const glm::dvec3& eye) const {
    if (coneCutoff >= 1.0f || box.empty()) return false;
    const glm::dvec3 toApex = glm::dvec3(coneApex) - eye;
    const double distance = glm::length(toApex);
    const double diagonal = glm::length(glm::dvec3(box.max) - glm::dvec3(box.min));
    if (!(distance > 0x1p-10 * diagonal)) return false;
    return glm::dot(toApex, glm::dvec3(coneAxis)) >= (double(coneCutoff) + kConeMargin) * distance;
}

bool LeafCluster::backFacingAlong(const glm::dvec3& direction) const {
    if (coneCutoff >= 1.0f) return false;
    const double length = glm::length(direction);
    return length > 0.0 && glm::dot(direction, glm::dvec3(coneAxis)) >= (double(coneCutoff) + kConeMargin) * length;
}

LeafClusters clustersOf(const Mesh& mesh, const std::vector<LocalBspNode>& nodes) {
    LeafClusters out;
    out.nodeFirst.reserve(nodes.size() + 1);
    const bool fits = rangesFit(mesh, nodes);
    // Per vertex, the last cluster that used it: a vertex is new to the current run when
    // its stamp differs. Stamps count up across leaves, so nothing is ever reset.
    std::vector<std::uint32_t> stamp(fits ? mesh.positions.size() : 0, kInvalidIndex);
    std::uint32_t run = 0;
    for (const LocalBspNode& node : nodes) {
        out.nodeFirst.push_back(static_cast<std::uint32_t>(out.clusters.size()));
        if (!node.isLeaf() || !fits || node.indexCount == 0) continue;
        std::uint32_t start = node.firstIndex, vertices = 0;
        const std::uint32_t end = node.firstIndex + node.indexCount;
        for (std::uint32_t t = node.firstIndex; t < end; t += 3) {
            std::uint32_t added = 0;
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t v = mesh.indices[t + k];
                bool seen = stamp[v] == run;
                for (int j = 0; j < k && !seen; ++j) seen = mesh.indices[t + j] == v;  // repeated within the triangle
                added += seen ? 0u : 1u;
            }
            if (t > start && ((t - start) / 3 == kClusterMaxTriangles || vertices + added > kClusterMaxVertices)) {
                out.clusters.push_back(boundsOf(mesh, start, t - start));
                start = t;
                vertices = 0;
                ++run;
                added = 0;
                for (int k = 0; k < 3; ++k) {
                    bool seen = false;
                    for (int j = 0; j < k && !seen; ++j) seen = mesh.indices[t + j] == mesh.indices[t + k];
                    added += seen ? 0u : 1u;
                }
            }
            for (int k = 0; k < 3; ++k) stamp[mesh.indices[t + k]] = run;
            vertices += added;
        }
        out.clusters.push_back(boundsOf(mesh, start, end - start));
        ++run;
    }
    out.nodeFirst.push_back(static_cast<std::uint32_t>(out.clusters.size()));
    assert(out.builtFor(nodes.size()));
    return out;
}

}  // namespace dyncull
