// Queries in flight, by handle (pending_queries.hpp). Papers: Staneker, Bartz, Straßer,
// Efficient Multiple Occlusion Queries, section 4 (batches of queries whose screen
// rectangles do not overlap); Bittner et al., Coherent Hierarchical Culling, section 4
// (queries on previously visible geometry, read a frame later).
#include "pending_queries.hpp"

namespace dyncull {

void QueryIssuer::beginFrame(const SchedulerParams& params, int width, int height) {
    pending_.clear();
    batchOpen_ = false;
    maxInFlight_ = params.tuning.maxQueriesInFlight;
    batching_ = params.features.useBatching;
    overlapping_ = params.approx.batchOverlapping;
    pendingMap_.resetOrClear(width, height, params.tuning.occupancyTileSize);
}

bool QueryIssuer::canIssue(const ScreenRect& rect) const {
    if (pending_.size() >= maxInFlight_) return false;
    if (!batching_) return pending_.empty();  // one query in flight at a time
    return overlapping_ || !pendingMap_.anySet(rect);
}

void QueryIssuer::issue(QueryScheduler::Frame& f, NodeRef ref, const QueryVolume& volume, const ScreenRect& rect) {
    const QueryId id = issueUnawaited(f, volume);
    if (batching_) pendingMap_.mark(rect);
    pending_.push_back(PendingQuery::of(f.objects, ref, id, rect, batching_));
}

QueryId QueryIssuer::issueUnawaited(QueryScheduler::Frame& f, const QueryVolume& volume) {
    if (!batchOpen_) {
        f.beginBatch();
        batchOpen_ = true;
        ++f.stats.batches;
    }
    return f.issue(volume);
}

void QueryIssuer::closeBatch(QueryScheduler::Frame& f) {
    if (!batchOpen_) return;
    f.endBatch();
    batchOpen_ = false;
}

void QueryIssuer::finish(QueryScheduler::Frame& f, const PendingQuery& p) {
    f.backend.release(p.id);
    if (p.markedRect) pendingMap_.unmark(p.rect);
}

void DrawQueries::collect(QueryScheduler::Frame& f, VisibilityHistory& history) {
    toRead_.takeAnswered(f, [&](NodeRef ref, QueryResult r) {
        NodeHistory& h = history.at(ref, f.objects);
        if (h.lastTouchedFrame == f.index) return;
        history.recordAnswer(h, r != QueryResult::Occluded, f.index - 1);
        if (r == QueryResult::Occluded) ++f.stats.drawQueriesOccluded;
    });
}

void DrawQueries::dropLate(QueryScheduler::Frame& f) {
    f.stats.drawQueriesLate += toRead_.size();
    toRead_.releaseAll(f.backend);
}

}  // namespace dyncull
