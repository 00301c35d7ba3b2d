// Occlusion-culling scheduler over the two-level hierarchy.
// Papers: Two-level BSP for dynamic occlusion culling (Algorithms 2-4, section 3.4);
// Staneker, Bartz, Straßer, Efficient Multiple Occlusion Queries (sections 3-4):
// occupancy-map fast accept and batches of queries with non-overlapping rectangles.
#include "dyncull/scheduler/query_scheduler.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>

namespace dyncull {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace

const char* toString(CullMode m) {
    switch (m) {
        case CullMode::Vfc: return "vfc";
        case CullMode::Simple: return "simple";
        case CullMode::Queries: return "queries";
        case CullMode::TwoPhase: return "full";
    }
    return "?";
}

const char* toString(NodeState s) {
    switch (s) {
        case NodeState::FrustumCulled: return "frustum_culled";
        case NodeState::Occluded: return "occluded";
        case NodeState::SmallFeature: return "small_feature";
        case NodeState::VisibleQueried: return "visible_queried";
        case NodeState::VisibleHistory: return "visible_history";
        case NodeState::VisibleOccupancy: return "visible_occupancy";
        case NodeState::VisibleNear: return "visible_near";
        case NodeState::VisibleFront: return "visible_front";
        case NodeState::VisibleVfc: return "visible_vfc";
        case NodeState::VisibleCheaper: return "visible_cheaper";
        case NodeState::VisibleOccluder: return "visible_occluder";
        case NodeState::ClusterCulled: return "cluster_culled";
    }
    return "?";
}

Expected<CullMode> parseCullMode(const std::string& s) {
    if (s == "vfc") return CullMode::Vfc;
    if (s == "simple") return CullMode::Simple;
    if (s == "queries") return CullMode::Queries;
    if (s == "full") return CullMode::TwoPhase;
    return Error{"unknown mode '" + s + "' (expected vfc, simple, queries or full)"};
}

Status validateSchedulerParams(const SchedulerParams& p) {
    if (p.tuning.maxQueriesInFlight == 0) return Error{"maxQueriesInFlight must be at least 1"};
    if (p.tuning.occupancyTileSize <= 0) return Error{"occupancyTileSize must be positive"};
    if (!(p.tuning.queryTimeoutMs > 0.0)) return Error{"queryTimeoutMs must be positive"};
    if (p.tuning.history.maxSkipFrames > 1000) return Error{"history.maxSkipFrames must be at most 1000"};
    if (!(p.tuning.frontPercent >= 0.0f && p.tuning.frontPercent <= 100.0f)) return Error{"frontPercent must be in [0, 100]"};
    if (!(p.tuning.autoVolumeSaving >= 0.0f && p.tuning.autoVolumeSaving <= 1.0f)) return Error{"autoVolumeSaving must be in [0, 1]"};
    if (static_cast<int>(p.tuning.volume) > static_cast<int>(VolumeChoice::Auto)) return Error{"volume has an unknown value"};
    for (double c : {p.tuning.costs.drawNsPerTriangle, p.tuning.costs.testNsPerVolume, p.tuning.costs.testNsPerPixel, p.tuning.costs.depthReadNs,
                     p.tuning.costs.triangleTestNsPerPart, p.tuning.costs.triangleTestNsPerTriangle})
        if (!(c >= 0.0 && c < 1e12)) return Error{"costs must be finite and non-negative (nanoseconds)"};
    if (p.tuning.costs.probeFrames == 0) return Error{"costs.probeFrames must be at least 1"};
    return {};
}

QueryScheduler::QueryScheduler(SchedulerParams params) : params_(params) {}

FrameStats QueryScheduler::cullFrame(const TwoLevelTree& tree, const FrameView& view, QueryBackend& backend,
                                     PartSink& sink) {
    const Camera& camera = view.camera;
    const int width = view.width, height = view.height;
    const auto t0 = Clock::now();
    FrameStats st;
    ++frame_;  // frame 0 is "never"; the first culled frame is 1
    tree_ = &tree;
    backend_ = &backend;
    sink_ = &sink;
    marking_ = false;
    clusterPyramid_ = false;
    camera_ = camera;
    // Camera-relative (eye at the origin, set up in double): precise at any distance from
    // the world origin, like the renderer's and the query backend's transforms.
    viewProj_ = view.viewProjRelative;
    distanceRow_ = camera.distanceRowRelative();
    frustum_ = view.frustum;
    width_ = width;
    height_ = height;
    stats_ = &st;
    active_.clear();
    pending_.clear();
    if (trace_) trace_->clear();
    if (drawnMap_.tilesX() * params_.tuning.occupancyTileSize < width || drawnMap_.tilesY() * params_.tuning.occupancyTileSize < height ||
        (drawnMap_.tilesX() - 1) * params_.tuning.occupancyTileSize >= width) {
        drawnMap_.reset(width, height, params_.tuning.occupancyTileSize);
        pendingMap_.reset(width, height, params_.tuning.occupancyTileSize);
        waitingMap_.reset(width, height, params_.tuning.occupancyTileSize);
    } else {
        drawnMap_.clear();
        pendingMap_.clear();
        waitingMap_.clear();
    }
    const std::uint32_t slots = tree.objects().slotCount();
    if (stillSince_.size() < slots) {
        stillSince_.resize(slots, frame_);
        lastPlacement_.resize(slots, 0);
    }

    backend.beginFrame(view);
    const Aabb rootBox = tree.worldBox(tree.root());
    if (!rootBox.empty()) active_.push_back(tree.root());
    frontBudget_ = frontLeavesSeen_ = 0;
    if (params_.mode != CullMode::Vfc && params_.tuning.frontPercent > 0.0f && !rootBox.empty())
        frontBudget_ = static_cast<std::uint32_t>(std::ceil(double(params_.tuning.frontPercent) / 100.0 * countFrustumLeaves()));
    if (params_.mode != CullMode::Queries) {
        // Switched away from Queries: its last draw queries will not be read.
        for (const Pending& p : drawQueries_) backend.release(p.id);
        drawQueries_.clear();
    }
    drawOccluders();
    switch (params_.mode) {
        case CullMode::Vfc: runVfc(); break;
        case CullMode::Simple: runSimple(); break;
        case CullMode::Queries: runQueries(); break;
        case CullMode::TwoPhase: runTwoPhase(); break;
    }
    drawOccludees();
    st.traversalMs = std::max(0.0, msSince(t0) - st.waitMs - st.drawMs - st.queryMs - st.depthReadMs);
    stats_ = nullptr;
    return st;
}

// Backend calls are timed apart from scheduling: on a software rasteriser a poll may
// flush the command stream, which is GL work, not the scheduler's.
void QueryScheduler::timedBeginBatch() {
    const auto t0 = Clock::now();
    backend_->beginBatch();
    stats_->queryMs += msSince(t0);
}

void QueryScheduler::timedEndBatch() {
    const auto t0 = Clock::now();
    backend_->endBatch();
    stats_->queryMs += msSince(t0);
}

QueryId QueryScheduler::timedIssue(const QueryVolume& volume) {
    stats_->queryTriangles += volume.isBox() ? 12u : volume.triangleCount;
    const auto t0 = Clock::now();
    const QueryId id = backend_->issue(volume);
    stats_->queryMs += msSince(t0);
    return id;
}

QueryResult QueryScheduler::timedPoll(QueryId id) {
    const auto t0 = Clock::now();
    const QueryResult r = backend_->poll(id);
    stats_->queryMs += msSince(t0);
    return r;
}

bool QueryScheduler::projectRect(const Aabb& box, ScreenRect& out) const {
    // Project the box clipped to the near plane, so boxes crossing it still get a correct
    // (conservative) rectangle. Returns false if the box crosses the near plane.
    // Double and camera-relative: the near test compares distances along the view direction
    // directly (clip w in perspective) (no depth terms of the projection,
    // which at near 1e-4 and far 1e7 span 11 orders of magnitude).
    const glm::dvec3 eye(camera_.position);
    const glm::dvec3 lo3 = glm::dvec3(box.min) - eye, hi3 = glm::dvec3(box.max) - eye;
    // A box this close to the near plane counts as crossing it: the GPU clips a query
    // volume with float vertices relative to the eye, which a backend may also push out by
    // up to 2^-22 of its world coordinates (QueryBackend::issue).
    // 2^-21 of the box's and 2^-22 of the eye-relative magnitude (and of near) cover both
    // roundings with a factor of two to spare.
    auto magnitude = [](const glm::dvec3& a, const glm::dvec3& b) {
        const glm::dvec3 m = glm::max(glm::abs(a), glm::abs(b));
        return std::max({m.x, m.y, m.z});
    };
    const double nearPlane = double(camera_.nearPlane);
    const double nearTest = nearPlane + 0x1p-21 * magnitude(glm::dvec3(box.min), glm::dvec3(box.max)) +
                            0x1p-22 * (magnitude(lo3, hi3) + nearPlane);
    glm::dvec4 clip[8];
    double distance[8];  // along the view direction
    bool front[8];  // in front of the near plane itself: part of the rectangle
    bool crosses = false;
    for (int i = 0; i < 8; ++i) {
        const glm::dvec3 c((i & 1) ? hi3.x : lo3.x, (i & 2) ? hi3.y : lo3.y, (i & 4) ? hi3.z : lo3.z);
        clip[i] = viewProj_ * glm::dvec4(c, 1.0);
        distance[i] = viewDistance(clip[i], c);
        front[i] = distance[i] >= nearPlane;
        crosses |= distance[i] < nearTest;
    }
    glm::dvec2 lo(1e300), hi(-1e300);
    auto addPoint = [&](const glm::dvec4& p) {
        const glm::dvec2 ndc = glm::dvec2(p) / p.w;  // w >= near > 0 (perspective) or 1 for every point added
        lo = glm::min(lo, ndc);
        hi = glm::max(hi, ndc);
    };
    for (int i = 0; i < 8; ++i)
        if (front[i]) addPoint(clip[i]);
    {
        // The 12 edges: pairs of corners differing in exactly one bit, cut at the near plane.
        for (int i = 0; i < 8; ++i)
            for (int bit = 1; bit < 8; bit <<= 1) {
                const int j = i | bit;
                if (j == i || front[i] == front[j]) continue;
                const double t = (distance[i] - nearPlane) / (distance[i] - distance[j]);
                addPoint(clip[i] + (clip[j] - clip[i]) * t);
            }
    }
    if (lo.x > hi.x) {  // nothing in front of the near plane
        out = {};
        return !crosses;
    }
    out = pixelRect(lo, hi);
    return !crosses;
}

ScreenRect QueryScheduler::pixelRect(const glm::dvec2& lo, const glm::dvec2& hi) const {
    // Pixels, rounded outwards and padded by one so rasterisation rules never leave a
    // covered pixel outside the rectangle.
    const double fx = 0.5 * width_, fy = 0.5 * height_;
    auto clampi = [](double v, int lim) { return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(lim))); };
    return {clampi(std::floor((lo.x + 1.0) * fx) - 1.0, width_), clampi(std::floor((lo.y + 1.0) * fy) - 1.0, height_),
            clampi(std::ceil((hi.x + 1.0) * fx) + 1.0, width_), clampi(std::ceil((hi.y + 1.0) * fy) + 1.0, height_)};
}

