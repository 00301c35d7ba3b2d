// Two-phase occlusion culling, the method of current GPU-driven engines (niagara, UE5
// Nanite, Bevy; see ../shared/notes/batched-occlusion-tests.md), on the two-level tree:
//  1. early pass: the parts visible last frame are drawn, frustum-culled;
//  2. their depth is read back into a farthest-depth pyramid (DepthPyramid);
//  3. late pass: the tree is traversed front to back, every node tested against the
//     pyramid (a rectangle and a depth, a few nanoseconds); an occluded node's subtree is
//     skipped;
//  4. the parts the pyramid let through are tested exactly, per pixel, in one batched
//     raster test against the early depth (NVIDIA's gl_occlusion_culling "temporal current
//     frame" scheme) and the visible ones drawn; then the parts drawn are tested against
//     the final depth, and those visible there are next frame's early set.
// Where the sink draws the parts itself, step 4 goes one level finer: the parts whose
// volumes passed are tested on their own triangles before they are drawn, and each draw
// marks whether it showed a sample, so the early set is the parts whose triangles, not
// volumes, were visible (the test on the geometry that the volume bound in
// docs/BENCHMARKS.md called for; no paper of ours has it).
// Which volumes are tested is the question of NOHC (Guthe et al. 2006: a query's cost
// against drawing's) and CHC++ (Mattausch et al. 2008: visible nodes only every few
// frames; both in ../shared/notes/batched-occlusion-tests.md): a cost model weighs a
// test's pixels against the part's triangles and the measured rate of tests that cull,
// and a part drawn early is tested again only when its visibility history says so.
// Conservative: whatever is not drawn was hidden behind depth that the final image also
// has (the early parts are drawn, and depth only grows nearer afterwards).
#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>
#include <cmath>

#include "dyncull/scheduler/query_scheduler.hpp"

namespace dyncull {

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }
}  // namespace

bool QueryScheduler::projectVolumeDepth(const QueryVolume& volume, ScreenRect& rect, float& nearestDepth) const {
    // The volume grown by the rounding of its float vertices, projected in double; any
    // point within the near-plane margin makes it "crossing" (visible), as in projectRect.
    std::array<glm::dvec3, QueryVolume::kMaxVertices> rel;
    bool asBox = false;
    const std::uint32_t n = volume.enlargedForRounding(glm::dvec3(camera_.position), rel, asBox);
    double magnitude = 0.0;
    for (std::uint32_t i = 0; i < n; ++i)
        magnitude = std::max({magnitude, std::abs(rel[i].x), std::abs(rel[i].y), std::abs(rel[i].z)});
    const double nearPlane = double(camera_.nearPlane);
    const double nearTest = nearPlane + 0x1p-21 * magnitude + 0x1p-22 * nearPlane;
    glm::dvec2 lo(1e300), hi(-1e300);
    double nearest = 0.0;
    for (std::uint32_t i = 0; i < n; ++i) {
        const glm::dvec4 clip = viewProj_ * glm::dvec4(rel[i], 1.0);
        if (viewDistance(clip, rel[i]) < nearTest) return false;
        const glm::dvec2 ndc = glm::dvec2(clip) / clip.w;
        lo = glm::min(lo, ndc);
        hi = glm::max(hi, ndc);
        nearest = std::max(nearest, clip.z / clip.w);
    }
    rect = pixelRect(lo, hi);
    nearestDepth = static_cast<float>(nearest);
    return true;
}

