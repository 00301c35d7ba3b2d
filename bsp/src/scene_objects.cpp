// Object store of the two-level scheme: shared models (split mesh + local BSP) and their
// instances, hot per-object data as structure-of-arrays, handles with generations.
// Paper: Two-level BSP for dynamic occlusion culling, section 3.1 (a transformation
// matrix per object, re-evaluated after every dynamic change).
#include "dyncull/bsp/scene_objects.hpp"

#include <cassert>
#include <string>

namespace dyncull {

namespace {

std::string handleText(ObjectHandle h) {
    return "handle (slot " + std::to_string(h.index) + ", generation " + std::to_string(h.generation) + ")";
}

}  // namespace

ModelId SceneObjects::addModel(LocalBsp bsp) {
    assert(!bsp.nodes.empty() && "a LocalBsp always has a root node");
    // Cache-loaded or hand-made trees arrive without volumes; every model has them after this.
    if (bsp.volumes.nodeCount() != bsp.nodes.size()) bsp.volumes = buildNodeVolumes(bsp.mesh, bsp.nodes);
    if (!bsp.clusters.builtFor(bsp.nodes.size())) bsp.clusters = clustersOf(bsp.mesh, bsp.nodes);
    models_.push_back(std::make_unique<LocalBsp>(std::move(bsp)));
    modelAlive_.push_back(1);
    return static_cast<ModelId>(models_.size() - 1);
}

Status SceneObjects::removeModel(ModelId id) {
    if (!modelAlive(id)) return Error{"removeModel: unknown or removed model " + std::to_string(id)};
    std::uint32_t users = 0;
    for (std::uint32_t i = 0; i < slotCount(); ++i) users += alive_[i] && model_[i] == id;
    if (users > 0)
        return Error{"removeModel: model " + std::to_string(id) + " is used by " + std::to_string(users) +
                     " objects; remove them or give them another model first"};
    // An empty single-leaf BSP keeps model(id) valid for code that walks every id.
    LocalBsp empty;
    empty.mesh.name = models_[id]->mesh.name;
    empty.nodes.emplace_back();
    empty.volumes = buildNodeVolumes(empty.mesh, empty.nodes);
    empty.clusters = clustersOf(empty.mesh, empty.nodes);
    *models_[id] = std::move(empty);
    modelAlive_[id] = 0;
    return {};
}

// Validates the transform and computes matrix + world box; shared by add and setTransform
// so both reject exactly the same inputs and never leave half-updated state.
static Status placement(const LocalBsp& model, const Transform& t, glm::mat4& matrix, Aabb& box) {
    if (Status s = validateTransform(t); !s) return s;
    const Aabb& local = model.root().box;
    if (local.empty() || !local.finite()) return Error{"model root box is empty or not finite"};
    matrix = t.matrix();
    box = transformAabb(matrix, local);
    if (!box.finite()) return Error{"transform: world box overflows float range"};
    return {};
}

Expected<ObjectHandle> SceneObjects::addObject(ModelId model, const Transform& transform, bool isStatic) {
    if (model >= models_.size())
        return Error{"addObject: unknown model id " + std::to_string(model) + " (" +
                     std::to_string(models_.size()) + " models)"};
    if (!modelAlive_[model]) return Error{"addObject: model " + std::to_string(model) + " was removed"};
    glm::mat4 m;
    Aabb box;
    if (Status s = placement(*models_[model], transform, m, box); !s)
        return Error{"addObject: " + s.message()};

    std::uint32_t i;
    if (!freeSlots_.empty()) {
        i = freeSlots_.back();
        freeSlots_.pop_back();
    } else {
        i = slotCount();
        model_.push_back(0);
        matrix_.emplace_back(1.0f);
        transform_.emplace_back();
        worldBox_.emplace_back();
        generation_.push_back(0);
        placedAt_.push_back(0);
        alive_.push_back(0);
        static_.push_back(0);
        role_.push_back(OcclusionRole::Both);
        movedFlag_.push_back(0);
    }
    model_[i] = model;
    matrix_[i] = m;
    transform_[i] = transform;
    worldBox_[i] = box;
    placedAt_[i] = ++placements_;
    alive_[i] = 1;
    static_[i] = isStatic ? 1 : 0;
    added_.push_back(i);
    ++live_;
    return ObjectHandle{i, generation_[i]};
}

bool SceneObjects::alive(ObjectHandle h) const {
    return h.index < slotCount() && alive_[h.index] != 0 && generation_[h.index] == h.generation;
}

Status SceneObjects::removeObject(ObjectHandle h) {
    if (!alive(h)) return Error{"removeObject: stale or invalid " + handleText(h)};
    const std::uint32_t i = h.index;
    if (role_[i] != OcclusionRole::Both) {
        role_[i] = OcclusionRole::Both;  // the slot's next object starts as Both
        std::erase(roleSlots_, i);
    }
    alive_[i] = 0;
    ++generation_[i];  // every handle to the old object is stale from now on
    freeSlots_.push_back(i);
    removed_.push_back(i);
    --live_;
    return {};
}

Status SceneObjects::setRole(ObjectHandle h, OcclusionRole role) {
    if (!alive(h)) return Error{"setRole: stale or invalid " + handleText(h)};
    const std::uint32_t i = h.index;
    if (role_[i] == OcclusionRole::Both && role != OcclusionRole::Both) roleSlots_.push_back(i);
    if (role_[i] != OcclusionRole::Both && role == OcclusionRole::Both) std::erase(roleSlots_, i);
    role_[i] = role;
    return {};
}

Status SceneObjects::setTransform(ObjectHandle h, const Transform& transform) {
    if (!alive(h)) return Error{"setTransform: stale or invalid " + handleText(h)};
    const std::uint32_t i = h.index;
    if (static_[i])
        return Error{"setTransform: " + handleText(h) + " was added as static and never moves; remove it and add it again to move it"};
    glm::mat4 m;
    Aabb box;
    if (Status s = placement(*models_[model_[i]], transform, m, box); !s)
        return Error{"setTransform: " + s.message()};
    matrix_[i] = m;
    transform_[i] = transform;
    worldBox_[i] = box;
    placedAt_[i] = ++placements_;
    if (!movedFlag_[i]) {
        movedFlag_[i] = 1;
        moved_.push_back(i);
    }
    return {};
}

Expected<ObjectHandle> SceneObjects::setModel(ObjectHandle h, ModelId model) {
    if (!alive(h)) return Error{"setModel: stale or invalid " + handleText(h)};
    if (!modelAlive(model)) return Error{"setModel: unknown or removed model " + std::to_string(model)};
    glm::mat4 m;
    Aabb box;
    if (Status s = placement(*models_[model], transform_[h.index], m, box); !s) return Error{"setModel: " + s.message()};
    // Remove and add: the slot is reused at once, under the next generation.
    const Transform transform = transform_[h.index];
    const bool isStatic = static_[h.index] != 0;
    const OcclusionRole role = role_[h.index];
    if (Status s = removeObject(h); !s) return s.error();
    auto added = addObject(model, transform, isStatic);
    if (added && role != OcclusionRole::Both) {
        Status s = setRole(*added, role);
        assert(s);
        (void)s;
    }
    return added;
}

void SceneObjects::clearMoved() {
    for (std::uint32_t i : moved_) movedFlag_[i] = 0;
    moved_.clear();
}

}  // namespace dyncull