QueryScheduler::FirstTest QueryScheduler::firstVisibilityTest(NodeRef ref, const Aabb& box, NodeHistory& h,
                                                             FrameStats& st) {
    // Algorithm 3.
    if (frustum_.outside(box)) {
        ++st.frustumCulled;
        h.lastVisible = false;
        trace(ref, box, NodeState::FrustumCulled);
        return FirstTest::Invisible;
    }
    ScreenRect rect;
    const bool inFront = projectRect(box, rect);
    if (!inFront || box.contains(camera_.position)) {
        // Camera inside or box crossing the near plane: a query could be clipped away
        // and wrongly answer "occluded", so such a node is always visible.
        ++st.visibleNearOrInside;
        trace(ref, box, NodeState::VisibleNear);
        return FirstTest::Visible;
    }
    if (rect.empty()) {
        // Passed the conservative plane test but projects to no pixel of the viewport.
        ++st.frustumCulled;
        h.lastVisible = false;
        trace(ref, box, NodeState::FrustumCulled);
        return FirstTest::Invisible;
    }
    if (frontLeavesSeen_ < frontBudget_) {
        // Front-most leaves (k-DOP paper, section 4): rarely occluded, drawn untested.
        // Inner nodes met before the budget is spent are opened the same way.
        if (tree_->isDrawable(ref)) ++frontLeavesSeen_;
        ++st.visibleFront;
        trace(ref, box, NodeState::VisibleFront);
        return FirstTest::Visible;
    }
    if (params_.mode != CullMode::Queries) return FirstTest::NeedQuery;
    if (params_.approx.smallFeaturePixels > 0 && static_cast<std::uint32_t>(rect.area()) < params_.approx.smallFeaturePixels) {
        ++st.smallFeatureCulled;
        h.lastVisible = false;
        trace(ref, box, NodeState::SmallFeature);
        return FirstTest::Invisible;
    }
    if (params_.features.useHistory && history_.canSkipQuery(ref, h, frame_, params_.tuning.history)) {
        ++st.skippedByHistory;
        trace(ref, box, NodeState::VisibleHistory);
        return FirstTest::Visible;
    }
    return FirstTest::NeedQuery;
}

