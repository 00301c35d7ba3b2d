// Occlusion-culling scheduler over the two-level hierarchy: the frame set-up and the
// stages every mode shares (first visibility test, drawing a visible node or opening it),
// plus the vfc and Simple modes. Queries lives in hardware_queries.cpp, TwoPhase in
// two_phase.cpp.
// Papers: Two-level BSP for dynamic occlusion culling (Algorithms 3-4, section 3.4);
// k-DOP bounding volumes for occlusion, section 4 (the front-most leaves drawn untested).
#include "dyncull/scheduler/query_scheduler.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "cluster_selection.hpp"
#include "pending_queries.hpp"

namespace dyncull {

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
        case NodeState::BudgetCulled: return "budget_culled";
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
    const TestCosts& costs = p.tuning.costs;
    for (double c : {costs.drawNsPerTriangle, costs.testNsPerVolume, costs.testNsPerPixel, costs.testNsPerBatch, costs.depthReadNs,
                     costs.triangleTestNsPerPart, costs.triangleTestNsPerTriangle, costs.clusterTestNs, costs.recordNsPerCluster,
                     costs.recordNsPerLearned, costs.drawNsPerRange, costs.pyramidNs})
        if (!(c >= 0.0 && c < 1e12)) return Error{"costs must be finite and non-negative (nanoseconds)"};
    if (!(costs.roundPyramidCulls >= 0.0 && costs.roundPyramidCulls <= 1.0)) return Error{"costs.roundPyramidCulls must be in [0, 1] (a share)"};
    if (!(p.approx.errorBudgetPercent >= 0.0 && p.approx.errorBudgetPercent <= 100.0))
        return Error{"errorBudgetPercent must be in [0, 100] (percent of the frame's pixels)"};
    if (p.tuning.costs.probeFrames == 0) return Error{"costs.probeFrames must be at least 1"};
    if (p.tuning.pyramidSpan < 2 || p.tuning.pyramidSpan > 64) return Error{"pyramidSpan must be in [2, 64] (texels)"};
    if (p.tuning.texelTestTexels < 0 || p.tuning.texelTestTexels > 65536) return Error{"texelTestTexels must be in [0, 65536]"};
    if (p.tuning.clusterTexelTests < 0 || p.tuning.clusterTexelTests > 65536) return Error{"clusterTexelTests must be in [0, 65536]"};
    if (p.tuning.candidateRounds < 1 || p.tuning.candidateRounds > 16) return Error{"candidateRounds must be in [1, 16]"};
    if (p.tuning.clusterPyramidSpan < 2 || p.tuning.clusterPyramidSpan > 64)
        return Error{"clusterPyramidSpan must be in [2, 64] (texels)"};
    if (p.tuning.recordPyramidSpan < 2 || p.tuning.recordPyramidSpan > 64)
        return Error{"recordPyramidSpan must be in [2, 64] (texels)"};
    return {};
}

QueryScheduler::QueryScheduler(SchedulerParams params)
    : params_(params),
      queries_(std::make_unique<QueryIssuer>()),
      latent_(std::make_unique<DeferredQueries>()),
      drawQueries_(std::make_unique<DrawQueries>()) {}
QueryScheduler::~QueryScheduler() = default;
QueryScheduler::QueryScheduler(QueryScheduler&&) noexcept = default;
QueryScheduler& QueryScheduler::operator=(QueryScheduler&&) noexcept = default;

FrameStats QueryScheduler::cullFrame(const TwoLevelTree& tree, const FrameView& view, QueryBackend& backend,
                                     PartSink& sink) {
    const auto t0 = SchedulerClock::now();
    FrameStats st;
    ++frame_;  // frame 0 is "never"; the first culled frame is 1
    // Camera-relative matrices (eye at the origin, set up in double): precise at any
    // distance from the world origin, like the renderer's and the query backend's.
    Frame f{tree, tree.objects(), backend, sink, view, ScreenProjection(view), st, trace_, frame_};
    if (trace_) trace_->clear();
    active_.clear();
    const std::uint32_t slots = tree.objects().slotCount();
    if (stillSince_.size() < slots) {
        stillSince_.resize(slots, frame_);
        lastPlacement_.resize(slots, 0);
    }

    backend.beginFrame(view);
    const Aabb rootBox = tree.worldBox(tree.root());
    if (!rootBox.empty()) active_.push_back(tree.root());
    if (params_.mode != CullMode::Vfc && params_.tuning.frontPercent > 0.0f && !rootBox.empty())
        f.frontBudget = static_cast<std::uint32_t>(std::ceil(double(params_.tuning.frontPercent) / 100.0 * countFrustumLeaves(f)));
    if (params_.mode != CullMode::Queries) {
        // Switched away from Queries: its last draw queries will not be read.
        drawQueries_->releaseAll(backend);
    }
    drawOccluders(f);
    switch (params_.mode) {
        case CullMode::Vfc: runVfc(f); break;
        case CullMode::Simple: runSimple(f); break;
        case CullMode::Queries: runQueries(f); break;
        case CullMode::TwoPhase: runTwoPhase(f); break;
    }
    drawOccludees(f);
    st.traversalMs = std::max(0.0, msSince(t0) - st.waitMs - st.drawMs - st.queryMs - st.depthReadMs);
    return st;
}

