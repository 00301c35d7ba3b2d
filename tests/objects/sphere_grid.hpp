// Triangles of a latitude-longitude grid, shared by the tests that build sphere-like meshes.
#pragma once

#include <cstdint>

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

}  // namespace dyncull::test