QueryVolume QueryScheduler::queryVolume(NodeRef ref, const Aabb& worldBox) const {
    if (ref.isSceneNode() || params_.mode != CullMode::Queries || !params_.features.useTightVolumes) return QueryVolume::fromAabb(worldBox);
    // Tightened volume: the node's own object-space volume under the object's matrix
    // instead of its world AABB, once the object has kept its transform for a few frames.
    if (frame_ - stillSince_[ref.object] < params_.tuning.tightenAfterFrames) return QueryVolume::fromAabb(worldBox);
    return objectNodeVolume(tree_->objects(), ref, params_.tuning.volume, params_.tuning.autoVolumeSaving);
}

QueryVolume objectNodeVolume(const SceneObjects& objs, NodeRef ref, VolumeChoice volume, float autoSaving) {
    assert(!ref.isSceneNode());
    const LocalBsp& model = objs.model(objs.modelOf(ref.object));
    const glm::mat4& m = objs.matrix(ref.object);
    if (volume == VolumeChoice::Aabb || model.volumes.nodeCount() != model.nodes.size())
        return QueryVolume::fromTransformedBox(m, model.nodes[ref.node].box);
    const VolumeKind kind = chooseVolume(model.volumes, ref.node, volume, autoSaving);
    const NodeVolume& v = model.volumes.get(ref.node, kind);
    if (v.vertexCount == 0)  // empty node: never reached in practice
        return QueryVolume::fromAabb(transformAabb(m, model.nodes[ref.node].box));
    return QueryVolume::fromNodeVolume(m, model.volumes, v);
}