void QueryScheduler::runTwoPhase() {
    const SceneObjects& objs = tree_->objects();
    const NodeRef root = active_.empty() ? NodeRef{} : active_.back();
    const bool triangles = params_.features.useTriangleTests && sink_->testsTriangles();
    markedDraws_.clear();
    if (triangles) {
        sink_->beginDrawMarks();
        marking_ = true;
    }

    // 1. Early pass. lastTouchedFrame marks a part drawn in it.
    const std::uint32_t partsBefore = stats_->partsDrawn;
    while (!active_.empty()) {
        const NodeRef ref = active_.back();
        active_.pop_back();
        ++stats_->nodesVisited;
        if (frustum_.outside(tree_->worldBox(ref))) continue;
        NodeHistory& h = history_.at(ref, objs);
        if (!tree_->isDrawable(ref)) {
            pushChildren(ref);
            continue;
        }
        if (h.lastVisible && h.lastVisibleFrame + 1 == frame_) {
            trace(ref, tree_->worldBox(ref), NodeState::VisibleHistory);  // drawn untested
            drawNode(ref, false);
            h.lastTouchedFrame = frame_;
        }
    }

    const bool drewEarly = stats_->partsDrawn > partsBefore;

    // 2. The early pass's depth, unless the cost model turned this frame's tests off. A
    // backend that cannot read depth leaves the pyramid unbuilt, and an unbuilt pyramid
    // calls nothing occluded.
    const bool testing = !params_.features.useCostModel || savedNs_ > params_.tuning.costs.depthReadNs ||
                         frame_ - lastTestedFrame_ >= params_.tuning.costs.probeFrames;
    culledTriangles_ = 0;
    bool haveDepth = false;
    if (testing) {
        const auto t0 = Clock::now();
        int w = 0, hgt = 0;
        haveDepth = backend_->readDepth(depth_, w, hgt) && w == width_ && hgt == height_;
        if (haveDepth) pyramid_.build(depth_, w, hgt);
        clusterPyramid_ = haveDepth;  // the late pass's draws test their clusters against it too
        stats_->depthReadMs += msSince(t0);
    }

    // 3. Late pass. Parts the pyramid cannot reject are either drawn at once or, with the
    // batched raster test, collected in `candidates_` and tested exactly afterwards; the
    // parts drawn early are collected in `refresh_` to be tested against the final depth.
    candidates_.clear();
    refresh_.clear();
    triangleTests_.clear();
    const bool raster = params_.features.useBatchedRaster && testing;
    if (!(root == NodeRef{})) active_.push_back(root);
    while (!active_.empty()) {
        const NodeRef ref = active_.back();
        active_.pop_back();
        ++stats_->nodesVisited;
        const Aabb box = tree_->worldBox(ref);
        NodeHistory& h = history_.at(ref, objs);
        // A part drawn in the early pass is still tested (for next frame) but was decided
        // there: its trace entry is the early one.
        const bool drawnEarly = tree_->isDrawable(ref) && h.lastTouchedFrame == frame_;
        auto note = [&](NodeState state) {
            if (!drawnEarly) trace(ref, box, state);
        };
        if (frustum_.outside(box)) {
            ++stats_->frustumCulled;
            h.lastVisible = false;
            note(NodeState::FrustumCulled);
            continue;
        }
        ScreenRect rect;
        float nearest = 1.0f;
        // Object nodes by their own volume (a transformed box or k-DOP, tighter than the
        // world box of a rotated part), scene nodes by their box; both grown by rounding.
        const QueryVolume volume = ref.isSceneNode() || !params_.features.useTightVolumes
                                       ? QueryVolume::fromAabb(box)
                                       : objectNodeVolume(objs, ref, params_.tuning.volume, params_.tuning.autoVolumeSaving);
        const bool inFront = projectVolumeDepth(volume, rect, nearest);
        bool certain = false;  // visible without any test (near plane, camera inside)
        if (!inFront || box.contains(camera_.position)) {
            ++stats_->visibleNearOrInside;
            certain = true;
        } else if (rect.empty()) {
            ++stats_->frustumCulled;
            h.lastVisible = false;
            note(NodeState::FrustumCulled);
            continue;
        } else if (haveDepth) {
            ++stats_->depthTests;
            if (pyramid_.occluded(rect, nearest)) {
                ++stats_->queriesOccluded;
                culledTriangles_ += subtreeTriangles(ref);
                history_.recordAnswer(h, false, frame_);
                note(NodeState::Occluded);
                continue;
            }
        }
        h.lastVisible = true;
        h.lastVisibleFrame = frame_;
        if (!tree_->isDrawable(ref)) {
            note(certain ? NodeState::VisibleNear : NodeState::VisibleQueried);
            pushChildren(ref);
        } else if (drawnEarly) {
            if (!raster || certain || triangles) continue;  // marks answer for it with triangles
            // Visibility history, as in Queries: a part that kept answering "visible" is
            // tested again only after the frames its answers earn. The cost model may
            // postpone it further, but not past history's longest postponement, so every
            // part is tested now and then and the rate of culling tests stays measured.
            const std::uint32_t sinceAnswer = frame_ - h.lastQueryFrame;
            if (params_.features.useHistory && sinceAnswer <= history_.postponement(ref, h, params_.tuning.history)) {
                ++stats_->skippedByHistory;
            } else if (sinceAnswer <= params_.tuning.history.maxSkipFrames && !worthTesting(ref, rect, refreshOccludedRate_)) {
                ++stats_->skippedByCost;
            } else {
                refresh_.push_back({ref, volume});
            }
        } else if (raster && !certain && (worthTesting(ref, rect, candidateOccludedRate_) || exploring(ref))) {
            candidates_.push_back({ref, volume});
        } else {
            if (raster && !certain) ++stats_->skippedByCost;
            note(certain ? NodeState::VisibleNear : testing && !raster ? NodeState::VisibleQueried : NodeState::VisibleCheaper);
            drawNode(ref, false);
        }
    }

    // 4. The batched raster test, exact per pixel against the early pass's depth, for the
    // parts the pyramid let through; then every part drawn after a test (early, or late
    // after this one) against the final depth: one hidden there is not drawn early next
    // frame (the first frame, which has no early set, would otherwise draw everything twice).
    // The rates the cost model sees move a quarter of the way to each batch's answers.
    auto learn = [](double& rate, const std::vector<QueryResult>& answers) {
        const auto occluded = std::count(answers.begin(), answers.end(), QueryResult::Occluded);
        rate += 0.25 * (double(occluded) / double(answers.size()) - rate);
    };
    if (!candidates_.empty()) {
        rasterTest(candidates_);
        learn(candidateOccludedRate_, rasterAnswers_);
        for (std::size_t i = 0; i < candidates_.size(); ++i) {
            const NodeRef ref = candidates_[i].ref;
            NodeHistory& h = history_.at(ref, objs);
            if (rasterAnswers_[i] == QueryResult::Occluded) {
                ++stats_->queriesOccluded;
                culledTriangles_ += subtreeTriangles(ref);
                history_.recordAnswer(h, false, frame_);
                trace(ref, tree_->worldBox(ref), NodeState::Occluded);
            } else if (triangles && (worthTriangleTest(ref) || exploring(ref))) {
                const LocalBspNode& n = objs.model(objs.modelOf(ref.object)).nodes[ref.node];
                triangleTests_.push_back({ref, n.firstIndex, n.indexCount});
            } else {
                trace(ref, tree_->worldBox(ref), NodeState::VisibleQueried);
                drawNode(ref, false);
                if (!triangles) refresh_.push_back(candidates_[i]);  // may be hidden by parts drawn after it
            }
        }
    }
    if (!triangleTests_.empty()) testTriangles();
    if (triangles) readDrawMarks();
    if (!refresh_.empty()) {
        rasterTest(refresh_);
        learn(refreshOccludedRate_, rasterAnswers_);
        for (std::size_t i = 0; i < refresh_.size(); ++i) {
            const bool visible = rasterAnswers_[i] != QueryResult::Occluded;
            if (!visible) culledTriangles_ += subtreeTriangles(refresh_[i].ref);  // not drawn early next frame
            history_.recordAnswer(history_.at(refresh_[i].ref, objs), visible, frame_);
        }
    }
    // A frame with no early depth (the first, or after everything turned hidden) had
    // nothing to test the pyramid against, so only the final-depth tests measured what
    // testing saves; without them the frame says nothing and the estimate stands.
    if (testing && (drewEarly || !refresh_.empty() || triangles)) {
        lastTestedFrame_ = frame_;
        savedNs_ = double(culledTriangles_) * params_.tuning.costs.drawNsPerTriangle;
    }
}

