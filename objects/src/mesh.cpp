#include "dyncull/objects/mesh.hpp"

#include <cmath>
#include <string>

namespace dyncull {

Aabb Mesh::bounds() const {
    Aabb b;
    for (const glm::vec3& p : positions) b.extend(p);
    return b;
}

void computeNormals(Mesh& mesh) {
    mesh.normals.assign(mesh.positions.size(), glm::vec3(0.0f));
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
        // Unnormalised cross product = 2 * area * normal, so big triangles weigh more.
        const glm::vec3 n = glm::cross(mesh.positions[b] - mesh.positions[a],
                                       mesh.positions[c] - mesh.positions[a]);
        mesh.normals[a] += n;
        mesh.normals[b] += n;
        mesh.normals[c] += n;
    }
    for (glm::vec3& n : mesh.normals) {
        const float len = glm::length(n);
        // len == 0 for isolated vertices or those touching only degenerate triangles.
        n = (len > 0.0f && std::isfinite(len)) ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
    }
}

double surfaceArea(const Mesh& mesh) {
    double area = 0.0;
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const glm::dvec3 a(mesh.positions[mesh.indices[t]]);
        const glm::dvec3 b(mesh.positions[mesh.indices[t + 1]]);
        const glm::dvec3 c(mesh.positions[mesh.indices[t + 2]]);
        area += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    return area;
}

std::string validateMesh(const Mesh& mesh) {
    if (mesh.indices.size() % 3 != 0)
        return "index count " + std::to_string(mesh.indices.size()) + " is not a multiple of 3";
    for (std::size_t i = 0; i < mesh.indices.size(); ++i) {
        if (mesh.indices[i] >= mesh.positions.size())
            return "index " + std::to_string(mesh.indices[i]) + " at position " + std::to_string(i) +
                   " out of range (" + std::to_string(mesh.positions.size()) + " vertices)";
    }
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        const glm::vec3& p = mesh.positions[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            return "vertex " + std::to_string(i) + " has a non-finite coordinate";
    }
    if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
        return "normal count " + std::to_string(mesh.normals.size()) + " differs from vertex count " +
               std::to_string(mesh.positions.size());
    return {};
}

std::string validateNormals(const Mesh& mesh) {
    for (std::size_t i = 0; i < mesh.normals.size(); ++i) {
        const glm::vec3& n = mesh.normals[i];
        if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z))
            return "normal " + std::to_string(i) + " is not finite";
        // Writers store unit normals; one shorter than 1e-6 has no reliable direction left.
        if (!(glm::dot(n, n) >= 1e-12f)) return "normal " + std::to_string(i) + " has zero length";
    }
    return {};
}

}  // namespace dyncull