void QueryScheduler::drawNode(NodeRef ref, bool untested) {
    const SceneObjects& objs = tree_->objects();
    const LocalBsp& model = objs.model(objs.modelOf(ref.object));
    const LocalBspNode& n = model.nodes[ref.node];
    const bool clustered = cullClusters(ref, model, n);
    if (clustered && clusterRanges_.empty()) {
        // No cluster of it can show a pixel: its decision, traced just before, becomes this.
        if (trace_) {
            if (!trace_->empty() && trace_->back().ref == ref)
                trace_->back().state = NodeState::ClusterCulled;
            else
                trace(ref, tree_->worldBox(ref), NodeState::ClusterCulled);
        }
        return;
    }
    const auto t0 = Clock::now();
    auto draw = [&] {
        if (clustered)
            sink_->drawPartRanges(ref, clusterRanges_);
        else
            sink_->drawPart(ref, n.firstIndex, n.indexCount);
    };
    if (untested && params_.mode == CullMode::Queries && params_.features.useDrawQueries) {
        const QueryId id = backend_->beginDrawQuery();
        draw();
        if (id != kNoQuery) {
            backend_->endDrawQuery(id);
            drawQueries_.push_back(pendingOf(ref, id, {}, false));
            ++stats_->drawQueries;
        }
    } else {
        draw();
        if (marking_) markedDraws_.push_back(ref);  // the sink marks its draws in this order
    }
    stats_->drawMs += msSince(t0);
    ++stats_->partsDrawn;
    if (!clustered) {
        stats_->trianglesDrawn += n.indexCount / 3;
    } else {
        for (const IndexRange& r : clusterRanges_) stats_->trianglesDrawn += r.indexCount / 3;
    }
    if (params_.mode == CullMode::Queries && params_.features.useOccupancyAccept) {
        ScreenRect r;
        projectRect(tree_->worldBox(ref), r);
        drawnMap_.mark(r);
    }
}

