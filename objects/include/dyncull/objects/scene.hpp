// A loaded scene: meshes plus instances placing them in the world.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/mesh.hpp"

namespace dyncull {

/// One placement of a mesh. `mesh` indexes Scene::meshes; `transform` maps object to world space.
struct Instance {
    std::uint32_t mesh = 0;
    glm::mat4 transform{1.0f};
    std::string name;
};

/// Owns its meshes by value. A mesh referenced by several instances is stored once.
struct Scene {
    std::vector<Mesh> meshes;
    std::vector<Instance> instances;

    std::size_t instancedTriangleCount() const;
    std::size_t uniqueTriangleCount() const;
    Aabb worldBounds() const;  ///< union of every instance's transformed mesh bounds
};

/// Every instance of `scene` transformed into world space and merged into one mesh named
/// `name` (a triangle soup for subdividing a static model): positions by the instance
/// matrix, normals by its inverse transpose (renormalised; computed first for meshes
/// without), winding flipped under mirroring transforms. The caller owns the result; its
/// size is the instanced size (shared meshes are copied once per instance). In
/// objects/src/flatten_scene.cpp.
Mesh flattenScene(const Scene& scene, const std::string& name);

}  // namespace dyncull
