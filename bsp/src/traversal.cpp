// Front-to-back traversal of the two-level hierarchy: scene nodes give near child, their
// objects sorted by box-centre distance, far child; local BSP nodes give near then far
// child, "near" decided with the eye moved into the object's space.
// Paper: Two-level BSP for dynamic occlusion culling, section 3.3 (traversing the
// structures) and Algorithm 4 (ProcessVisibleNode: objects inserted before child 2).
#include "dyncull/bsp/traversal.hpp"

#include <algorithm>

namespace dyncull {

Aabb TwoLevelTree::worldBox(NodeRef ref) const {
    if (ref.isSceneNode()) return scene_->nodes()[ref.node].box;
    if (ref.node == 0) return objects_->worldBox(ref.object);  // same transformAabb, cached
    const LocalBsp& model = objects_->model(objects_->modelOf(ref.object));
    return transformAabb(objects_->matrix(ref.object), model.nodes[ref.node].box);
}

bool TwoLevelTree::isDrawable(NodeRef ref) const {
    if (ref.isSceneNode()) return false;
    return objects_->model(objects_->modelOf(ref.object)).nodes[ref.node].isLeaf();
}

void TwoLevelTree::expand(NodeRef ref, const glm::vec3& eye, std::vector<NodeRef>& out) const {
    if (ref.isSceneNode()) {
        const auto& nodes = scene_->nodes();
        const LooseBspNode& node = nodes[ref.node];
        // Near child: the side of the split plane the eye is on (on the plane: children[0]).
        const int nearSide = (!node.isLeaf() && eye[node.axis] > node.split) ? 1 : 0;
        auto pushChild = [&](int side) {
            if (node.isLeaf()) return;
            const std::uint32_t c = node.children[side];
            if (nodes[c].subtreeObjects > 0) out.push_back({kInvalidIndex, c});
        };
        pushChild(nearSide);
        const std::size_t first = out.size();
        for (std::uint32_t o = node.firstObject; o != kInvalidIndex; o = scene_->nextObject(o)) out.push_back({o, 0});
        // Squared distance orders the same as distance; slot index breaks ties reproducibly.
        auto dist2 = [&](const NodeRef& r) {
            const glm::vec3 d = objects_->worldBox(r.object).center() - eye;
            return glm::dot(d, d);
        };
        std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(), [&](const NodeRef& a, const NodeRef& b) {
            const float da = dist2(a), db = dist2(b);
            return da != db ? da < db : a.object < b.object;
        });
        pushChild(1 - nearSide);
        return;
    }
    const LocalBsp& model = objects_->model(objects_->modelOf(ref.object));
    const LocalBspNode& node = model.nodes[ref.node];
    if (node.isLeaf()) return;
    // Eye in object space: inverse of world = T * R * S * object, without a 4x4 inverse.
    const Transform& t = objects_->transform(ref.object);
    const glm::vec3 local = (glm::conjugate(t.rotation) * (eye - t.translation)) / t.scale;
    const int nearSide = local[node.axis] > node.split ? 1 : 0;
    for (int side : {nearSide, 1 - nearSide}) {
        const std::uint32_t c = node.children[side];
        if (model.nodes[c].indexCount > 0) out.push_back({ref.object, c});
    }
}

FrontToBackIterator::FrontToBackIterator(const TwoLevelTree& tree, const glm::vec3& eye) : tree_(&tree), eye_(eye) {
    const auto& nodes = tree.scene().nodes();
    if (!nodes.empty() && nodes[tree.scene().root()].subtreeObjects > 0) stack_.push_back(tree.root());
}

bool FrontToBackIterator::next(NodeRef& out) {
    if (stack_.empty()) return false;
    current_ = stack_.back();
    stack_.pop_back();
    out = current_;
    return true;
}

void FrontToBackIterator::descend() {
    scratch_.clear();
    tree_->expand(current_, eye_, scratch_);
    // Stack: push in reverse so the nearest child is popped first.
    stack_.insert(stack_.end(), scratch_.rbegin(), scratch_.rend());
}

}  // namespace dyncull