void QueryScheduler::processVisible(NodeRef ref, NodeHistory& h, bool untested) {
    // Algorithm 4: draw a part, or replace the node by its children front-to-back.
    h.lastVisible = true;
    h.lastVisibleFrame = frame_;
    if (tree_->isDrawable(ref)) {
        drawNode(ref, untested);
        return;
    }
    pushChildren(ref);
}

std::uint32_t QueryScheduler::countFrustumLeaves() const {
    // The k-DOP paper's list L: leaves not outside the frustum, by a hierarchical walk of
    // both levels (no sorting, no screen projection).
    const LooseBsp& scene = tree_->scene();
    const SceneObjects& objs = tree_->objects();
    std::uint32_t leaves = 0;
    std::vector<std::uint32_t> stack{scene.root()}, local;
    while (!stack.empty()) {
        const LooseBspNode& node = scene.nodes()[stack.back()];
        stack.pop_back();
        if (node.subtreeObjects == 0 || frustum_.outside(node.box)) continue;
        for (std::uint32_t o = node.firstObject; o != kInvalidIndex; o = scene.nextObject(o)) {
            if (frustum_.outside(objs.worldBox(o))) continue;
            const LocalBsp& model = objs.model(objs.modelOf(o));
            local.assign(1, 0);
            while (!local.empty()) {
                const std::uint32_t n = local.back();
                local.pop_back();
                const LocalBspNode& ln = model.nodes[n];
                if (n != 0 && (ln.indexCount == 0 || frustum_.outside(transformAabb(objs.matrix(o), ln.box)))) continue;
                if (ln.isLeaf()) {
                    ++leaves;
                } else {
                    local.push_back(ln.children[0]);
                    local.push_back(ln.children[1]);
                }
            }
        }
        if (!node.isLeaf()) {
            stack.push_back(node.children[0]);
            stack.push_back(node.children[1]);
        }
    }
    return leaves;
}

void QueryScheduler::runVfc() {
    while (!active_.empty()) {
        const NodeRef ref = active_.back();
        active_.pop_back();
        ++stats_->nodesVisited;
        if (frustum_.outside(tree_->worldBox(ref))) {
            ++stats_->frustumCulled;
            if (trace_) trace(ref, tree_->worldBox(ref), NodeState::FrustumCulled);
            continue;
        }
        NodeHistory& h = history_.at(ref, tree_->objects());
        h.lastTouchedFrame = frame_;
        if (trace_) trace(ref, tree_->worldBox(ref), NodeState::VisibleVfc);
        processVisible(ref, h, false);
    }
}