QueryScheduler::FirstTest QueryScheduler::firstVisibilityTest(Frame& f, NodeRef ref, const Aabb& box, NodeHistory& h) {
    // Algorithm 3.
    FrameStats& st = f.stats;
    if (f.frustum().outside(box)) {
        ++st.frustumCulled;
        h.lastVisible = false;
        f.note(ref, box, NodeState::FrustumCulled);
        return FirstTest::Invisible;
    }
    ScreenRect rect;
    const bool inFront = f.screen.rect(box, rect);
    if (!inFront || box.contains(f.camera().position)) {
        // Camera inside or box crossing the near plane: a query could be clipped away
        // and wrongly answer "occluded", so such a node is always visible.
        ++st.visibleNearOrInside;
        f.note(ref, box, NodeState::VisibleNear);
        return FirstTest::Visible;
    }
    if (rect.empty()) {
        // Passed the conservative plane test but projects to no pixel of the viewport.
        ++st.frustumCulled;
        h.lastVisible = false;
        f.note(ref, box, NodeState::FrustumCulled);
        return FirstTest::Invisible;
    }
    if (f.frontLeavesSeen < f.frontBudget) {
        // Front-most leaves (k-DOP paper, section 4): rarely occluded, drawn untested.
        // Inner nodes met before the budget is spent are opened the same way.
        if (f.tree.isDrawable(ref)) ++f.frontLeavesSeen;
        ++st.visibleFront;
        f.note(ref, box, NodeState::VisibleFront);
        return FirstTest::Visible;
    }
    if (params_.mode != CullMode::Queries) return FirstTest::NeedQuery;
    if (params_.approx.smallFeaturePixels > 0 && static_cast<std::uint32_t>(rect.area()) < params_.approx.smallFeaturePixels) {
        ++st.smallFeatureCulled;
        st.claimedErrorPixels += static_cast<std::uint64_t>(rect.area());  // everything it could show is inside
        h.lastVisible = false;
        f.note(ref, box, NodeState::SmallFeature);
        return FirstTest::Invisible;
    }
    if (params_.features.useHistory && history_.canSkipQuery(ref, h, f.index, params_.tuning.history)) {
        ++st.skippedByHistory;
        f.note(ref, box, NodeState::VisibleHistory);
        return FirstTest::Visible;
    }
    return FirstTest::NeedQuery;
}

QueryScheduler::Visit QueryScheduler::visitNearest(Frame& f) {
    const NodeRef ref = active_.back();
    active_.pop_back();
    ++f.stats.nodesVisited;
    const Aabb box = f.tree.worldBox(ref);
    NodeHistory& h = history_.at(ref, f.objects);
    const FirstTest ft = firstVisibilityTest(f, ref, box, h);  // reads last frame's lastTouchedFrame
    h.lastTouchedFrame = f.index;
    return {ref, box, ft};
}

QueryVolume QueryScheduler::queryVolume(const Frame& f, NodeRef ref, const Aabb& worldBox) const {
    if (ref.isSceneNode() || params_.mode != CullMode::Queries || !params_.features.useTightVolumes) return QueryVolume::fromAabb(worldBox);
    // Tightened volume: the node's own object-space volume under the object's matrix
    // instead of its world AABB, once the object has kept its transform for a few frames.
    if (f.index - stillSince_[ref.object] < params_.tuning.tightenAfterFrames) return QueryVolume::fromAabb(worldBox);
    return objectNodeVolume(f.objects, ref, params_.tuning.volume, params_.tuning.autoVolumeSaving);
}

namespace {
/// Whether objectNodeVolume takes the node's own box: the box was asked for, or the model
/// has no stored volumes.
bool nodeBoxOnly(const LocalBsp& model, VolumeChoice volume) {
    return volume == VolumeChoice::Aabb || model.volumes.nodeCount() != model.nodes.size();
}
}  // namespace

