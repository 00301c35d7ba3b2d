// Visibility history. Paper: Two-level BSP for dynamic occlusion culling, section 3.4,
// Algorithm 3 (ExamineRecentQueryResults) and Figure 3.
#include "dyncull/scheduler/visibility_history.hpp"

#include <algorithm>
#include <bit>
#include <cassert>

namespace dyncull {

namespace {
std::size_t clusterWordsOf(const LocalBsp& model) {
    return model.clusters.builtFor(model.nodes.size()) ? (model.clusters.clusters.size() + 63) / 64 : 0;
}
}  // namespace

void VisibilityHistory::ensureBlock(std::uint32_t slot, const SceneObjects& objects) {
    if (slot >= objectBase_.size()) {
        objectBase_.resize(slot + 1, kInvalidIndex);
        objectClusterBase_.resize(slot + 1, 0);
        objectGen_.resize(slot + 1, 0);
        objectModel_.resize(slot + 1, kInvalidIndex);
    }
    const std::uint32_t gen = objects.handle(slot).generation;
    const ModelId model = objects.modelOf(slot);
    const LocalBsp& m = objects.model(model);
    if (objectBase_[slot] == kInvalidIndex || objectModel_[slot] != model) {
        // New block; a slot whose model changed leaks its old block until clear(), which
        // only happens when objects are re-created with another model (rare).
        objectBase_[slot] = static_cast<std::uint32_t>(objectNodes_.size());
        objectNodes_.resize(objectNodes_.size() + m.nodes.size());
        objectClusterBase_[slot] = static_cast<std::uint32_t>(clusterWords_.size());
        clusterWords_.resize(clusterWords_.size() + clusterWordsOf(m), 0);
        objectModel_[slot] = model;
        objectGen_[slot] = gen;
    } else if (objectGen_[slot] != gen) {
        // Slot reused by a new object of the same model: its history means nothing now.
        std::fill_n(objectNodes_.begin() + objectBase_[slot], m.nodes.size(), NodeHistory{});
        std::fill_n(clusterWords_.begin() + objectClusterBase_[slot], clusterWordsOf(m), 0);
        objectGen_[slot] = gen;
    }
}

NodeHistory& VisibilityHistory::at(NodeRef ref, const SceneObjects& objects) {
    if (ref.isSceneNode()) {
        if (ref.node >= scene_.size()) scene_.resize(ref.node + 1);
        return scene_[ref.node];
    }
    ensureBlock(ref.object, objects);
    assert(ref.node < objects.model(objects.modelOf(ref.object)).nodes.size() && "a node of the object's current model");
    return objectNodes_[objectBase_[ref.object] + ref.node];
}

std::span<std::uint64_t> VisibilityHistory::clusterBits(std::uint32_t object, const SceneObjects& objects) {
    ensureBlock(object, objects);
    return {clusterWords_.data() + objectClusterBase_[object], clusterWordsOf(objects.model(objects.modelOf(object)))};
}

const NodeHistory* VisibilityHistory::find(NodeRef ref, const SceneObjects& objects) const {
    if (ref.isSceneNode()) return ref.node < scene_.size() ? &scene_[ref.node] : nullptr;
    const std::uint32_t slot = ref.object;
    if (slot >= objectBase_.size() || objectBase_[slot] == kInvalidIndex || objectModel_[slot] != objects.modelOf(slot) ||
        objectGen_[slot] != objects.handle(slot).generation || ref.node >= objects.model(objects.modelOf(slot)).nodes.size())
        return nullptr;
    return &objectNodes_[objectBase_[slot] + ref.node];
}

void VisibilityHistory::clear() {
    scene_.clear();
    objectNodes_.clear();
    clusterWords_.clear();
    objectBase_.clear();
    objectClusterBase_.clear();
    objectGen_.clear();
    objectModel_.clear();
}

void VisibilityHistory::recordAnswer(NodeHistory& h, bool visible, std::uint32_t frame) const {
    h.bits = static_cast<std::uint8_t>((h.bits << 1) | (visible ? 1u : 0u));
    h.answers = static_cast<std::uint8_t>(std::min<int>(h.answers + 1, 8));
    h.lastQueryFrame = frame;
    h.lastVisible = visible;
    if (visible) h.lastVisibleFrame = frame;
}

bool VisibilityHistory::canSkipQuery(NodeRef ref, const NodeHistory& h, std::uint32_t frame, const HistoryParams& p) const {
    // Only a node reached and visible in the previous frame may skip ("invisible last
    // time -> query"); a node not reached last frame (parent culled) was not visible.
    if (!h.lastVisible || h.lastTouchedFrame + 1 != frame) return false;
    return frame - h.lastQueryFrame <= postponement(ref, h, p);
}

std::uint32_t VisibilityHistory::postponement(NodeRef ref, const NodeHistory& h, const HistoryParams& p) const {
    const std::uint32_t visibleAnswers = static_cast<std::uint32_t>(std::popcount(h.bits));
    if (visibleAnswers < p.minVisibleToSkip) return 0;
    std::uint32_t skip = std::min(p.maxSkipFrames, p.skipFramesPerVisible * visibleAnswers);
    if (p.jitter && skip >= 2) {
        const std::uint32_t hash = hashNode(ref) ^ 0x9e3779b9u;
        skip -= (hash >> 7) % (skip / 2 + 1);
    }
    return skip;
}

std::size_t VisibilityHistory::memoryBytes() const {
    return (scene_.capacity() + objectNodes_.capacity()) * sizeof(NodeHistory) + clusterWords_.capacity() * sizeof(std::uint64_t) +
           (objectBase_.capacity() + objectClusterBase_.capacity() + objectGen_.capacity() + objectModel_.capacity()) *
               sizeof(std::uint32_t);
}

}  // namespace dyncull
