#include "dyncull/objects/convex_mesh.hpp"

#include <cassert>

namespace dyncull {

double meshSurfaceArea(std::span<const glm::vec3> v, std::span<const std::uint8_t> idx) {
    assert(idx.size() % 3 == 0);
    double area = 0.0;
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
        const glm::dvec3 a(v[idx[t]]), b(v[idx[t + 1]]), c(v[idx[t + 2]]);
        area += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    return area;
}

double meshVolume(std::span<const glm::vec3> v, std::span<const std::uint8_t> idx) {
    assert(idx.size() % 3 == 0);
    if (v.empty()) return 0.0;
    // Tetrahedra from a vertex of the mesh (not the origin) keep the sum well conditioned
    // for meshes far from the origin.
    const glm::dvec3 o(v[0]);
    double six = 0.0;
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
        const glm::dvec3 a = glm::dvec3(v[idx[t]]) - o, b = glm::dvec3(v[idx[t + 1]]) - o,
                         c = glm::dvec3(v[idx[t + 2]]) - o;
        six += glm::dot(a, glm::cross(b, c));
    }
    return six / 6.0;
}

}  // namespace dyncull
