// Two-phase occlusion culling, the method of current GPU-driven engines (niagara, UE5
// Nanite, Bevy; see ../shared/notes/batched-occlusion-tests.md), on the two-level tree:
//  1. early pass: the parts visible last frame are drawn, frustum-culled;
//  2. their depth is read back into a farthest-depth pyramid (DepthPyramid);
//  3. late pass: the tree is traversed front to back, every node tested against the
//     pyramid (a rectangle and a depth, a few nanoseconds; where that cannot decide, texel
//     by texel, the volume's depth bounded by its front faces' planes); an occluded node's
//     subtree is skipped;
//  4. the parts the pyramid let through are tested again against a pyramid of the depth
//     after the early parts' deferred clusters are drawn (the surfaces newly in view, which
//     hide most of them), and those left exactly, per pixel, in batched raster
//     tests (NVIDIA's gl_occlusion_culling "temporal current frame" scheme), in rounds
//     front to back, each against the depth drawn before it, and the visible ones drawn
//     (their clusters against a pyramid built again from that depth, where it pays); then
//     the parts drawn are tested against the final depth, and those visible there are
//     next frame's early set.
// Where the sink draws clusters, the early set is kept per cluster: a part drawn early is
// drawn as only the clusters whose boxes showed in the final depth of the frame it was last
// drawn in, and its other clusters are tested against the pyramid in the late pass
// (cluster_history.cpp).
// Where the sink draws the parts itself, step 4 can go one level finer: the parts whose
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
#include <cassert>
#include <cmath>

#include "cluster_selection.hpp"

