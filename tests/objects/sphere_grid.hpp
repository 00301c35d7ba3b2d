// Triangles of a latitude-longitude grid, shared by the tests that build sphere-like meshes.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

#include "dyncull/objects/mesh.hpp"

namespace dyncull::test {

/// Appends the triangles over a grid of (stacks + 1) rows of `slices` positions each, row j
/// from pole to pole, wrapping around each row; the pole rows get one fan of triangles.
inline void appendSphereGridTriangles(Mesh& m, int slices, int stacks) {
    for (int j = 0; j < stacks; ++j)
        for (int i = 0; i < slices; ++i) {
            const auto a = std::uint32_t(j * slices + i), b = std::uint32_t(j * slices + (i + 1) % slices);
            const auto c = a + std::uint32_t(slices), d = b + std::uint32_t(slices);
            if (j > 0) m.indices.insert(m.indices.end(), {a, b, c});
            if (j + 1 < stacks) m.indices.insert(m.indices.end(), {b, d, c});
        }
}

/// A UV sphere of `slices` x (stacks + 1) positions (poles included once per slice) and
/// appendSphereGridTriangles' triangles; no normals.
inline Mesh sphereGridMesh(int slices, int stacks, float radius = 1.0f, glm::vec3 centre = glm::vec3(0.0f)) {
    Mesh m;
    m.name = "sphere";
    for (int j = 0; j <= stacks; ++j) {
        const float phi = std::numbers::pi_v<float> * float(j) / float(stacks);
        for (int i = 0; i < slices; ++i) {
            const float theta = 2.0f * std::numbers::pi_v<float> * float(i) / float(slices);
            m.positions.push_back(centre + radius * glm::vec3(std::sin(phi) * std::cos(theta), std::cos(phi),
                                                              std::sin(phi) * std::sin(theta)));
        }
    }
    appendSphereGridTriangles(m, slices, stacks);
    return m;
}

}  // namespace dyncull::test
