// Small meshes built in code so engine tests never depend on loaders or data files.
#pragma once

#include <cmath>

#include "dyncull/objects/mesh.hpp"

namespace dyncull::test {

/// Axis-aligned quad in the z = 0 plane covering [-h, h]^2, facing +Z.
inline Mesh quadMesh(float h = 1.0f) {
    Mesh m;
    m.name = "quad";
    m.positions = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
    m.normals.assign(4, {0, 0, 1});
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
}

/// Cube [-h, h]^3 with per-face normals (24 vertices, 12 triangles).
inline Mesh cubeMesh(float h = 1.0f) {
    Mesh m;
    m.name = "cube";
    const glm::vec3 n[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const glm::vec3& normal : n) {
        // Two tangents spanning the face, ordered so (u x v) = normal (counter-clockwise).
        const glm::vec3 helper = std::abs(normal.y) > 0.5f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
        const glm::vec3 u = glm::cross(helper, normal);
        const glm::vec3 v = glm::cross(normal, u);
        const auto base = static_cast<std::uint32_t>(m.positions.size());
        for (int k = 0; k < 4; ++k) {
            const float su = (k == 1 || k == 2) ? 1.0f : -1.0f;
            const float sv = (k >= 2) ? 1.0f : -1.0f;
            m.positions.push_back(h * (normal + su * u + sv * v));
            m.normals.push_back(normal);
        }
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    return m;
}

/// UV sphere of radius r (rings x segments quads), normals = directions.
inline Mesh sphereMesh(float r = 1.0f, int rings = 12, int segments = 24) {
    Mesh m;
    m.name = "sphere";
    const float pi = 3.14159265f;
    for (int i = 0; i <= rings; ++i) {
        const float th = pi * static_cast<float>(i) / static_cast<float>(rings);
        for (int j = 0; j <= segments; ++j) {
            const float ph = 2.0f * pi * static_cast<float>(j) / static_cast<float>(segments);
            const glm::vec3 d(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
            m.positions.push_back(r * d);
            m.normals.push_back(d);
        }
    }
    const auto row = static_cast<std::uint32_t>(segments + 1);
    for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(rings); ++i)
        for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(segments); ++j) {
            const std::uint32_t a = i * row + j, b = a + row;
            m.indices.insert(m.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
        }
    return m;
}

}  // namespace dyncull::test