void QueryScheduler::testTriangles() {
    const SceneObjects& objs = tree_->objects();
    const auto t0 = Clock::now();
    triangleAnswers_.assign(triangleTests_.size(), QueryResult::Visible);
    sink_->testParts(triangleTests_, triangleAnswers_);
    stats_->triangleTests += static_cast<std::uint32_t>(triangleTests_.size());
    stats_->triangleTestMs += msSince(t0);
    const auto occluded = std::count(triangleAnswers_.begin(), triangleAnswers_.end(), QueryResult::Occluded);
    triangleOccludedRate_ += 0.25 * (double(occluded) / double(triangleTests_.size()) - triangleOccludedRate_);
    for (std::size_t i = 0; i < triangleTests_.size(); ++i) {
        const NodeRef ref = triangleTests_[i].part;
        if (triangleAnswers_[i] == QueryResult::Occluded) {
            ++stats_->queriesOccluded;
            culledTriangles_ += triangleTests_[i].indexCount / 3;
            history_.recordAnswer(history_.at(ref, objs), false, frame_);
            trace(ref, tree_->worldBox(ref), NodeState::Occluded);
        } else {
            trace(ref, tree_->worldBox(ref), NodeState::VisibleQueried);
            drawNode(ref, false);  // its draw mark says whether it stays visible
        }
    }
}

