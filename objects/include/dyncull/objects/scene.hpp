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
    /// Where the scene sits in the file's world space, in the file's units (glTF: usually
    /// metres), in double precision: every instance transform maps object space to world
    /// space minus `origin`, i.e. the full placement is translate(origin) * transform.
    /// Loaders set it for scenes far from the file's origin (a model at 1e7 would lose
    /// whole units in float transforms) and leave it 0 otherwise. Everything below
    /// (worldBounds, flattenScene, rendering) works relative to it; a caller combining
    /// scenes or placing the model absolutely adds it back in double.
    glm::dvec3 origin{0.0};

    std::size_t instancedTriangleCount() const;
    std::size_t uniqueTriangleCount() const;
    Aabb worldBounds() const;  ///< union of every instance's transformed mesh bounds (relative to `origin`)
};

/// Every instance of `scene` transformed into world space (relative to scene.origin) and
/// merged into one mesh named `name` (a triangle soup for subdividing a static model):
/// positions by the instance
/// matrix, normals by its inverse transpose (renormalised; computed first for meshes
/// without), winding flipped under mirroring transforms. The caller owns the result; its
/// size is the instanced size (shared meshes are copied once per instance). In
/// objects/src/flatten_scene.cpp.
Mesh flattenScene(const Scene& scene, const std::string& name);

}  // namespace dyncull