namespace dyncull {

void QueryScheduler::runTwoPhase(Frame& f) {
    const NodeRef root = active_.empty() ? NodeRef{} : active_.back();
    const bool triangles = params_.features.useTriangleTests && f.sink.testsTriangles();
    markedDraws_.clear();
    if (triangles) {
        f.sink.beginDrawMarks();
        f.marking = true;
    }

    // The cost model may turn this frame's tests off. Every probeFrames frames it probes
    // whether they would pay again: at the frame's end, testing every part drawn against
    // a pyramid of the final depth (testOnFinalPyramid: a depth read that waits for nothing
    // the frame's end does not wait for, and no early pass's stall); or, where the sink
    // tests triangles, with a frame that tests.
    const bool pays = !params_.features.useCostModel || savedNs_ > params_.tuning.costs.depthReadNs;
    const bool probeDue = !pays && f.index - lastTestedFrame_ >= params_.tuning.costs.probeFrames;
    f.probeAtEnd = probeDue && params_.features.useEndProbes && !triangles;
    const bool testing = pays || (probeDue && !f.probeAtEnd);
    // Unless this frame does not test, its early parts draw only the clusters that showed
    // last frame (cluster history).
    deferredParts_.clear();
    clusterParts_.clear();
    clusterPartLearned_.clear();
    learnedClusters_.clear();
    deferredTriangles_ = 0;
    const bool clusterHistory =
        testing && params_.features.useClusterHistory && params_.features.useClusters && !triangles && f.sink.drawsRanges();
    // Its own cost model: the bits are recorded while what they saved the frame after
    // (deferred triangles the late pass did not draw) exceeds what recording them cost, and
    // every probeFrames frames to measure that again.
    f.useClusterBits = clusterHistory && lastClusterRecordFrame_ + 1 == f.index;
    f.recordClusterBits = clusterHistory && (!params_.features.useCostModel || clusterBitsSavedNs_ > clusterRecordNs_ ||
                                             f.index - lastClusterRecordFrame_ >= params_.tuning.costs.probeFrames);
    // Recorded from the draws' own fragments where the sink can mark each cluster drawn.
    f.markClusters = f.recordClusterBits && params_.features.useClusterMarks && f.sink.marksRanges();
    markedClusters_.clear();
    if (f.markClusters) f.sink.beginRangeMarks();

    // 1. Early pass, in a frame that tests. A frame that does not has one traversal, which
    // draws everything front to back as vfc does: last frame's parts drawn first would
    // change only the order, and a worse order costs overdraw.
    bool drewEarly = false;
    if (testing) {
        drewEarly = drawEarlySet(f);
    } else {
        active_.clear();
    }

    // 2. The early pass's depth, unless this frame does not test. A backend that cannot
    // read depth leaves the pyramid unbuilt, and an unbuilt pyramid calls nothing occluded.
    culledTriangles_ = 0;
    bool haveDepth = false;
    if (testing) {
        haveDepth = buildPyramid(f);
        f.clusterPyramid = haveDepth;  // the late pass's draws test their clusters against it too
    }
    // The early parts' deferred clusters depend only on this pyramid: a worker selects
    // them while the late pass traverses and draws.
    if (f.clusterPyramid) startDeferredSelection(f);

    // 3. Late pass.
    candidates_.clear();
    candidateFootprints_.clear();
    candidateMargins_.clear();
    candidateMarginNs_ = 0.0;
    refresh_.clear();
    triangleTests_.clear();
    if (!(root == NodeRef{})) {
        active_.push_back(root);
        lateTraversal(f, testing, haveDepth, triangles);
    }
    // The early parts' clusters that were hidden last frame, where the pyramid lets them
    // through: drawn before the raster tests, whose depth they make nearer.
    if (!deferredParts_.empty()) drawDeferredClusters(f);
    joinDeferredSelection();  // the worker, done by now, never outlives the late pass
    if (f.useClusterBits) clusterBitsSavedNs_ = double(deferredTriangles_) * params_.tuning.costs.drawNsPerTriangle;

    // 4. The batched raster test, exact per pixel against the depth drawn so far, for the
    // parts the pyramid let through (first tested again against a pyramid of the depth the
    // deferred clusters drew, which hides most of them); then every part drawn after a test (early, or late
    // after this one) against the final depth: one hidden there is not drawn early next
    // frame (the first frame, which has no early set, would otherwise draw everything twice).
    if (!candidates_.empty()) testCandidatesOnLateDepth(f);
    if (!candidates_.empty()) testCandidates(f, triangles);
    if (!triangleTests_.empty()) testTriangles(f);
    if (triangles) readDrawMarks(f);
    const bool refreshOnPyramid = params_.features.useRefreshPyramid && f.recordClusterBits && !f.markClusters && !budgetTakesEarlySet();
    if (f.probeAtEnd) {
        testOnFinalPyramid(f);
    } else if (!refresh_.empty() && !(refreshOnPyramid && testOnFinalPyramid(f))) {
        testRefresh(f);
    }
    if (f.markClusters) {
        readClusterMarks(f);  // also ends the sink's marking
    } else if (f.recordClusterBits && !clusterParts_.empty()) {
        recordClusterVisibility(f);
    }
    // A frame with no early depth (the first, or after everything turned hidden) had
    // nothing to test the pyramid against, so only the final-depth tests measured what
    // testing saves; without them the frame says nothing and the estimate stands.
    if ((testing && (drewEarly || !refresh_.empty() || triangles)) || f.probeAtEnd) {
        lastTestedFrame_ = f.index;
        savedNs_ = double(culledTriangles_) * params_.tuning.costs.drawNsPerTriangle;
    }
}

void QueryScheduler::splitDrawWait(Frame& f) {
    if (!params_.tuning.splitDrawWaits) return;
    const auto t0 = SchedulerClock::now();
    f.backend.finishDrawing();
    f.stats.drawWaitMs += msSince(t0);
}

bool QueryScheduler::buildPyramid(Frame& f) {
    const auto t0 = SchedulerClock::now();
    splitDrawWait(f);
    int w = 0, h = 0;
    const bool haveDepth = f.backend.readDepth(depth_, w, h) && w == f.view.width && h == f.view.height;
    if (haveDepth) pyramid_.adopt(depth_, w, h);  // depth_ gets the old level 0 back for the next read
    f.stats.pyramidBuilds += haveDepth;
    pyramidView_.reset();
    if (haveDepth) pyramidView_ = f.view;
    f.stats.depthReadMs += msSince(t0);
    return haveDepth;
}

bool QueryScheduler::drawEarlySet(Frame& f) {
    // lastTouchedFrame marks a part drawn here.
    const std::uint32_t partsBefore = f.stats.partsDrawn;
    const std::uint64_t trianglesBefore = f.stats.trianglesDrawn;
    while (!active_.empty()) {
        const NodeRef ref = active_.back();
        active_.pop_back();
        ++f.stats.nodesVisited;
        if (f.frustum().outside(f.tree.worldBox(ref))) continue;
        NodeHistory& h = history_.at(ref, f.objects);
        if (!f.tree.isDrawable(ref)) {
            pushChildren(f, ref);
            continue;
        }
        if (h.lastVisible && h.lastVisibleFrame + 1 == f.index) {
            f.note(ref, NodeState::VisibleHistory);  // drawn untested
            drawNode(f, ref, false, f.useClusterBits ? ClusterPass::Early : ClusterPass::All);
            h.lastTouchedFrame = f.index;
        }
    }
    f.stats.earlyTriangles += f.stats.trianglesDrawn - trianglesBefore;
    return f.stats.partsDrawn > partsBefore;
}

void QueryScheduler::lateTraversal(Frame& f, bool testing, bool haveDepth, bool triangles) {
    // Parts the pyramid cannot reject are either drawn at once or, with the batched raster
    // test, collected in `candidates_` and tested exactly afterwards; the parts drawn early
    // are collected in `refresh_` to be tested against the final depth.
    const SceneObjects& objs = f.objects;
    const bool raster = params_.features.useBatchedRaster && testing;
    while (!active_.empty()) {
        const NodeRef ref = active_.back();
        active_.pop_back();
        ++f.stats.nodesVisited;
        const Aabb box = f.tree.worldBox(ref);
        NodeHistory& h = history_.at(ref, objs);
        // A part drawn in the early pass is still tested (for next frame) but was decided
        // there: its trace entry is the early one.
        const bool drawnEarly = f.tree.isDrawable(ref) && h.lastTouchedFrame == f.index;
        auto note = [&](NodeState state) {
            if (!drawnEarly) f.note(ref, box, state);
        };
        if (f.frustum().outside(box)) {
            ++f.stats.frustumCulled;
            h.lastVisible = false;
            note(NodeState::FrustumCulled);
            continue;
        }
        // Object nodes by their own volume (a transformed box or k-DOP, tighter than the
        // world box of a rotated part), scene nodes by their box; both grown by rounding.
        DepthFootprint fp;
        const auto tTest = params_.tuning.splitDrawWaits ? SchedulerClock::now() : SchedulerClock::time_point{};
        const bool inFront = testedFootprint(f, ref, fp, false);
        const ScreenRect& rect = fp.rect;
        bool certain = false;  // visible without any test (near plane, camera inside)
        if (!inFront || box.contains(f.camera().position)) {
            ++f.stats.visibleNearOrInside;
            certain = true;
        } else if (rect.empty()) {
            ++f.stats.frustumCulled;
            h.lastVisible = false;
            note(NodeState::FrustumCulled);
            continue;
        } else if (haveDepth) {
            ++f.stats.depthTests;
            const bool occluded = pyramidHides(f, ref, fp);
            if (params_.tuning.splitDrawWaits) f.stats.pyramidTestMs += msSince(tTest);
            if (occluded) {
                ++f.stats.queriesOccluded;
                culledTriangles_ += subtreeTriangles(f, ref);
                history_.recordAnswer(h, false, f.index);
                note(NodeState::Occluded);
                continue;
            }
        }
        h.lastVisible = true;
        h.lastVisibleFrame = f.index;
        if (!f.tree.isDrawable(ref)) {
            note(certain ? NodeState::VisibleNear : NodeState::VisibleQueried);
            pushChildren(f, ref);
        } else if (drawnEarly) {
            if (!raster || certain || triangles) continue;  // marks answer for it with triangles
            // Visibility history, as in Queries: a part that kept answering "visible" is
            // tested again only after the frames its answers earn. The cost model may
            // postpone it further, but not past history's longest postponement, so every
            // part is tested now and then and the rate of culling tests stays measured.
            const std::uint32_t sinceAnswer = f.index - h.lastQueryFrame;
            if (params_.features.useHistory && sinceAnswer <= history_.postponement(ref, h, params_.tuning.history)) {
                ++f.stats.skippedByHistory;
            } else if (sinceAnswer <= params_.tuning.history.maxSkipFrames && !worthTesting(f, ref, rect, refreshOccludedRate_)) {
                ++f.stats.skippedByCost;
            } else {
                refresh_.push_back(ref);
            }
        } else if (const double margin = raster && !certain ? testMarginNs(f, ref, rect, candidateOccludedRate_) : 0.0;
                   raster && !certain && (!params_.features.useCostModel || margin > 0.0 || exploring(ref))) {
            candidates_.push_back(ref);
            candidateFootprints_.push_back(fp);
            candidateMargins_.push_back(std::max(margin, 0.0));  // an exploring part rides along where the round pays
            candidateMarginNs_ += std::max(margin, 0.0);
        } else {
            if (raster && !certain) ++f.stats.skippedByCost;
            note(certain ? NodeState::VisibleNear : testing && !raster ? NodeState::VisibleQueried : NodeState::VisibleCheaper);
            drawNode(f, ref, false);
            if (f.probeAtEnd && !certain) refresh_.push_back(ref);
        }
    }

}

namespace {
/// The cost model's rate of "occluded" answers moves a quarter of the way to a batch's.
void learnOccludedRate(double& rate, std::size_t occluded, std::size_t answers) {
    rate += 0.25 * (double(occluded) / double(answers) - rate);
}
void learnOccludedRate(double& rate, const std::vector<QueryResult>& answers) {
    learnOccludedRate(rate, static_cast<std::size_t>(std::count(answers.begin(), answers.end(), QueryResult::Occluded)), answers.size());
}
}  // namespace

void QueryScheduler::testCandidates(Frame& f, bool triangles) {
    const bool budget = params_.approx.errorBudgetPercent > 0.0;
    if (!budget) {
        // In rounds, front to back (the traversal's order): a later round is tested against
        // the depth of the earlier rounds' visible parts too; as many as pay.
        const std::size_t rounds = candidateRoundsPaid(f);
        if (rounds == 0) {
            // Cheaper drawn than tested: settled as if every answer were "visible", so they
            // are drawn and tested for next frame against the final depth.
            f.stats.skippedByCost += static_cast<std::uint32_t>(candidates_.size());
            rasterAnswers_.assign(candidates_.size(), QueryResult::Visible);
            budgetCulled_.assign(candidates_.size(), kBudgetNo);
            settleCandidates(f, triangles, false);
            return;
        }
        lastCandidateBatchFrame_ = f.index;
        allCandidates_.swap(candidates_);
        for (std::size_t r = 0; r < rounds; ++r) {
            const std::size_t begin = allCandidates_.size() * r / rounds, end = allCandidates_.size() * (r + 1) / rounds;
            candidates_.assign(allCandidates_.begin() + std::ptrdiff_t(begin), allCandidates_.begin() + std::ptrdiff_t(end));
            rasterTest(f, candidates_, false);
            budgetCulled_.assign(candidates_.size(), kBudgetNo);
            learnOccludedRate(candidateOccludedRate_, rasterAnswers_);
            refreshClusterPyramid(f);
            settleCandidates(f, triangles);
        }
        return;
    }
    rasterTest(f, candidates_, true);
    budgetCulled_.assign(candidates_.size(), kBudgetNo);
    if (!params_.approx.budgetRecount) {
        spendErrorBudget(f);
        learnOccludedRate(candidateOccludedRate_, rasterAnswers_);  // budget culls save drawing too
        refreshClusterPyramid(f);
        settleCandidates(f, triangles);
        return;
    }
    // The candidates small enough to fit in the budget wait until the others are drawn,
    // and are counted again against that nearer depth: they show fewer samples there
    // (often none), so the same budget takes more of them.
    const std::uint64_t budgetPixels = errorBudgetPixels(f);
    waitingParts_.clear();
    for (std::size_t i = 0; i < candidates_.size(); ++i)
        if (rasterAnswers_[i] != QueryResult::Occluded && rasterSamples_[i] <= budgetPixels) {
            budgetCulled_[i] = kBudgetLater;
            waitingParts_.push_back(candidates_[i]);
        }
    learnOccludedRate(candidateOccludedRate_, rasterAnswers_);
    refreshClusterPyramid(f);
    settleCandidates(f, triangles);
    if (waitingParts_.empty()) return;
    candidates_.swap(waitingParts_);
    rasterTest(f, candidates_, true);
    budgetCulled_.assign(candidates_.size(), kBudgetNo);
    spendErrorBudget(f);
    refreshClusterPyramid(f);
    settleCandidates(f, triangles);
}

void QueryScheduler::testCandidatesOnLateDepth(Frame& f) {
    // The deferred clusters are what came into view since last frame, in front of much
    // that the early depth did not hide. Their depth costs a read (the raster test would
    // wait for the same drawing) and a build; each candidate it hides saves a raster test.
    if (!params_.features.useLatePyramid || !f.clusterPyramid || f.stats.deferredClustersDrawn == 0) return;
    assert(candidateFootprints_.size() == candidates_.size() && candidateMargins_.size() == candidates_.size());
    const TestCosts& c = params_.tuning.costs;
    if (params_.features.useCostModel &&
        double(candidates_.size()) * c.testNsPerVolume * candidateOccludedRate_ <= c.pyramidNs)
        return;
    f.clusterPyramid = buildPyramid(f);  // the parts drawn after it test their clusters against it too
    if (!f.clusterPyramid) return;
    std::size_t kept = 0;
    candidateMarginNs_ = 0.0;
    for (std::size_t i = 0; i < candidates_.size(); ++i) {
        const NodeRef ref = candidates_[i];
        ++f.stats.depthTests;
        if (pyramidHides(f, ref, candidateFootprints_[i])) {
            ++f.stats.queriesOccluded;
            culledTriangles_ += subtreeTriangles(f, ref);
            history_.recordAnswer(history_.at(ref, f.objects), false, f.index);
            f.note(ref, NodeState::Occluded);
            continue;
        }
        candidates_[kept] = ref;
        candidateMarginNs_ += candidateMargins_[i];
        ++kept;
    }
    // The model's rate is of every candidate, hidden here or by the raster test.
    learnOccludedRate(candidateOccludedRate_, candidates_.size() - kept, candidates_.size());
    candidates_.resize(kept);
}

void QueryScheduler::refreshClusterPyramid(Frame& f) {
    // The raster test's answers waited for everything drawn before it, so the read only
    // copies. The deferred clusters' worker, which reads the pyramid, is joined by now.
    if (!params_.features.useRoundPyramids || !f.clusterPyramid || !params_.features.useClusters || !f.sink.drawsRanges()) return;
    std::uint64_t triangles = 0;
    for (std::size_t i = 0; i < candidates_.size(); ++i)
        if (rasterAnswers_[i] != QueryResult::Occluded && budgetCulled_[i] == kBudgetNo) triangles += subtreeTriangles(f, candidates_[i]);
    const TestCosts& c = params_.tuning.costs;
    if (params_.features.useCostModel && double(triangles) * c.drawNsPerTriangle * c.roundPyramidCulls <= c.pyramidNs) return;
    f.clusterPyramid = buildPyramid(f);
}

std::size_t QueryScheduler::candidateRoundsPaid(const Frame& f) const {
    const std::size_t rounds = std::min<std::size_t>(params_.tuning.candidateRounds, candidates_.size());
    const TestCosts& c = params_.tuning.costs;
    if (!params_.features.useCostModel || c.testNsPerBatch == 0.0) return rounds;
    const double paid = std::floor(candidateMarginNs_ / c.testNsPerBatch);
    if (paid >= 1.0) return static_cast<std::size_t>(std::min(paid, double(rounds)));
    return f.index - lastCandidateBatchFrame_ >= c.probeFrames ? 1 : 0;
}

void QueryScheduler::settleCandidates(Frame& f, bool triangles, bool tested) {
    const SceneObjects& objs = f.objects;
    const std::uint64_t trianglesBefore = f.stats.trianglesDrawn;
    for (std::size_t i = 0; i < candidates_.size(); ++i) {
        const NodeRef ref = candidates_[i];
        NodeHistory& h = history_.at(ref, objs);
        if (budgetCulled_[i] == kBudgetLater) continue;
        if (budgetCulled_[i] == kBudgetCulled) {
            // Not visible next frame either, so it is tested again then.
            ++f.stats.budgetCulled;
            culledTriangles_ += subtreeTriangles(f, ref);
            history_.recordAnswer(h, false, f.index);
            f.note(ref, NodeState::BudgetCulled);
        } else if (rasterAnswers_[i] == QueryResult::Occluded) {
            ++f.stats.queriesOccluded;
            culledTriangles_ += subtreeTriangles(f, ref);
            history_.recordAnswer(h, false, f.index);
            f.note(ref, NodeState::Occluded);
        } else if (triangles && (worthTriangleTest(f, ref) || exploring(ref))) {
            const LocalBspNode& n = objs.model(objs.modelOf(ref.object)).nodes[ref.node];
            triangleTests_.push_back({ref, n.firstIndex, n.indexCount});
        } else {
            f.note(ref, tested ? NodeState::VisibleQueried : NodeState::VisibleCheaper);
            drawNode(f, ref, false);
            if (!triangles) refresh_.push_back(candidates_[i]);  // may be hidden by parts drawn after it
        }
    }
    f.stats.testedTriangles += f.stats.trianglesDrawn - trianglesBefore;
}

void QueryScheduler::testRefresh(Frame& f) {
    const SceneObjects& objs = f.objects;
    // With an error budget, a part that shows so little that the budget could take it is
    // left out of next frame's early set, so that it is a candidate the budget may cull
    // then (drawn this frame, it costs no error now).
    const bool budget = budgetTakesEarlySet();
    const std::uint64_t budgetPixels = errorBudgetPixels(f);
    rasterTest(f, refresh_, budget);
    learnOccludedRate(refreshOccludedRate_, rasterAnswers_);
    for (std::size_t i = 0; i < refresh_.size(); ++i) {
        const bool visible = rasterAnswers_[i] != QueryResult::Occluded &&
                             !(budget && rasterSamples_[i] != kUnknownSamples && rasterSamples_[i] <= budgetPixels);
        if (!visible) culledTriangles_ += subtreeTriangles(f, refresh_[i]);  // not drawn early next frame
        history_.recordAnswer(history_.at(refresh_[i], objs), visible, f.index);
    }
}

bool QueryScheduler::readFinalPyramid(Frame& f) {
    if (!f.finalPyramid) f.finalPyramid = buildPyramid(f);
    return f.finalPyramid;
}

bool QueryScheduler::testOnFinalPyramid(Frame& f) {
    // A part drawn whose volume is behind the final depth would have been culled by a
    // frame that tests, or leaves the early set: what testing saves, as the late pass's
    // first test measures it. Its own fragments are in that depth, never behind its
    // volume's nearest point, so a part that shows is never called hidden.
    if (refresh_.empty()) return true;
    if (!readFinalPyramid(f)) return false;
    std::size_t hiddenParts = 0;
    for (const NodeRef ref : refresh_) {
        DepthFootprint fp;
        ++f.stats.depthTests;
        const bool hidden = testedFootprint(f, ref, fp, false) && !fp.rect.empty() && pyramidHides(f, ref, fp);
        if (hidden) culledTriangles_ += subtreeTriangles(f, ref);
        hiddenParts += hidden;
        history_.recordAnswer(history_.at(ref, f.objects), !hidden, f.index);
    }
    // A probe's parts are every part drawn, not those drawn early: their rate is not the
    // refresh's.
    if (!f.probeAtEnd) learnOccludedRate(refreshOccludedRate_, hiddenParts, refresh_.size());
    return true;
}

void QueryScheduler::testTriangles(Frame& f) {
    const SceneObjects& objs = f.objects;
    const auto t0 = SchedulerClock::now();
    triangleAnswers_.assign(triangleTests_.size(), QueryResult::Visible);
    f.sink.testParts(triangleTests_, triangleAnswers_);
    f.stats.triangleTests += static_cast<std::uint32_t>(triangleTests_.size());
    f.stats.triangleTestMs += msSince(t0);
    const auto occluded = std::count(triangleAnswers_.begin(), triangleAnswers_.end(), QueryResult::Occluded);
    triangleOccludedRate_ += 0.25 * (double(occluded) / double(triangleTests_.size()) - triangleOccludedRate_);
    for (std::size_t i = 0; i < triangleTests_.size(); ++i) {
        const NodeRef ref = triangleTests_[i].part;
        if (triangleAnswers_[i] == QueryResult::Occluded) {
            ++f.stats.queriesOccluded;
            culledTriangles_ += triangleTests_[i].indexCount / 3;
            history_.recordAnswer(history_.at(ref, objs), false, f.index);
            f.note(ref, NodeState::Occluded);
        } else {
            f.note(ref, NodeState::VisibleQueried);
            drawNode(f, ref, false);  // its draw mark says whether it stays visible
        }
    }
}

void QueryScheduler::readDrawMarks(Frame& f) {
    const SceneObjects& objs = f.objects;
    const auto t0 = SchedulerClock::now();
    triangleAnswers_.assign(markedDraws_.size(), QueryResult::Visible);
    if (!markedDraws_.empty()) f.sink.readDrawMarks(triangleAnswers_);
    f.stats.triangleTestMs += msSince(t0);
    // A draw that showed nothing was hidden by what was drawn before it, and stays hidden
    // (depth only grows nearer): not drawn early next frame. One that showed a sample may
    // have been covered later; it is drawn early and marked again.
    for (std::size_t i = 0; i < markedDraws_.size(); ++i) {
        const NodeRef ref = markedDraws_[i];
        const bool visible = triangleAnswers_[i] != QueryResult::Occluded;
        if (!visible) {
            ++f.stats.drawMarksHidden;
            culledTriangles_ += subtreeTriangles(f, ref);
        }
        history_.recordAnswer(history_.at(ref, objs), visible, f.index);
    }
    f.marking = false;
}

bool QueryScheduler::worthTriangleTest(const Frame& f, NodeRef ref) {
    if (!params_.features.useCostModel) return true;
    const TestCosts& c = params_.tuning.costs;
    const double triangles = double(subtreeTriangles(f, ref));
    return triangleOccludedRate_ * triangles * c.drawNsPerTriangle > c.triangleTestNsPerPart + triangles * c.triangleTestNsPerTriangle;
}

double QueryScheduler::testMarginNs(const Frame& f, NodeRef ref, const ScreenRect& rect, double occludedRate) {
    const TestCosts& c = params_.tuning.costs;
    return occludedRate * double(subtreeTriangles(f, ref)) * c.drawNsPerTriangle - (c.testNsPerVolume + c.testNsPerPixel * rect.area());
}

bool QueryScheduler::worthTesting(const Frame& f, NodeRef ref, const ScreenRect& rect, double occludedRate) {
    return !params_.features.useCostModel || testMarginNs(f, ref, rect, occludedRate) > 0.0;
}

std::uint64_t QueryScheduler::subtreeTriangles(const Frame& f, NodeRef ref) {
    const SceneObjects& objs = f.objects;
    auto objectTriangles = [&](std::uint32_t object, std::uint32_t node) {
        const LocalBsp& model = objs.model(objs.modelOf(object));
        // A bounds model's one part is the game's whole object: count what drawing it costs.
        if (model.drawTriangles > 0) return std::uint64_t{model.drawTriangles};
        return std::uint64_t{model.nodes[node].indexCount / 3};
    };
    if (!ref.isSceneNode()) return objectTriangles(ref.object, ref.node);
    const LooseBsp& scene = f.tree.scene();
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

QueryVolume QueryScheduler::testedVolume(const Frame& f, NodeRef ref) const {
    if (ref.isSceneNode() || !params_.features.useTightVolumes) return QueryVolume::fromAabb(f.tree.worldBox(ref));
    return objectNodeVolume(f.objects, ref, params_.tuning.volume, testedAutoSaving(f, ref));
}

float QueryScheduler::testedAutoSaving(const Frame& f, NodeRef ref) const {
    // A part drawn as clusters has its clusters' boxes tested against the pyramid once its
    // volume passes, and they bound it tighter than any one volume: a k-DOP's extra
    // triangles then cost every pyramid and raster test and save little, so Auto takes the
    // better of its two boxes (a k-DOP would have to save all of the box's area).
    const bool asClusters = drawsAsClusters(f, ref, f.objects.model(f.objects.modelOf(ref.object)));
    return asClusters ? 1.0f : params_.tuning.autoVolumeSaving;
}

bool QueryScheduler::pyramidHides(Frame& f, NodeRef ref, DepthFootprint& fp) const {
    // The pyramid exists only for a single-sample target, where a volume that covers no
    // pixel centre draws nothing.
    if (fp.centres.empty() || pyramid_.occluded(fp.centres, fp.nearest, params_.tuning.pyramidSpan)) return true;
    if (params_.tuning.texelTestTexels == 0) return false;
    // The same footprint again, with its planes: made only for what the span test let through.
    if (fp.planesLeftOut && !testedFootprint(f, ref, fp, true)) return false;
    const bool hidden = pyramid_.occludedPerTexel(fp.centres, fp.nearest, fp.planes, params_.tuning.texelTestTexels);
    f.stats.texelOccluded += hidden;
    return hidden;
}

bool QueryScheduler::testedFootprint(const Frame& f, NodeRef ref, DepthFootprint& out, bool planes) const {
    if (ref.isSceneNode()) return f.screen.boxDepth(f.screen.worldProjection(), f.tree.worldBox(ref), out, planes);
    if (!params_.features.useTightVolumes) return f.screen.volumeDepth(testedVolume(f, ref), out);
    const SceneObjects& objs = f.objects;
    const VolumeKind kind = objectNodeVolumeKind(objs, ref, params_.tuning.volume, testedAutoSaving(f, ref));
    if (kind == VolumeKind::Obb && params_.features.useObbFrames) {
        // As a box in its own frame: its front faces' planes and its outline too.
        const std::optional<glm::dmat4> frame = objectNodeObbFrame(objs, ref);
        if (frame) {
            static const Aabb kFrameBox{glm::vec3(-1.0f), glm::vec3(1.0f)};
            if (const std::optional<bool> inFront = f.screen.frameBoxDepth(f.screen.objectProjection(*frame), kFrameBox, out, planes))
                return *inFront;
        }
    }
    if (kind != VolumeKind::Aabb) return f.screen.volumeDepth(testedVolume(f, ref), out);
    const Aabb box = objectNodeBox(objs, ref, params_.tuning.volume);
    if (box.empty()) return f.screen.volumeDepth(testedVolume(f, ref), out);
    return f.screen.boxDepth(f.screen.objectProjection(objs.matrix(ref.object)), box, out, planes);
}

void QueryScheduler::rasterTest(Frame& f, const std::vector<NodeRef>& parts, bool countSamples) {
    // Batches of at most this many volumes, all drawn before the first is read: the
    // volumes (and the backend's streams) are held for one batch at a time, and a batch
    // of a typical frame's tests is one draw.
    constexpr std::size_t kRasterBatchVolumes = 2048;
    const auto t0 = SchedulerClock::now();
    rasterAnswers_.assign(parts.size(), QueryResult::Visible);
    rasterSamples_.assign(countSamples ? parts.size() : 0, kUnknownSamples);
    rasterBatches_.clear();
    splitDrawWait(f);
    for (std::size_t start = 0; start < parts.size(); start += kRasterBatchVolumes) {
        const std::size_t end = std::min(parts.size(), start + kRasterBatchVolumes);
        rasterVolumes_.clear();
        for (std::size_t i = start; i < end; ++i) rasterVolumes_.push_back(testedVolume(f, parts[i]));
        rasterBatches_.push_back(f.backend.testVolumes(rasterVolumes_, countSamples));
    }
    for (std::size_t b = 0; b < rasterBatches_.size(); ++b) {
        if (rasterBatches_[b] == kNoBatch) continue;  // answers stay Visible
        const std::size_t start = b * kRasterBatchVolumes, count = std::min(kRasterBatchVolumes, parts.size() - start);
        // Nothing else to do meanwhile: wait.
        f.backend.collectVolumes(rasterBatches_[b], std::span(rasterAnswers_).subspan(start, count),
                                 params_.tuning.queryTimeoutMs,
                                 countSamples ? std::span(rasterSamples_).subspan(start, count) : std::span<std::uint32_t>{});
        ++f.stats.rasterBatches;
        f.stats.rasterTests += static_cast<std::uint32_t>(count);
    }
    f.stats.rasterMs += msSince(t0);
}

}  // namespace dyncull