void QueryScheduler::readDrawMarks() {
    const SceneObjects& objs = tree_->objects();
    const auto t0 = Clock::now();
    triangleAnswers_.assign(markedDraws_.size(), QueryResult::Visible);
    if (!markedDraws_.empty()) sink_->readDrawMarks(triangleAnswers_);
    stats_->triangleTestMs += msSince(t0);
    // A draw that showed nothing was hidden by what was drawn before it, and stays hidden
    // (depth only grows nearer): not drawn early next frame. One that showed a sample may
    // have been covered later; it is drawn early and marked again.
    for (std::size_t i = 0; i < markedDraws_.size(); ++i) {
        const NodeRef ref = markedDraws_[i];
        const bool visible = triangleAnswers_[i] != QueryResult::Occluded;
        if (!visible) {
            ++stats_->drawMarksHidden;
            culledTriangles_ += subtreeTriangles(ref);
        }
        history_.recordAnswer(history_.at(ref, objs), visible, frame_);
    }
    marking_ = false;
}

bool QueryScheduler::worthTriangleTest(NodeRef ref) {
    if (!params_.features.useCostModel) return true;
    const TestCosts& c = params_.tuning.costs;
    const double triangles = double(subtreeTriangles(ref));
    return triangleOccludedRate_ * triangles * c.drawNsPerTriangle > c.triangleTestNsPerPart + triangles * c.triangleTestNsPerTriangle;
}

bool QueryScheduler::worthTesting(NodeRef ref, const ScreenRect& rect, double occludedRate) {
    if (!params_.features.useCostModel) return true;
    const TestCosts& c = params_.tuning.costs;
    return occludedRate * double(subtreeTriangles(ref)) * c.drawNsPerTriangle > c.testNsPerVolume + c.testNsPerPixel * rect.area();
}

std::uint64_t QueryScheduler::subtreeTriangles(NodeRef ref) {
    const SceneObjects& objs = tree_->objects();
    auto objectTriangles = [&](std::uint32_t object, std::uint32_t node) {
        const LocalBsp& model = objs.model(objs.modelOf(object));
        // A bounds model's one part is the game's whole object: count what drawing it costs.
        if (model.drawTriangles > 0) return std::uint64_t{model.drawTriangles};
        return std::uint64_t{model.nodes[node].indexCount / 3};
    };
    if (!ref.isSceneNode()) return objectTriangles(ref.object, ref.node);
    const LooseBsp& scene = tree_->scene();
    std::uint64_t triangles = 0;
    scratchIndices_.assign(1, ref.node);
    while (!scratchIndices_.empty()) {
        const LooseBspNode& n = scene.nodes()[scratchIndices_.back()];
        scratchIndices_.pop_back();
        for (std::uint32_t o = n.firstObject; o != kInvalidIndex; o = scene.nextObject(o)) triangles += objectTriangles(o, 0);
        if (!n.isLeaf()) scratchIndices_.insert(scratchIndices_.end(), {n.children[0], n.children[1]});
    }
    return triangles;
}

bool QueryScheduler::exploring(NodeRef ref) const {
    // One new part in eight, a different eighth each frame, is tested whatever the model
    // expects, so a rate that fell while nothing was occluded can rise again.
    return ((hashNode(ref) >> 5) + frame_) % 8 == 0;
}

void QueryScheduler::rasterTest(const std::vector<TestedPart>& parts) {
    const auto t0 = Clock::now();
    rasterVolumes_.clear();
    for (const TestedPart& p : parts) rasterVolumes_.push_back(p.volume);
    rasterAnswers_.assign(parts.size(), QueryResult::Visible);
    const BatchId batch = backend_->testVolumes(rasterVolumes_);
    if (batch != kNoBatch) {
        backend_->collectVolumes(batch, rasterAnswers_, params_.tuning.queryTimeoutMs);  // nothing else to do meanwhile
        ++stats_->rasterBatches;
        stats_->rasterTests += static_cast<std::uint32_t>(parts.size());
    }
    stats_->rasterMs += msSince(t0);
}

}  // namespace dyncull