VolumeKind objectNodeVolumeKind(const SceneObjects& objs, NodeRef ref, VolumeChoice volume, float autoSaving) {
    assert(!ref.isSceneNode());
    const LocalBsp& model = objs.model(objs.modelOf(ref.object));
    if (nodeBoxOnly(model, volume)) return VolumeKind::Aabb;
    return chooseVolume(model.volumes, ref.node, volume, autoSaving);
}

Aabb objectNodeBox(const SceneObjects& objs, NodeRef ref, VolumeChoice volume) {
    assert(!ref.isSceneNode());
    const LocalBsp& model = objs.model(objs.modelOf(ref.object));
    if (nodeBoxOnly(model, volume)) return model.nodes[ref.node].box;
    Aabb box;
    for (const glm::vec3& p : model.volumes.verticesOf(model.volumes.get(ref.node, VolumeKind::Aabb))) box.extend(p);
    return box;
}

glm::dmat4 boxFrame(std::span<const glm::vec3, 8> corners) {
    // Corner i is the centre plus or minus half axis k as bit k of i is set or clear: the
    // sums over all eight cancel the other axes, and average the corners' roundings.
    glm::dvec3 centre(0.0), axes[3] = {glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0)};
    for (std::size_t i = 0; i < 8; ++i) {
        const glm::dvec3 c(corners[i]);
        centre += c;
        for (std::size_t k = 0; k < 3; ++k) axes[k] += (i >> k) & 1 ? c : -c;
    }
    return glm::dmat4(glm::dvec4(axes[0] / 8.0, 0.0), glm::dvec4(axes[1] / 8.0, 0.0), glm::dvec4(axes[2] / 8.0, 0.0),
                      glm::dvec4(centre / 8.0, 1.0));
}

std::optional<glm::dmat4> objectNodeObbFrame(const SceneObjects& objs, NodeRef ref) {
    assert(!ref.isSceneNode());
    const LocalBsp& model = objs.model(objs.modelOf(ref.object));
    if (model.volumes.nodeCount() != model.nodes.size()) return std::nullopt;
    const NodeVolume& v = model.volumes.get(ref.node, VolumeKind::Obb);
    if (v.vertexCount != 8 || !v.isBox()) return std::nullopt;
    return glm::dmat4(objs.matrix(ref.object)) * boxFrame(model.volumes.verticesOf(v).first<8>());
}

QueryVolume objectNodeVolume(const SceneObjects& objs, NodeRef ref, VolumeChoice volume, float autoSaving) {
    assert(!ref.isSceneNode());
    const LocalBsp& model = objs.model(objs.modelOf(ref.object));
    const glm::mat4& m = objs.matrix(ref.object);
    if (nodeBoxOnly(model, volume)) return QueryVolume::fromTransformedBox(m, model.nodes[ref.node].box);
    const VolumeKind kind = objectNodeVolumeKind(objs, ref, volume, autoSaving);
    const NodeVolume& v = model.volumes.get(ref.node, kind);
    if (v.vertexCount == 0)  // empty node: never reached in practice
        return QueryVolume::fromAabb(transformAabb(m, model.nodes[ref.node].box));
    return QueryVolume::fromNodeVolume(m, model.volumes, v);
}

void QueryScheduler::drawNode(Frame& f, NodeRef ref, bool untested, ClusterPass pass) {
    const SceneObjects& objs = f.objects;
    const LocalBsp& model = objs.model(objs.modelOf(ref.object));
    const LocalBspNode& n = model.nodes[ref.node];
    const bool clustered = cullClusters(f, ref, model, n, pass);
    if (lastDeferred_ > 0) {
        // The late pass decides on the rest of its clusters, and on its trace entry if
        // none is drawn now.
        const bool traced = f.trace && !f.trace->empty() && f.trace->back().ref == ref;
        const std::uint32_t entry = traced ? static_cast<std::uint32_t>(f.trace->size() - 1) : kInvalidIndex;
        // Its early cull pushed it last onto clusterParts_, where the record finds it.
        assert(!f.recordClusterBits || (!clusterParts_.empty() && clusterParts_.back() == ref));
        const std::uint32_t recordIndex = f.recordClusterBits ? static_cast<std::uint32_t>(clusterParts_.size() - 1) : kInvalidIndex;
        deferredParts_.push_back({ref, !clusterRanges_.empty(), entry, recordIndex});
        if (clusterRanges_.empty()) return;
    }
    if (clustered && clusterRanges_.empty()) {
        // No cluster of it can show a pixel: its decision, traced just before, becomes this.
        if (f.trace) {
            if (!f.trace->empty() && f.trace->back().ref == ref)
                f.trace->back().state = NodeState::ClusterCulled;
            else
                f.note(ref, NodeState::ClusterCulled);
        }
        return;
    }
    const auto t0 = SchedulerClock::now();
    auto draw = [&] {
        if (clustered)
            f.sink.drawPartRanges(ref, clusterRanges_);
        else
            f.sink.drawPart(ref, n.firstIndex, n.indexCount);
    };
    if (untested && params_.mode == CullMode::Queries && params_.features.useDrawQueries) {
        const QueryId id = f.backend.beginDrawQuery();
        draw();
        if (id != kNoQuery) {
            f.backend.endDrawQuery(id);
            drawQueries_->add(f.objects, ref, id);
            ++f.stats.drawQueries;
        }
    } else {
        draw();
        if (f.marking) markedDraws_.push_back(ref);  // the sink marks its draws in this order
        if (f.markClusters && clustered) noteMarkedRanges(ref);
    }
    f.stats.drawMs += msSince(t0);
    ++f.stats.partsDrawn;
    if (!clustered) {
        // A bounds model stands for its object: count what its draw costs, not the box.
        f.stats.trianglesDrawn += model.drawTriangles > 0 ? model.drawTriangles : n.indexCount / 3;
    } else {
        for (const IndexRange& r : clusterRanges_) f.stats.trianglesDrawn += r.indexCount / 3;
    }
    if (params_.mode == CullMode::Queries && params_.features.useOccupancyAccept) {
        ScreenRect r;
        f.screen.rect(f.tree.worldBox(ref), r);
        drawnMap_.mark(r);
    }
}

