// Test models for streaming: many closed surfaces with shared vertices, like a scan.
#pragma once

#include <cmath>

#include "dyncull/objects/mesh.hpp"

namespace dyncull::test {

/// `n` x `n` x 2 closed UV spheres of `rings` x `segments` quads (as triangles), with
/// shared vertices: a scanned-like surface in many clumps.
inline Mesh sphereField(int n, int rings, int segments) {
    Mesh m;
    m.name = "spheres";
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int k = 0; k < 2; ++k) {
                const glm::vec3 c(3.0f * i, 3.0f * k, 3.0f * j);
                const auto base = static_cast<std::uint32_t>(m.positions.size());
                for (int r = 0; r <= rings; ++r)
                    for (int s = 0; s < segments; ++s) {
                        const float th = 3.14159265f * r / rings, ph = 6.2831853f * s / segments;
                        m.positions.push_back(c + glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)));
                    }
                for (int r = 0; r < rings; ++r)
                    for (int s = 0; s < segments; ++s) {
                        const std::uint32_t a = base + r * segments + s, b = base + r * segments + (s + 1) % segments;
                        const std::uint32_t c2 = a + segments, d = b + segments;
                        m.indices.insert(m.indices.end(), {a, c2, b, b, c2, d});
                    }
            }
    return m;
}

}  // namespace dyncull::test
