// Indexed triangle mesh in object space. Owned by value; a Scene holds meshes and
// instances refer to them by index, so one mesh is uploaded once and shared.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"

namespace dyncull {

struct Mesh {
    std::string name;
    std::vector<glm::vec3> positions;  ///< object space, units of the source file
    std::vector<glm::vec3> normals;    ///< unit length, one per position (may be empty until computeNormals)
    std::vector<std::uint32_t> indices;  ///< 3 per triangle, counter-clockwise front faces

    std::size_t triangleCount() const { return indices.size() / 3; }
    std::size_t vertexCount() const { return positions.size(); }
    Aabb bounds() const;
};

/// Area-weighted vertex normals; degenerate (zero-area) triangles contribute nothing and
/// a vertex with no usable triangle gets +Z so the shader never sees NaN.
void computeNormals(Mesh& mesh);

/// Sum of triangle areas (object-space units squared), in double for conservation tests.
double surfaceArea(const Mesh& mesh);

/// Checks the invariants every loader guarantees: indices in range, count a multiple of 3,
/// finite positions, normals empty or one per position. Returns a message or "" if valid.
std::string validateMesh(const Mesh& mesh);

/// Checks that every normal is finite and not (near) zero: what a reader of a file that
/// stores normals must check, since such a normal shades black. Returns a message or "".
std::string validateNormals(const Mesh& mesh);

}  // namespace dyncull
