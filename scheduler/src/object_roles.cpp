// Objects with an occlusion role (OcclusionRole, scene_objects.hpp), handled apart from the
// tree's traversal in every mode: occluder-only objects are drawn whole before it, untested,
// so their depth occludes from the first test on; occludee-only objects are tested after
// it, against the depth of everything else (the batched raster test, exact per pixel), and
// drawn whole without depth writes, so they occlude nothing. The depth an occludee is tested
// against is final for it (nothing that occludes is drawn afterwards), so the test is
// conservative in every mode.
#include <algorithm>

#include "cull_frame.hpp"

namespace dyncull {

void QueryScheduler::pushChildren(Frame& f, NodeRef ref) {
    scratch_.clear();
    f.tree.expand(ref, f.camera().position, scratch_);
    const SceneObjects& objs = f.objects;
    if (ref.isSceneNode() && !objs.roleSlots().empty())
        std::erase_if(scratch_, [&](const NodeRef& r) { return !r.isSceneNode() && objs.role(r.object) != OcclusionRole::Both; });
    // active_ is a stack whose back is processed next: push the farthest first.
    for (auto it = scratch_.rbegin(); it != scratch_.rend(); ++it) active_.push_back(*it);
}

namespace {
/// The live slots of `role` whose boxes meet the frustum, nearest first.
void inFrustum(const SceneObjects& objs, OcclusionRole role, const Frustum& frustum, const glm::vec3& eye,
               std::vector<std::pair<float, std::uint32_t>>& out, std::uint32_t& culled) {
    out.clear();
    for (std::uint32_t slot : objs.roleSlots()) {
        if (objs.role(slot) != role) continue;
        const Aabb& box = objs.worldBox(slot);
        if (frustum.outside(box)) {
            ++culled;
            continue;
        }
        const glm::vec3 d = box.center() - eye;
        out.push_back({glm::dot(d, d), slot});
    }
    std::sort(out.begin(), out.end());
}
}  // namespace

void QueryScheduler::drawOccluders(Frame& f) {
    const SceneObjects& objs = f.objects;
    if (objs.roleSlots().empty()) return;
    inFrustum(objs, OcclusionRole::OccluderOnly, f.frustum(), f.camera().position, roleOrder_, f.stats.frustumCulled);
    for (const auto& [distance, slot] : roleOrder_) {
        const NodeRef root{slot, 0};
        f.note(root, objs.worldBox(slot), NodeState::VisibleOccluder);
        drawNode(f, root, false);  // the whole object: its root's range is every part
    }
}

void QueryScheduler::drawOccludees(Frame& f) {
    const SceneObjects& objs = f.objects;
    if (objs.roleSlots().empty()) return;
    inFrustum(objs, OcclusionRole::OccludeeOnly, f.frustum(), f.camera().position, roleOrder_, f.stats.frustumCulled);
    candidates_.clear();
    for (const auto& [distance, slot] : roleOrder_) {
        const NodeRef root{slot, 0};
        const Aabb& box = objs.worldBox(slot);
        if (params_.mode == CullMode::Vfc) {
            f.note(root, box, NodeState::VisibleVfc);
            drawNode(f, root, false);
            continue;
        }
        const QueryVolume volume = testedVolume(f, root);
        DepthFootprint fp;
        if (!f.screen.volumeDepth(volume, fp) || box.contains(f.camera().position)) {
            ++f.stats.visibleNearOrInside;
            f.note(root, box, NodeState::VisibleNear);
            drawNode(f, root, false);
        } else if (fp.rect.empty()) {
            ++f.stats.frustumCulled;
            f.note(root, box, NodeState::FrustumCulled);
        } else {
            candidates_.push_back(root);
        }
    }
    if (candidates_.empty()) return;
    // One batch: occludees draw no depth, so none can hide another.
    rasterTest(f, candidates_);
    for (std::size_t i = 0; i < candidates_.size(); ++i) {
        const NodeRef root = candidates_[i];
        if (rasterAnswers_[i] == QueryResult::Occluded) {
            ++f.stats.queriesOccluded;
            f.note(root, objs.worldBox(root.object), NodeState::Occluded);
        } else {
            f.note(root, objs.worldBox(root.object), NodeState::VisibleQueried);
            drawNode(f, root, false);
        }
    }
}

}  // namespace dyncull
