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

}  // namespace dyncull
