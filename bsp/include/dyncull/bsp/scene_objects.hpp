// The objects of a dynamic scene: models (a split mesh and its local BSP, shared) and
// instances of them with transforms. Hot per-object data is structure-of-arrays;
// callers name objects by ObjectHandle (index + generation), never by pointer.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/bsp/local_bsp.hpp"
#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/error.hpp"
#include "dyncull/objects/transform.hpp"

namespace dyncull {

struct ObjectHandle {
    std::uint32_t index = kInvalidIndex;
    std::uint32_t generation = 0;
    bool valid() const { return index != kInvalidIndex; }
    friend bool operator==(const ObjectHandle&, const ObjectHandle&) = default;
};

using ModelId = std::uint32_t;

/// What an object does in occlusion culling. Both: it is tested, and its depth occludes
/// what lies behind it (the default). OccluderOnly: never tested; whenever its box meets the
/// frustum it is drawn whole, first (before any test of the frame), so its depth occludes
/// from the start: terrain, a building's shell, anything almost always seen.
/// OccludeeOnly: tested, but its depth occludes nothing: it is drawn whole, last, after
/// every other object, if a test against their final depth shows it, and without depth
/// writes (the part renderer; a game's callback must draw it so too): glass, particles,
/// anything blended.
enum class OcclusionRole : std::uint8_t { Both, OccluderOnly, OccludeeOnly };

/// Owns models and objects. Slots of removed objects go on a free list and their
/// generation is bumped so stale handles are detected.
class SceneObjects {
public:
    /// Takes ownership of a built local BSP; returns its id for addObject. Computes the
    /// nodes' query volumes when the BSP has none (e.g. loaded from a cache).
    ModelId addModel(LocalBsp bsp);
    const LocalBsp& model(ModelId id) const { return *models_[id]; }
    /// Ids ever given out, removed ones included (a removed model is an empty BSP).
    std::size_t modelCount() const { return models_.size(); }
    bool modelAlive(ModelId id) const { return id < models_.size() && modelAlive_[id] != 0; }
    /// Frees a model no live object uses; its id is never given out again. Errors: unknown
    /// or removed model, or objects still using it (remove them or give them another model).
    Status removeModel(ModelId id);
    /// Gives an object another model, keeping its transform and static flag. The object
    /// comes back under a new handle (the old one is stale from now on), because everything
    /// kept per object downstream (visibility histories, pending queries) names the old
    /// model's nodes. Errors: stale handle, unknown or removed model, a model whose box the
    /// object's transform cannot place.
    Expected<ObjectHandle> setModel(ObjectHandle h, ModelId model);

    /// Adds an instance. Errors on an unknown model or an invalid transform. A static object
    /// promises never to move: setTransform refuses it, and it costs nothing per frame (no
    /// relink, no motion check anywhere downstream).
    Expected<ObjectHandle> addObject(ModelId model, const Transform& transform, bool isStatic = false);
    Status removeObject(ObjectHandle h);
    /// Sets the object's OcclusionRole (Both when added; kept by setModel). Error: stale handle.
    Status setRole(ObjectHandle h, OcclusionRole role);
    /// Sets a new world transform; marks the object moved for this frame's relink. Errors:
    /// stale handle, invalid transform, or a static object.
    Status setTransform(ObjectHandle h, const Transform& transform);
    bool alive(ObjectHandle h) const;

    // --- SoA access by slot index (0 .. slotCount()-1); dead slots have alive(i) == false.
    std::uint32_t slotCount() const { return static_cast<std::uint32_t>(model_.size()); }
    std::uint32_t objectCount() const { return live_; }
    bool alive(std::uint32_t i) const { return alive_[i] != 0; }
    ModelId modelOf(std::uint32_t i) const { return model_[i]; }
    const glm::mat4& matrix(std::uint32_t i) const { return matrix_[i]; }  ///< object -> world
    const Transform& transform(std::uint32_t i) const { return transform_[i]; }
    const Aabb& worldBox(std::uint32_t i) const { return worldBox_[i]; }  ///< world space
    bool isStatic(std::uint32_t i) const { return static_[i] != 0; }
    OcclusionRole role(std::uint32_t i) const { return role_[i]; }
    /// The live slots whose role is not Both, in no particular order: the scheduler handles
    /// them apart from the tree's traversal without scanning every object.
    const std::vector<std::uint32_t>& roleSlots() const { return roleSlots_; }
    /// When the slot was last placed (addObject or setTransform), as a value of one counter
    /// shared by every slot: a consumer that keeps it sees a move, or the slot's reuse by a
    /// new object, as a different value, without comparing matrices.
    std::uint64_t placedAt(std::uint32_t i) const { return placedAt_[i]; }
    ObjectHandle handle(std::uint32_t i) const { return {i, generation_[i]}; }

    /// Slots whose transform changed since the last clearMoved() (unique, ascending not guaranteed).
    const std::vector<std::uint32_t>& moved() const { return moved_; }
    void clearMoved();
    /// Slots added or removed since the last clearStructural(); the loose BSP consumes these.
    const std::vector<std::uint32_t>& added() const { return added_; }
    const std::vector<std::uint32_t>& removed() const { return removed_; }
    void clearStructural() { added_.clear(); removed_.clear(); }

private:
    std::vector<std::unique_ptr<LocalBsp>> models_;  // stable addresses: renderer caches per model
    std::vector<std::uint8_t> modelAlive_;
    std::vector<ModelId> model_;
    std::vector<glm::mat4> matrix_;
    std::vector<Transform> transform_;
    std::vector<Aabb> worldBox_;
    std::vector<std::uint32_t> generation_;
    std::vector<std::uint64_t> placedAt_;
    std::uint64_t placements_ = 0;
    std::vector<std::uint8_t> alive_, static_, movedFlag_;
    std::vector<OcclusionRole> role_;
    std::vector<std::uint32_t> freeSlots_, moved_, added_, removed_, roleSlots_;
    std::uint32_t live_ = 0;
};

}  // namespace dyncull
