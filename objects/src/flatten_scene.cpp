// A scene's instances merged into one mesh in world space: the triangle soup a static
// model is subdivided from (Scene subdivision for occlusion culling, section 2.1: the
// subdivision starts from the whole polygonal model, whatever its object structure).
#include <glm/gtc/matrix_inverse.hpp>

#include "dyncull/objects/scene.hpp"

namespace dyncull {

Mesh flattenScene(const Scene& scene, const std::string& name) {
    Mesh out;
    out.name = name;
    std::size_t vertices = 0, indices = 0;
    for (const Instance& inst : scene.instances) {
        vertices += scene.meshes[inst.mesh].positions.size();
        indices += scene.meshes[inst.mesh].indices.size();
    }
    out.positions.reserve(vertices);
    out.normals.reserve(vertices);
    out.indices.reserve(indices);
    for (const Instance& inst : scene.instances) {
        const Mesh& m = scene.meshes[inst.mesh];
        const glm::mat4& t = inst.transform;
        const glm::mat3 normalMatrix = glm::inverseTranspose(glm::mat3(t));
        // A mirroring transform turns counter-clockwise faces clockwise: swap two corners.
        const bool mirror = glm::determinant(glm::mat3(t)) < 0.0f;
        const auto base = static_cast<std::uint32_t>(out.positions.size());
        Mesh withNormals;
        const Mesh* src = &m;
        if (m.normals.size() != m.positions.size()) {
            withNormals = m;
            computeNormals(withNormals);
            src = &withNormals;
        }
        for (std::size_t v = 0; v < src->positions.size(); ++v) {
            out.positions.push_back(glm::vec3(t * glm::vec4(src->positions[v], 1.0f)));
            const glm::vec3 n = normalMatrix * src->normals[v];
            const float len = glm::length(n);
            // Degenerate (zero) normals stay as they are rather than becoming NaN.
            out.normals.push_back(len > 0.0f ? n / len : src->normals[v]);
        }
        for (std::size_t i = 0; i < src->indices.size(); i += 3) {
            out.indices.push_back(base + src->indices[i]);
            out.indices.push_back(base + src->indices[i + (mirror ? 2 : 1)]);
            out.indices.push_back(base + src->indices[i + (mirror ? 1 : 2)]);
        }
    }
    return out;
}

}  // namespace dyncull