void QueryScheduler::runSimple() {
    // Simple OC: hierarchical, one stop-and-wait query per node in the frustum.
    while (!active_.empty()) {
        const NodeRef ref = active_.back();
        active_.pop_back();
        ++stats_->nodesVisited;
        const Aabb box = tree_->worldBox(ref);
        NodeHistory& h = history_.at(ref, tree_->objects());
        const FirstTest ft = firstVisibilityTest(ref, box, h, *stats_);
        h.lastTouchedFrame = frame_;
        if (ft == FirstTest::Invisible) continue;
        if (ft == FirstTest::NeedQuery) {
            timedBeginBatch();
            const QueryId id = timedIssue(QueryVolume::fromAabb(box));
            timedEndBatch();
            ++stats_->queriesIssued;
            ++stats_->batches;
            const auto tw = Clock::now();
            const QueryResult r = backend_->wait(id, params_.tuning.queryTimeoutMs);
            stats_->waitMs += msSince(tw);
            backend_->release(id);
            if (r == QueryResult::NotReady) ++stats_->queriesTimedOut;
            const bool visible = r != QueryResult::Occluded;
            history_.recordAnswer(h, visible, frame_);
            trace(ref, box, visible ? NodeState::VisibleQueried : NodeState::Occluded);
            if (!visible) {
                ++stats_->queriesOccluded;
                continue;
            }
        }
        processVisible(ref, h, false);
    }
}

void QueryScheduler::finishQuery(Pending& p, QueryResult r) {
    backend_->release(p.id);
    if (p.batchedRect) pendingMap_.unmark(p.rect);
    if (r == QueryResult::NotReady) ++stats_->queriesTimedOut;  // from wait(): timed out
    const bool visible = r != QueryResult::Occluded;
    NodeHistory& h = history_.at(p.node, tree_->objects());
    history_.recordAnswer(h, visible, frame_);
    if (trace_) trace(p.node, tree_->worldBox(p.node), visible ? NodeState::VisibleQueried : NodeState::Occluded);
    if (visible)
        processVisible(p.node, h, false);
    else
        ++stats_->queriesOccluded;
}

QueryScheduler::Pending QueryScheduler::pendingOf(NodeRef ref, QueryId id, ScreenRect rect, bool batchedRect) const {
    const std::uint32_t gen = ref.isSceneNode() ? 0 : tree_->objects().handle(ref.object).generation;
    return {ref, id, rect, batchedRect, gen};
}

template <class OnAnswer>
void QueryScheduler::takeAnswered(std::vector<Pending>& queries, OnAnswer onAnswer) {
    const SceneObjects& objs = tree_->objects();
    for (std::size_t i = 0; i < queries.size();) {
        const Pending p = queries[i];
        const QueryResult r = timedPoll(p.id);
        if (r == QueryResult::NotReady) {
            ++i;
            continue;
        }
        backend_->release(p.id);
        // The object may have been removed since the query was issued, and its slot reused
        // by another object (of a model with fewer nodes, perhaps): only the same object's
        // answer is recorded.
        if (p.node.isSceneNode() || (p.node.object < objs.slotCount() && objs.alive(p.node.object) &&
                                     objs.handle(p.node.object).generation == p.generation))
            onAnswer(history_.at(p.node, objs), r);
        queries[i] = queries.back();
        queries.pop_back();
    }
}

void QueryScheduler::collectLatent() {
    // Answers to queries of earlier frames (useLastFrameResults): recorded in the history
    // for the next decision; never drawn from here.
    takeAnswered(latent_, [&](NodeHistory& h, QueryResult r) {
        h.queryInFlight = false;
        history_.recordAnswer(h, r != QueryResult::Occluded, frame_);
    });
}

void QueryScheduler::collectDrawAnswers() {
    // Last frame's draw queries. A part already reached this frame keeps this frame's
    // decision (the answer is older); an unanswered query is polled again later.
    takeAnswered(drawAnswers_, [&](NodeHistory& h, QueryResult r) {
        if (h.lastTouchedFrame == frame_) return;
        history_.recordAnswer(h, r != QueryResult::Occluded, frame_ - 1);
        if (r == QueryResult::Occluded) ++stats_->drawQueriesOccluded;
    });
}

