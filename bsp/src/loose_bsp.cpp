// Global loose BSP over object world boxes with per-frame relinking, incremental refit of
// node boxes, root growth and time-budgeted lazy subtree rebuilds.
// Paper: Two-level BSP for dynamic occlusion culling, section 3.2 (scene partitioning:
// objects are not split but tied to the smallest node containing them; relinked up or down
// every frame without changing the subdivision; "lazy" local reconstruction).
#include "dyncull/bsp/loose_bsp.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace dyncull {

namespace {

constexpr std::uint8_t kFree = 1;       // node is on the free list
constexpr std::uint8_t kDirty = 2;      // node box must be refit this frame
constexpr std::uint8_t kCandidate = 4;  // node is in candidates_ for a lazy rebuild
constexpr double kCreditFrames = 64.0;  // rebuild budget saved for at most this many frames
constexpr std::uint32_t kDepthLimit = 250;  // depth is stored in 8 bits

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Root cell slack: 1% of the scene extent so objects touching the boundary don't grow the
// root at once, plus 1e-6 of the coordinate magnitude (~16 float ulps) so far-away scenes
// of zero extent still get a cell with some room; 1 world unit if there is no scale at all.
float marginFor(const Aabb& box) {
    const glm::vec3 e = box.extent();
    const float ext = std::max({e.x, e.y, e.z});
    const glm::vec3 a = glm::max(glm::abs(box.min), glm::abs(box.max));
    const float mag = std::max({a.x, a.y, a.z});
    const float m = 0.01f * ext + 1e-6f * mag;
    return m > 0.0f ? m : 1.0f;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Node storage

std::uint32_t LooseBsp::allocNode() {
    if (!freeNodes_.empty()) {
        const std::uint32_t n = freeNodes_.back();
        freeNodes_.pop_back();
        nodes_[n] = LooseBspNode{};
        return n;
    }
    nodes_.emplace_back();
    return static_cast<std::uint32_t>(nodes_.size() - 1);
}

// Frees every descendant of n (not n itself). Their objects must already be unlinked.
void LooseBsp::freeSubtreeBelow(std::uint32_t n) {
    walk_.clear();
    if (!nodes_[n].isLeaf()) {
        walk_.push_back(nodes_[n].children[0]);
        walk_.push_back(nodes_[n].children[1]);
    }
    while (!walk_.empty()) {
        const std::uint32_t x = walk_.back();
        walk_.pop_back();
        LooseBspNode& node = nodes_[x];
        if (!node.isLeaf()) {
            walk_.push_back(node.children[0]);
            walk_.push_back(node.children[1]);
        }
        node = LooseBspNode{};
        node.flags = kFree;  // also drops kCandidate: stale candidate entries are skipped
        freeNodes_.push_back(x);
    }
    nodes_[n].children[0] = nodes_[n].children[1] = kInvalidIndex;
}

void LooseBsp::ensureSlots(std::uint32_t slots) {
    if (node_.size() >= slots) return;
    node_.resize(slots, kInvalidIndex);
    next_.resize(slots, kInvalidIndex);
    prev_.resize(slots, kInvalidIndex);
}

// ---------------------------------------------------------------------------------------
// Intrusive object lists

void LooseBsp::link(std::uint32_t o, std::uint32_t n) {
    LooseBspNode& node = nodes_[n];
    next_[o] = node.firstObject;
    prev_[o] = kInvalidIndex;
    if (node.firstObject != kInvalidIndex) prev_[node.firstObject] = o;
    node.firstObject = o;
    ++node.objectCount;
    node_[o] = n;
}

void LooseBsp::unlink(std::uint32_t o) {
    LooseBspNode& node = nodes_[node_[o]];
    if (prev_[o] != kInvalidIndex) next_[prev_[o]] = next_[o];
    else node.firstObject = next_[o];
    if (next_[o] != kInvalidIndex) prev_[next_[o]] = prev_[o];
    --node.objectCount;
    node_[o] = next_[o] = prev_[o] = kInvalidIndex;
}

// subtreeObjects += delta on from, its parent, ... up to but excluding `to`
// (kInvalidIndex: up to and including the root).
void LooseBsp::addCounts(std::uint32_t from, std::uint32_t to, int delta) {
    for (std::uint32_t x = from; x != to; x = nodes_[x].parent) {
        nodes_[x].subtreeObjects = static_cast<std::uint32_t>(static_cast<int>(nodes_[x].subtreeObjects) + delta);
        noteCounts(x);
    }
}

// Smallest node below (or at) `from` whose cell contains box; ties between two children
// (a flat box lying exactly on the split plane) go to children[0].
std::uint32_t LooseBsp::descend(std::uint32_t from, const Aabb& box) const {
    std::uint32_t n = from;
    while (!nodes_[n].isLeaf()) {
        const LooseBspNode& node = nodes_[n];
        if (nodes_[node.children[0]].cell.contains(box)) n = node.children[0];
        else if (nodes_[node.children[1]].cell.contains(box)) n = node.children[1];
        else break;
    }
    return n;
}

// ---------------------------------------------------------------------------------------
// Build

// Builds the subtree of n (cell, parent and depth already set) over objects [begin, end),
// links them and returns the subtree box.
Aabb LooseBsp::buildNode(std::uint32_t n, const SceneObjects& objects, std::uint32_t* begin, std::uint32_t* end) {
    const auto count = static_cast<std::uint32_t>(end - begin);
    {
        LooseBspNode& node = nodes_[n];
        node.subtreeObjects = node.builtSubtreeObjects = count;
        node.objectCount = 0;
        node.firstObject = kInvalidIndex;
        node.children[0] = node.children[1] = kInvalidIndex;
    }
    const Aabb cell = nodes_[n].cell;
    const std::uint32_t depth = nodes_[n].depth;
    const std::uint32_t maxDepth = std::min(params_.maxDepth, kDepthLimit);

    int axis = -1;
    float split = 0.0f;
    if (count > params_.maxObjectsPerLeaf && depth < maxDepth) {
        // Axes by decreasing cell extent; per axis try the median box centre, then the middle
        // of the centres' range (separates two dense clusters where the median cuts one).
        int order[3] = {0, 1, 2};
        const glm::vec3 e = cell.extent();
        std::stable_sort(order, order + 3, [&](int a, int b) { return e[a] > e[b]; });
        for (int k = 0; k < 3 && axis < 0; ++k) {
            const int a = order[k];
            auto centre = [&](std::uint32_t o) { return objects.worldBox(o).center()[a]; };
            std::uint32_t* mid = begin + count / 2;
            std::nth_element(begin, mid, end, [&](std::uint32_t x, std::uint32_t y) { return centre(x) < centre(y); });
            float lo = centre(*begin), hi = lo;
            for (std::uint32_t* p = begin; p != end; ++p) {
                lo = std::min(lo, centre(*p));
                hi = std::max(hi, centre(*p));
            }
            const float tries[2] = {centre(*mid), lo + 0.5f * (hi - lo)};
            for (float s : tries) {
                s = std::clamp(s, cell.min[a], cell.max[a]);
                std::uint32_t left = 0, right = 0;
                for (std::uint32_t* p = begin; p != end; ++p) {
                    const Aabb& b = objects.worldBox(*p);
                    if (b.max[a] <= s) ++left;
                    else if (b.min[a] >= s) ++right;
                }
                if (left > 0 && right > 0) {  // progress: objects reach both children
                    axis = a;
                    split = s;
                    break;
                }
            }
        }
    }

    Aabb box;
    if (axis < 0) {  // leaf
        for (std::uint32_t* p = begin; p != end; ++p) {
            link(*p, n);
            box.extend(objects.worldBox(*p));
        }
        nodes_[n].box = box;
        return box;
    }

    // [left | straddling | right]; the same tests as descend() so build and relink agree.
    std::uint32_t* midBegin = std::partition(begin, end, [&](std::uint32_t o) { return objects.worldBox(o).max[axis] <= split; });
    std::uint32_t* midEnd = std::partition(midBegin, end, [&](std::uint32_t o) { return objects.worldBox(o).min[axis] < split; });
    const std::uint32_t c0 = allocNode();
    const std::uint32_t c1 = allocNode();
    for (int side = 0; side < 2; ++side) {
        LooseBspNode& child = nodes_[side == 0 ? c0 : c1];
        child.cell = cell;
        if (side == 0) child.cell.max[axis] = split;
        else child.cell.min[axis] = split;
        child.parent = n;
        child.depth = static_cast<std::uint8_t>(depth + 1);
    }
    {
        LooseBspNode& node = nodes_[n];
        node.children[0] = c0;
        node.children[1] = c1;
        node.axis = static_cast<std::uint8_t>(axis);
        node.split = split;
    }
    for (std::uint32_t* p = midBegin; p != midEnd; ++p) {
        link(*p, n);
        box.extend(objects.worldBox(*p));
    }
    box.extend(buildNode(c0, objects, begin, midBegin));
    box.extend(buildNode(c1, objects, midEnd, end));
    nodes_[n].box = box;
    return box;
}

void LooseBsp::build(SceneObjects& objects) {
    nodes_.clear();
    freeNodes_.clear();
    candidates_.clear();
    rebuildCreditMs_ = 0.0;
    node_.assign(objects.slotCount(), kInvalidIndex);
    next_.assign(objects.slotCount(), kInvalidIndex);
    prev_.assign(objects.slotCount(), kInvalidIndex);
    dirtyByDepth_.resize(std::min(params_.maxDepth, kDepthLimit) + 1);
    for (auto& bucket : dirtyByDepth_) bucket.clear();

    gather_.clear();
    Aabb all;
    for (std::uint32_t i = 0; i < objects.slotCount(); ++i) {
        if (!objects.alive(i)) continue;
        gather_.push_back(i);
        all.extend(objects.worldBox(i));
    }
    const std::uint32_t root = allocNode();
    if (!all.empty()) {
        buildMargin_ = marginFor(all);
        nodes_[root].cell = all.inflated(buildMargin_);
    }
    buildNode(root, objects, gather_.data(), gather_.data() + gather_.size());
    objects.clearMoved();
    objects.clearStructural();
}

// ---------------------------------------------------------------------------------------
// Per-frame update

// Enlarges the root cell to contain `box`, growing by at least the current largest extent
// (doubling) so an object drifting away causes O(log distance) growths. Every node whose
// cell lies on the old root boundary is extended with it, so children still partition
// their parent and no object's smallest containing node changes (all lay inside the old cell).
void LooseBsp::growRoot(const Aabb& box) {
    ++rootGrowths_;
    const Aabb old = nodes_[0].cell;
    if (old.empty()) {
        buildMargin_ = marginFor(box);
        nodes_[0].cell = box.inflated(buildMargin_);
        return;
    }
    const glm::vec3 e = old.extent();
    const float grow = std::max({e.x, e.y, e.z, buildMargin_});
    Aabb cell = old;
    for (int a = 0; a < 3; ++a) {
        if (box.min[a] < old.min[a]) cell.min[a] = std::min(old.min[a] - grow, box.min[a]);
        if (box.max[a] > old.max[a]) cell.max[a] = std::max(old.max[a] + grow, box.max[a]);
    }
    walk_.clear();
    walk_.push_back(0);
    while (!walk_.empty()) {
        LooseBspNode& node = nodes_[walk_.back()];
        walk_.pop_back();
        bool touches = false;
        for (int a = 0; a < 3; ++a) {
            if (node.cell.min[a] == old.min[a]) { node.cell.min[a] = cell.min[a]; touches = true; }
            if (node.cell.max[a] == old.max[a]) { node.cell.max[a] = cell.max[a]; touches = true; }
        }
        // A child off the old boundary has no descendant on it (cells nest).
        if (touches && !node.isLeaf()) {
            walk_.push_back(node.children[0]);
            walk_.push_back(node.children[1]);
        }
    }
}

void LooseBsp::markDirty(std::uint32_t n) {
    LooseBspNode& node = nodes_[n];
    if (node.flags & kDirty) return;
    node.flags |= kDirty;
    dirtyByDepth_[node.depth].push_back(n);
}

// Bottom-up by depth so each touched node and ancestor is refit once per frame; a node whose
// box did not change does not dirty its parent.
void LooseBsp::refitDirty(const SceneObjects& objects) {
    for (std::size_t d = dirtyByDepth_.size(); d-- > 0;) {
        auto& bucket = dirtyByDepth_[d];
        for (std::uint32_t n : bucket) {
            LooseBspNode& node = nodes_[n];
            node.flags &= static_cast<std::uint8_t>(~kDirty);
            Aabb box;
            for (std::uint32_t o = node.firstObject; o != kInvalidIndex; o = next_[o]) box.extend(objects.worldBox(o));
            if (!node.isLeaf()) {
                box.extend(nodes_[node.children[0]].box);
                box.extend(nodes_[node.children[1]].box);
            }
            if (box.min != node.box.min || box.max != node.box.max) {
                node.box = box;
                if (node.parent != kInvalidIndex) markDirty(node.parent);
            }
        }
        bucket.clear();
    }
}

void LooseBsp::insertObject(std::uint32_t o, const Aabb& box) {
    if (!nodes_[0].cell.contains(box)) growRoot(box);
    const std::uint32_t n = descend(0, box);
    link(o, n);
    addCounts(n, kInvalidIndex, +1);
    markDirty(n);
}

// Walk up from the object's node until the cell contains the box, then down; the
// subdivision itself is unchanged. Returns true when the object changed node.
bool LooseBsp::relink(std::uint32_t o, const Aabb& box) {
    if (!nodes_[0].cell.contains(box)) growRoot(box);
    const std::uint32_t cur = node_[o];
    std::uint32_t up = cur;
    while (!nodes_[up].cell.contains(box)) up = nodes_[up].parent;  // the root contains it
    const std::uint32_t target = descend(up, box);
    markDirty(cur);
    if (target == cur) return false;
    unlink(o);
    addCounts(cur, up, -1);
    link(o, target);
    addCounts(target, up, +1);
    noteCounts(up);  // its children's balance changed
    markDirty(target);
    return true;
}

LooseBspFrameStats LooseBsp::update(SceneObjects& objects) {
    const auto t0 = Clock::now();
    LooseBspFrameStats stats;
    ensureSlots(objects.slotCount());
    if (nodes_.empty()) allocNode();  // update() without build(): start from an empty root
    if (dirtyByDepth_.empty()) dirtyByDepth_.resize(std::min(params_.maxDepth, kDepthLimit) + 1);

    const std::uint32_t growthsBefore = rootGrowths_;
    for (std::uint32_t i : objects.removed()) {
        if (node_[i] == kInvalidIndex) continue;  // added and removed in the same frame
        const std::uint32_t n = node_[i];
        unlink(i);
        addCounts(n, kInvalidIndex, -1);
        markDirty(n);
    }
    for (std::uint32_t i : objects.added())
        if (objects.alive(i) && node_[i] == kInvalidIndex) insertObject(i, objects.worldBox(i));
    for (std::uint32_t i : objects.moved())
        if (objects.alive(i) && node_[i] != kInvalidIndex && relink(i, objects.worldBox(i))) ++stats.relinked;
    objects.clearMoved();
    objects.clearStructural();
    stats.rootGrowths = rootGrowths_ - growthsBefore;

    refitDirty(objects);
    stats.rebuilds = lazyRebuild(objects);
    stats.updateMs = msSince(t0);
    return stats;
}

// ---------------------------------------------------------------------------------------
// Lazy rebuild

// How far the subtree drifted from what it was built for (1 = as built). Growth: more
// objects than built for (a leaf past maxObjectsPerLeaf); shrink: an inner subtree much
// deeper than its contents need; skew: one child holds nearly everything.
float LooseBsp::imbalance(std::uint32_t n) const {
    const LooseBspNode& node = nodes_[n];
    const float m = static_cast<float>(std::max<std::uint32_t>(params_.maxObjectsPerLeaf, 1));
    const float sub = static_cast<float>(node.subtreeObjects);
    const float built = static_cast<float>(node.builtSubtreeObjects);
    float s = sub / std::max(built, m);
    if (!node.isLeaf()) {
        s = std::max(s, built / std::max(sub, m));
        if (sub > 2.0f * m) {
            const float c0 = static_cast<float>(nodes_[node.children[0]].subtreeObjects);
            const float c1 = static_cast<float>(nodes_[node.children[1]].subtreeObjects);
            s = std::max(s, std::sqrt((std::max(c0, c1) + m) / (std::min(c0, c1) + m)));
        }
    }
    return s;
}

void LooseBsp::noteCounts(std::uint32_t n) {
    if (params_.rebuildBudgetMs <= 0.0 || (nodes_[n].flags & kCandidate)) return;
    if (imbalance(n) > params_.imbalanceFactor) {
        nodes_[n].flags |= kCandidate;
        candidates_.push_back(n);
    }
}

void LooseBsp::rebuildSubtree(std::uint32_t n, const SceneObjects& objects) {
    gather_.clear();
    walk_.clear();
    walk_.push_back(n);
    while (!walk_.empty()) {
        LooseBspNode& node = nodes_[walk_.back()];
        walk_.pop_back();
        for (std::uint32_t o = node.firstObject; o != kInvalidIndex;) {
            const std::uint32_t nx = next_[o];
            gather_.push_back(o);
            node_[o] = next_[o] = prev_[o] = kInvalidIndex;
            o = nx;
        }
        node.firstObject = kInvalidIndex;
        node.objectCount = 0;
        if (!node.isLeaf()) {
            walk_.push_back(node.children[0]);
            walk_.push_back(node.children[1]);
        }
    }
    freeSubtreeBelow(n);
    nodes_[n].flags &= static_cast<std::uint8_t>(~kCandidate);
    // Same objects, same cell: the subtree box and all ancestors stay valid.
    buildNode(n, objects, gather_.data(), gather_.data() + gather_.size());
}

std::uint32_t LooseBsp::lazyRebuild(const SceneObjects& objects) {
    const double budget = params_.rebuildBudgetMs;
    if (budget <= 0.0 || candidates_.empty()) {
        rebuildCreditMs_ = 0.0;
        return 0;
    }
    const auto t0 = Clock::now();
    ranked_.clear();
    for (std::uint32_t n : candidates_) {
        LooseBspNode& node = nodes_[n];
        if (!(node.flags & kCandidate) || (node.flags & kFree)) continue;  // stale entry
        const float s = imbalance(n);
        if (s > params_.imbalanceFactor) ranked_.emplace_back(s, n);
        else node.flags &= static_cast<std::uint8_t>(~kCandidate);  // drifted back
    }
    // Biggest imbalance first; index breaks ties so runs are reproducible.
    std::sort(ranked_.begin(), ranked_.end(), [](const auto& a, const auto& b) {
        return a.first != b.first ? a.first > b.first : a.second < b.second;
    });

    const double cap = kCreditFrames * budget;
    const double available = budget + rebuildCreditMs_;
    std::uint32_t done = 0;
    std::size_t k = 0;
    for (; k < ranked_.size(); ++k) {
        const std::uint32_t n = ranked_[k].second;
        if (!(nodes_[n].flags & kCandidate)) continue;  // freed by an ancestor's rebuild
        const double estimate = nodes_[n].subtreeObjects * rebuildNsPerObject_ * 1e-6;
        const double spent = msSince(t0);
        // Too big for what is left: stop and save the budget for it, unless the savings are
        // full (it would never fit) — then it runs as this frame's only rebuild.
        if (spent + estimate > available && !(done == 0 && rebuildCreditMs_ >= cap)) break;
        const auto t1 = Clock::now();
        rebuildSubtree(n, objects);
        const double ms = msSince(t1);
        if (nodes_[n].subtreeObjects >= 16)  // tiny rebuilds are dominated by timer noise
            rebuildNsPerObject_ = 0.75 * rebuildNsPerObject_ + 0.25 * (ms * 1e6 / nodes_[n].subtreeObjects);
        ++done;
    }
    candidates_.clear();
    for (; k < ranked_.size(); ++k)
        if (nodes_[ranked_[k].second].flags & kCandidate) candidates_.push_back(ranked_[k].second);
    rebuildCreditMs_ = candidates_.empty() ? 0.0 : std::clamp(available - msSince(t0), 0.0, cap);
    return done;
}

// ---------------------------------------------------------------------------------------
// Queries

std::uint32_t LooseBsp::depth() const {
    std::uint32_t d = 0;
    for (const LooseBspNode& n : nodes_)
        if (!(n.flags & kFree)) d = std::max<std::uint32_t>(d, n.depth);
    return d;
}

std::uint32_t LooseBsp::nodeCount() const {
    return static_cast<std::uint32_t>(nodes_.size() - freeNodes_.size());
}

std::size_t LooseBsp::memoryBytes() const {
    std::size_t bytes = nodes_.capacity() * sizeof(LooseBspNode);
    for (const auto* v : {&freeNodes_, &node_, &next_, &prev_, &candidates_, &gather_, &walk_})
        bytes += v->capacity() * sizeof(std::uint32_t);
    for (const auto& b : dirtyByDepth_) bytes += b.capacity() * sizeof(std::uint32_t);
    bytes += ranked_.capacity() * sizeof(ranked_[0]);
    return bytes;
}

std::string LooseBsp::validate(const SceneObjects& objects) const {
    auto at = [](std::uint32_t n) { return "node " + std::to_string(n) + ": "; };
    if (nodes_.empty()) return objects.objectCount() == 0 ? "" : "no root but live objects";
    if (nodes_[0].flags & kFree) return "root is free";
    if (node_.size() < objects.slotCount()) return "per-object links smaller than slot count";
    std::uint32_t reachable = 0, listed = 0;
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
        const std::uint32_t n = stack.back();
        stack.pop_back();
        const LooseBspNode& node = nodes_[n];
        ++reachable;
        if (node.flags & kFree) return at(n) + "reachable but free";
        Aabb box;
        std::uint32_t count = 0, prev = kInvalidIndex;
        for (std::uint32_t o = node.firstObject; o != kInvalidIndex; prev = o, o = next_[o]) {
            if (++count > objects.slotCount()) return at(n) + "object list has a cycle";
            if (o >= objects.slotCount() || !objects.alive(o)) return at(n) + "lists dead slot " + std::to_string(o);
            if (node_[o] != n || prev_[o] != prev) return at(n) + "broken links of object " + std::to_string(o);
            const Aabb& b = objects.worldBox(o);
            if (!node.cell.contains(b)) return at(n) + "cell does not contain object " + std::to_string(o);
            if (!node.isLeaf() && (nodes_[node.children[0]].cell.contains(b) || nodes_[node.children[1]].cell.contains(b)))
                return at(n) + "object " + std::to_string(o) + " fits a child";
            box.extend(b);
        }
        if (count != node.objectCount) return at(n) + "objectCount " + std::to_string(node.objectCount) + " != listed " + std::to_string(count);
        listed += count;
        std::uint32_t sub = count;
        if ((node.children[0] == kInvalidIndex) != (node.children[1] == kInvalidIndex)) return at(n) + "one child only";
        if (!node.isLeaf()) {
            for (std::uint32_t c : node.children) {
                const LooseBspNode& child = nodes_[c];
                if (child.parent != n || child.depth != node.depth + 1) return at(c) + "bad parent or depth";
                if (!node.cell.contains(child.cell)) return at(c) + "cell not inside parent cell";
                box.extend(child.box);
                sub += child.subtreeObjects;
                stack.push_back(c);
            }
        }
        if (sub != node.subtreeObjects) return at(n) + "subtreeObjects " + std::to_string(node.subtreeObjects) + " != " + std::to_string(sub);
        if (box.min != node.box.min || box.max != node.box.max) return at(n) + "box is not the tight union of its contents";
        if (reachable > nodes_.size()) return "node graph has a cycle";
    }
    if (reachable != nodeCount()) return "reachable nodes " + std::to_string(reachable) + " != live nodes " + std::to_string(nodeCount());
    if (listed != objects.objectCount()) return "linked objects " + std::to_string(listed) + " != live objects " + std::to_string(objects.objectCount());
    for (std::uint32_t i = 0; i < objects.slotCount(); ++i)
        if (!objects.alive(i) && node_[i] != kInvalidIndex) return "dead slot " + std::to_string(i) + " still linked";
    return "";
}

}  // namespace dyncull
