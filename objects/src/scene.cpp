#include "dyncull/objects/scene.hpp"

namespace dyncull {

std::size_t Scene::instancedTriangleCount() const {
    std::size_t n = 0;
    for (const Instance& inst : instances) n += meshes[inst.mesh].triangleCount();
    return n;
}

std::size_t Scene::uniqueTriangleCount() const {
    std::size_t n = 0;
    for (const Mesh& m : meshes) n += m.triangleCount();
    return n;
}

Aabb Scene::worldBounds() const {
    std::vector<Aabb> local(meshes.size());
    for (std::size_t i = 0; i < meshes.size(); ++i) local[i] = meshes[i].bounds();
    Aabb b;
    for (const Instance& inst : instances) b.extend(transformAabb(inst.transform, local[inst.mesh]));
    return b;
}

}  // namespace dyncull
