// The Queries mode: hardware occlusion queries scheduled front to back over the two-level
// tree (Two-level BSP for dynamic occlusion culling, section 3.4, Algorithm 2), with the
// batching and occupancy-map fast accept of Staneker, Bartz, Straßer, Efficient Multiple
// Occlusion Queries (sections 3-4). The active list (a stack, nearest at the back) is
// refined as visible nodes are replaced by their children; a node that needs a query but
// overlaps a pending query's rectangle, or finds the in-flight limit reached, waits.
// A frame runs four stages until nothing is left: finish answered queries, process the
// active list, retry waiting nodes, and, with nothing else to do, wait for the oldest query.
#include <algorithm>

#include "cull_frame.hpp"
#include "pending_queries.hpp"

namespace dyncull {

void QueryScheduler::runQueries(Frame& f) {
    drawnMap_.resetOrClear(f.view.width, f.view.height, params_.tuning.occupancyTileSize);
    waitingMap_.resetOrClear(f.view.width, f.view.height, params_.tuning.occupancyTileSize);
    queries_->beginFrame(params_, f.view.width, f.view.height);
    waiting_.clear();
    answeredSinceRetry_ = false;
    collectLatent(f);
    // Last frame's draw queries become this frame's answers to read; never waited for.
    drawQueries_->beginFrame(f.backend);
    drawQueries_->collect(f, history_);

    auto onAnswer = [&](const PendingQuery& p, QueryResult r) {
        // A query answers "occluded" with samples only under a sample threshold: those
        // samples bound what the culled node would have shown (depth only grows nearer).
        if (r == QueryResult::Occluded) f.stats.claimedErrorPixels += f.backend.samples(p.id);
        finishQuery(f, p.node, r);
        answeredSinceRetry_ = true;
    };
    while (!active_.empty() || !waiting_.empty() || !queries_->empty()) {
        // 1. Finish answered queries, oldest first; visible ones push their children.
        queries_->closeBatch(f);
        if (drawQueries_->waiting()) drawQueries_->collect(f, history_);
        bool progress = queries_->takeAnswered(f, onAnswer);

        // 2. Process the active list front to back.
        progress |= !active_.empty();
        while (!active_.empty()) {
            const auto [ref, box, ft] = visitNearest(f);
            NodeHistory& h = history_.at(ref, f.objects);
            if (ft == FirstTest::Invisible) continue;
            if (ft == FirstTest::Visible) {
                queries_->closeBatch(f);
                processVisible(f, ref, h, true);
                continue;
            }
            queryOrWait(f, ref, box, h);
        }

        // 3. Retry waiting nodes nearest first.
        progress |= retryWaiting(f);
        queries_->closeBatch(f);

        // 4. Nothing else to do: wait for the oldest query.
        if (!progress && active_.empty() && !queries_->empty())
            queries_->waitOldest(f, params_.tuning.queryTimeoutMs, onAnswer);
    }
    queries_->closeBatch(f);
    drawQueries_->dropLate(f);
}

void QueryScheduler::queryOrWait(Frame& f, NodeRef ref, const Aabb& box, NodeHistory& h) {
    ScreenRect rect;
    f.screen.rect(box, rect);
    if (acceptByOccupancy(f, ref, box, rect)) return;
    if (params_.approx.useLastFrameResults) {
        decideByLastAnswer(f, ref, box, h);
        return;
    }
    // With useWaitOrder a waiting node also blocks every farther node whose rectangle
    // overlaps it (waitingMap_), so no node is queried before a nearer occluder in front of
    // it is drawn (fewer parts drawn for nothing, more waiting).
    if (!(keepsWaitOrder() && !waiting_.empty() && waitingMap_.anySet(rect)) && queries_->canIssue(rect)) {
        issueQuery(f, ref, box, rect);
        return;
    }
    const glm::vec3 d = glm::vec3(glm::dvec3(box.center()) - glm::dvec3(f.camera().position));
    const Waiting w{glm::dot(d, d), ref, box, rect};
    auto at = std::upper_bound(waiting_.begin(), waiting_.end(), w.dist2, [](float v, const Waiting& e) { return v < e.dist2; });
    waiting_.insert(at, w);
    waitingMap_.mark(rect);
}

bool QueryScheduler::acceptByOccupancy(Frame& f, NodeRef ref, const Aabb& box, const ScreenRect& rect) {
    // Tested as soon as a node is reached, even if a nearer waiting node overlaps it:
    // deferring the test too waited far longer for few parts saved (docs/BENCHMARKS.md,
    // "Waiting order").
    if (!params_.features.useOccupancyAccept || drawnMap_.allSet(rect)) return false;
    ++f.stats.skippedByOccupancy;
    NodeHistory& h = history_.at(ref, f.objects);
    history_.recordAnswer(h, true, f.index);
    f.note(ref, box, NodeState::VisibleOccupancy);
    queries_->closeBatch(f);
    processVisible(f, ref, h, true);
    return true;
}

void QueryScheduler::decideByLastAnswer(Frame& f, NodeRef ref, const Aabb& box, NodeHistory& h) {
    // Approximate: act on the previous answer now, read this query in a later frame.
    if (!h.queryInFlight) {
        latent_->add(f.objects, ref, queries_->issueUnawaited(f, queryVolume(f, ref, box)));
        h.queryInFlight = true;
    }
    if (h.answers > 0 && !h.lastVisible) {
        ++f.stats.queriesOccluded;
        f.stats.claimUnbounded = true;  // an old answer bounds nothing about this frame
        f.note(ref, box, NodeState::Occluded);
        return;
    }
    f.note(ref, box, NodeState::VisibleQueried);
    queries_->closeBatch(f);
    processVisible(f, ref, h, false);
}

void QueryScheduler::finishQuery(Frame& f, NodeRef ref, QueryResult r) {
    if (r == QueryResult::NotReady) ++f.stats.queriesTimedOut;  // from waitOldest: timed out
    const bool visible = r != QueryResult::Occluded;
    NodeHistory& h = history_.at(ref, f.objects);
    history_.recordAnswer(h, visible, f.index);
    f.note(ref, visible ? NodeState::VisibleQueried : NodeState::Occluded);
    if (visible)
        processVisible(f, ref, h, false);
    else
        ++f.stats.queriesOccluded;
}

bool QueryScheduler::retryWaiting(Frame& f) {
    // Only an answer frees a rectangle or an in-flight slot; without one, every waiting
    // node is still blocked. (The drawn map only fills up, so the occupancy accept, tested
    // before a node waits, cannot newly succeed.) Each node still waiting blocks the
    // farther ones it overlaps when the order is kept.
    if (!answeredSinceRetry_ || waiting_.empty()) return false;
    answeredSinceRetry_ = false;
    const bool keepOrder = keepsWaitOrder();
    waitingMap_.clear();
    bool issued = false;
    std::size_t kept = 0;  // compacts in place, keeping the order
    for (const Waiting& w : waiting_) {
        const bool blocked = keepOrder && waitingMap_.anySet(w.rect);
        if (!blocked && queries_->canIssue(w.rect)) {
            issueQuery(f, w.ref, w.box, w.rect);
            issued = true;
        } else {
            waitingMap_.mark(w.rect);
            waiting_[kept++] = w;
        }
    }
    waiting_.resize(kept);
    return issued;
}

void QueryScheduler::collectLatent(Frame& f) {
    // Answers to queries of earlier frames (useLastFrameResults): recorded in the history
    // for the next decision; never drawn from here.
    latent_->takeAnswered(f, [&](NodeRef ref, QueryResult r) {
        NodeHistory& h = history_.at(ref, f.objects);
        h.queryInFlight = false;
        history_.recordAnswer(h, r != QueryResult::Occluded, f.index);
    });
}

void QueryScheduler::issueQuery(Frame& f, NodeRef ref, const Aabb& box, const ScreenRect& rect) {
    if (!ref.isSceneNode()) {
        // When the object last changed its transform, for tightenAfterFrames.
        const std::uint64_t placed = f.objects.placedAt(ref.object);
        if (placed != lastPlacement_[ref.object]) {
            lastPlacement_[ref.object] = placed;
            stillSince_[ref.object] = f.index;
        }
    }
    queries_->issue(f, ref, queryVolume(f, ref, box), rect);
}

}  // namespace dyncull