void QueryScheduler::runQueries() {
    // Algorithm 2 with batching: the active list (a stack, nearest at the back) is refined
    // as visible nodes are replaced by their children; nodes that need a query but overlap
    // a pending query's rectangle (or exceed the in-flight limit) wait in `deferred`.
    const SceneObjects& objs = tree_->objects();
    bool batchOpen = false;
    auto openBatch = [&] {
        if (!batchOpen) {
            timedBeginBatch();
            batchOpen = true;
            ++stats_->batches;
        }
    };
    auto closeBatch = [&] {
        if (batchOpen) {
            timedEndBatch();
            batchOpen = false;
        }
    };
    // Issue a query for `ref` now if allowed; false if it must wait.
    auto tryIssue = [&](NodeRef ref, const Aabb& box, const ScreenRect& rect) -> bool {
        if (pending_.size() >= params_.tuning.maxQueriesInFlight) return false;
        if (params_.features.useBatching) {
            if (!params_.approx.batchOverlapping && pendingMap_.anySet(rect)) return false;
        } else if (!pending_.empty()) {
            return false;  // no batching: one query in flight at a time
        }
        if (!ref.isSceneNode()) {
            const std::uint64_t placed = objs.placedAt(ref.object);
            if (placed != lastPlacement_[ref.object]) {
                lastPlacement_[ref.object] = placed;
                stillSince_[ref.object] = frame_;
            }
        }
        openBatch();
        const QueryId id = timedIssue(queryVolume(ref, box));
        ++stats_->queriesIssued;
        const bool marked = params_.features.useBatching;
        if (marked) pendingMap_.mark(rect);
        pending_.push_back(pendingOf(ref, id, rect, marked));
        return true;
    };

    // Nodes waiting for a query, nearest first. With useWaitOrder a waiting node also
    // blocks every farther node whose rectangle overlaps it (waitingMap_), so no node is
    // queried before a nearer occluder in front of it is drawn (fewer parts drawn for
    // nothing, more waiting).
    struct Deferred {
        float dist2;  // squared distance from the eye to the box centre
        NodeRef ref;
        Aabb box;
        ScreenRect rect;
    };
    std::vector<Deferred> deferred;
    const glm::dvec3 eye(camera_.position);
    auto defer = [&](NodeRef ref, const Aabb& box, const ScreenRect& rect) {
        const glm::vec3 d = glm::vec3(glm::dvec3(box.center()) - eye);
        const Deferred w{glm::dot(d, d), ref, box, rect};
        auto at = std::upper_bound(deferred.begin(), deferred.end(), w.dist2,
                                   [](float v, const Deferred& e) { return v < e.dist2; });
        deferred.insert(at, w);
        waitingMap_.mark(rect);
    };
    const bool keepOrder = params_.features.useWaitOrder && !params_.approx.batchOverlapping;
    // Occupancy-map fast accept: a rectangle touching screen area where nothing has been
    // drawn cannot be hidden. Tested as soon as a node is reached, even if a nearer waiting
    // node overlaps it: deferring the test too waited far longer for few parts saved
    // (docs/BENCHMARKS.md, "Waiting order").
    auto occupancyAccept = [&](NodeRef ref, const Aabb& box, const ScreenRect& rect) -> bool {
        if (!params_.features.useOccupancyAccept || drawnMap_.allSet(rect)) return false;
        ++stats_->skippedByOccupancy;
        NodeHistory& h = history_.at(ref, objs);
        history_.recordAnswer(h, true, frame_);
        trace(ref, box, NodeState::VisibleOccupancy);
        closeBatch();
        processVisible(ref, h, true);
        return true;
    };

    waitingMap_.clear();
    bool answered = false;  // a query finished since waiting nodes were last retried
    collectLatent();
    // Last frame's draw queries become this frame's answers to read; never waited for.
    drawAnswers_.swap(drawQueries_);
    drawQueries_.clear();
    collectDrawAnswers();

    while (!active_.empty() || !deferred.empty() || !pending_.empty()) {
        bool progress = false;

        // 1. Finish answered queries, oldest first; visible ones push their children.
        closeBatch();
        if (!drawAnswers_.empty()) collectDrawAnswers();
        for (std::size_t i = 0; i < pending_.size();) {
            const QueryResult r = timedPoll(pending_[i].id);
            if (r == QueryResult::NotReady) {
                ++i;
                continue;
            }
            Pending p = pending_[i];
            pending_.erase(pending_.begin() + static_cast<std::ptrdiff_t>(i));
            finishQuery(p, r);
            progress = answered = true;
        }

        // 2. Process the active list front-to-back.
        while (!active_.empty()) {
            const NodeRef ref = active_.back();
            active_.pop_back();
            ++stats_->nodesVisited;
            progress = true;
            const Aabb box = tree_->worldBox(ref);
            NodeHistory& h = history_.at(ref, objs);
            const FirstTest ft = firstVisibilityTest(ref, box, h, *stats_);  // reads last frame's lastTouchedFrame
            h.lastTouchedFrame = frame_;
            if (ft == FirstTest::Invisible) continue;
            if (ft == FirstTest::Visible) {
                closeBatch();
                processVisible(ref, h, true);
                continue;
            }
            ScreenRect rect;
            projectRect(box, rect);
            if (occupancyAccept(ref, box, rect)) continue;
            if (!params_.approx.useLastFrameResults) {
                if ((keepOrder && !deferred.empty() && waitingMap_.anySet(rect)) || !tryIssue(ref, box, rect))
                    defer(ref, box, rect);
            } else {
                // Approximate: act on the previous answer now, read this query next frame.
                if (!h.queryInFlight) {
                    openBatch();
                    const QueryId id = timedIssue(queryVolume(ref, box));
                    ++stats_->queriesIssued;
                    latent_.push_back(pendingOf(ref, id, rect, false));
                    h.queryInFlight = true;
                }
                if (h.answers > 0 && !h.lastVisible) {
                    ++stats_->queriesOccluded;
                    trace(ref, box, NodeState::Occluded);
                    continue;
                }
                trace(ref, box, NodeState::VisibleQueried);
                closeBatch();
                processVisible(ref, h, false);
            }
        }

        // 3. Retry waiting nodes nearest first; each one still waiting blocks the farther
        // ones it overlaps. (The drawn map only fills up, so the occupancy accept, tested
        // before a node waits, cannot newly succeed.)
        if (answered && !deferred.empty()) {
            // Only an answer frees a rectangle or an in-flight slot; without one, every
            // waiting node is still blocked.
            answered = false;
            waitingMap_.clear();
            std::size_t kept = 0;  // compacts in place, keeping the order
            for (const Deferred& d : deferred) {
                const bool blocked = keepOrder && waitingMap_.anySet(d.rect);
                if (!blocked && tryIssue(d.ref, d.box, d.rect)) {
                    progress = true;
                } else {
                    waitingMap_.mark(d.rect);
                    deferred[kept++] = d;
                }
            }
            deferred.resize(kept);
        }
        closeBatch();

        // 4. Nothing else to do: wait for the oldest query.
        if (!progress && active_.empty() && !pending_.empty()) {
            const auto tw = Clock::now();
            const QueryResult r = backend_->wait(pending_.front().id, params_.tuning.queryTimeoutMs);
            stats_->waitMs += msSince(tw);
            Pending p = pending_.front();
            pending_.erase(pending_.begin());
            finishQuery(p, r);
            answered = true;
        }
    }
    closeBatch();
    // Answers that have not arrived by now would be two frames old at the next read:
    // dropped, so those parts keep their history.
    stats_->drawQueriesLate += static_cast<std::uint32_t>(drawAnswers_.size());
    for (const Pending& p : drawAnswers_) backend_->release(p.id);
    drawAnswers_.clear();
}

}  // namespace dyncull