void QueryScheduler::processVisible(Frame& f, NodeRef ref, NodeHistory& h, bool untested) {
    // Algorithm 4: draw a part, or replace the node by its children front-to-back.
    h.lastVisible = true;
    h.lastVisibleFrame = f.index;
    if (f.tree.isDrawable(ref)) {
        drawNode(f, ref, untested);
        return;
    }
    pushChildren(f, ref);
}

std::uint32_t QueryScheduler::countFrustumLeaves(const Frame& f) const {
    // The k-DOP paper's list L: leaves not outside the frustum, by a hierarchical walk of
    // both levels (no sorting, no screen projection).
    const LooseBsp& scene = f.tree.scene();
    const SceneObjects& objs = f.objects;
    std::uint32_t leaves = 0;
    std::vector<std::uint32_t> stack{scene.root()}, local;
    while (!stack.empty()) {
        const LooseBspNode& node = scene.nodes()[stack.back()];
        stack.pop_back();
        if (node.subtreeObjects == 0 || f.frustum().outside(node.box)) continue;
        for (std::uint32_t o = node.firstObject; o != kInvalidIndex; o = scene.nextObject(o)) {
            if (f.frustum().outside(objs.worldBox(o))) continue;
            const LocalBsp& model = objs.model(objs.modelOf(o));
            local.assign(1, 0);
            while (!local.empty()) {
                const std::uint32_t n = local.back();
                local.pop_back();
                const LocalBspNode& ln = model.nodes[n];
                if (n != 0 && (ln.indexCount == 0 || f.frustum().outside(transformAabb(objs.matrix(o), ln.box)))) continue;
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

void QueryScheduler::runVfc(Frame& f) {
    while (!active_.empty()) {
        const NodeRef ref = active_.back();
        active_.pop_back();
        ++f.stats.nodesVisited;
        if (f.frustum().outside(f.tree.worldBox(ref))) {
            ++f.stats.frustumCulled;
            f.note(ref, NodeState::FrustumCulled);
            continue;
        }
        NodeHistory& h = history_.at(ref, f.objects);
        h.lastTouchedFrame = f.index;
        f.note(ref, NodeState::VisibleVfc);
        processVisible(f, ref, h, false);
    }
}

void QueryScheduler::runSimple(Frame& f) {
    // Simple OC: hierarchical, one stop-and-wait query per node in the frustum.
    while (!active_.empty()) {
        const auto [ref, box, ft] = visitNearest(f);
        NodeHistory& h = history_.at(ref, f.objects);
        if (ft == FirstTest::Invisible) continue;
        if (ft == FirstTest::NeedQuery) {
            f.beginBatch();
            const QueryId id = f.issue(QueryVolume::fromAabb(box));
            f.endBatch();
            ++f.stats.batches;
            const QueryResult r = f.wait(id, params_.tuning.queryTimeoutMs);
            f.backend.release(id);
            if (r == QueryResult::NotReady) ++f.stats.queriesTimedOut;
            const bool visible = r != QueryResult::Occluded;
            history_.recordAnswer(h, visible, f.index);
            f.note(ref, box, visible ? NodeState::VisibleQueried : NodeState::Occluded);
            if (!visible) {
                ++f.stats.queriesOccluded;
                continue;
            }
        }
        processVisible(f, ref, h, false);
    }
}

}  // namespace dyncull
