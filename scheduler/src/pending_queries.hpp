// Queries in flight, named by their object's handle: the Queries mode's occlusion queries
// awaited this frame (QueryIssuer), and the queries read in a later frame without blocking
// (DeferredQueries: draw queries, and the one-frame-latency setting's queries). An answer
// that arrives after its object was removed, and its slot perhaps reused by another object
// of a model with fewer nodes, is dropped instead of landing on the newcomer.
#pragma once

#include <cstdint>
#include <vector>

#include "cull_frame.hpp"

namespace dyncull {

/// One query in flight: its node, the rectangle it covers, and the generation of the node's
/// object when it was issued (0 for scene nodes).
struct PendingQuery {
    NodeRef node;
    QueryId id = kNoQuery;
    ScreenRect rect;
    bool markedRect = false;  ///< rect is marked in QueryIssuer's map of pending rectangles
    std::uint32_t generation = 0;

    static PendingQuery of(const SceneObjects& objects, NodeRef ref, QueryId id, ScreenRect rect = {}, bool marked = false) {
        return {ref, id, rect, marked, ref.isSceneNode() ? 0 : objects.handle(ref.object).generation};
    }
    /// True if the node's object is still the one the query was issued for.
    bool stillValid(const SceneObjects& objects) const {
        return node.isSceneNode() || (node.object < objects.slotCount() && objects.alive(node.object) &&
                                      objects.handle(node.object).generation == generation);
    }
};

/// Queries answered in a later frame, polled without ever blocking.
class DeferredQueries {
public:
    void add(const SceneObjects& objects, NodeRef ref, QueryId id) { queries_.push_back(PendingQuery::of(objects, ref, id)); }
    bool empty() const { return queries_.empty(); }
    std::uint32_t size() const { return static_cast<std::uint32_t>(queries_.size()); }
    void swap(DeferredQueries& other) { queries_.swap(other.queries_); }

    /// Polls every query; each answered one is released and removed, and
    /// onAnswer(NodeRef, QueryResult) runs if its object still exists.
    template <class OnAnswer>
    void takeAnswered(QueryScheduler::Frame& f, OnAnswer onAnswer) {
        for (std::size_t i = 0; i < queries_.size();) {
            const PendingQuery p = queries_[i];
            const QueryResult r = f.poll(p.id);
            if (r == QueryResult::NotReady) {
                ++i;
                continue;
            }
            f.backend.release(p.id);
            if (p.stillValid(f.objects)) onAnswer(p.node, r);
            queries_[i] = queries_.back();
            queries_.pop_back();
        }
    }
    /// Releases every query unread (their answers are no longer wanted).
    void releaseAll(QueryBackend& backend) {
        for (const PendingQuery& p : queries_) backend.release(p.id);
        queries_.clear();
    }

private:
    std::vector<PendingQuery> queries_;
};

/// The Queries mode's occlusion queries awaited this frame, issued in batches whose
/// screen rectangles do not overlap (Staneker et al., Efficient Multiple Occlusion Queries,
/// section 4): a query whose rectangle overlaps a pending one could be answered "visible"
/// only because the nearer node has not been drawn yet.
class QueryIssuer {
public:
    /// Starts a frame of `width` x `height` pixels with the rules of `params`.
    void beginFrame(const SchedulerParams& params, int width, int height);
    /// True if a query of rectangle `rect` may be issued now: under the in-flight limit, and
    /// (with batching) overlapping no pending rectangle, or (without) nothing pending.
    bool canIssue(const ScreenRect& rect) const;
    /// Issues a query of `volume` for `ref` (a batch is opened if none is).
    void issue(QueryScheduler::Frame& f, NodeRef ref, const QueryVolume& volume, const ScreenRect& rect);
    /// Issues a query of `volume` in the open batch (opening one) that this frame does not
    /// await: its caller keeps and reads it (the one-frame-latency setting).
    QueryId issueUnawaited(QueryScheduler::Frame& f, const QueryVolume& volume);
    /// Ends the open batch, if any (before drawing: queries and draws do not interleave).
    void closeBatch(QueryScheduler::Frame& f);

    bool empty() const { return pending_.empty(); }
    /// Removes the answered queries, oldest first, calling onAnswer(PendingQuery, result)
    /// for each, then releasing it; true if any answered.
    template <class OnAnswer>
    bool takeAnswered(QueryScheduler::Frame& f, OnAnswer onAnswer) {
        bool any = false;
        for (std::size_t i = 0; i < pending_.size();) {
            const QueryResult r = f.poll(pending_[i].id);
            if (r == QueryResult::NotReady) {
                ++i;
                continue;
            }
            const PendingQuery p = pending_[i];
            pending_.erase(pending_.begin() + static_cast<std::ptrdiff_t>(i));
            onAnswer(p, r);  // before the release: the answer may read the query's samples
            finish(f, p);
            any = true;
        }
        return any;
    }
    /// Blocks for the oldest query (at most `timeoutMs`; NotReady if it timed out) and
    /// removes it, calling onAnswer(PendingQuery, result).
    template <class OnAnswer>
    void waitOldest(QueryScheduler::Frame& f, double timeoutMs, OnAnswer onAnswer) {
        const PendingQuery p = pending_.front();
        const QueryResult r = f.wait(p.id, timeoutMs);
        pending_.erase(pending_.begin());
        onAnswer(p, r);
        finish(f, p);
    }

private:
    void finish(QueryScheduler::Frame& f, const PendingQuery& p);

    std::vector<PendingQuery> pending_;  // oldest first
    OccupancyMap pendingMap_;  // rectangles of pending queries (with batching)
    bool batchOpen_ = false;
    std::uint32_t maxInFlight_ = 1;
    bool batching_ = true, overlapping_ = false;
};

/// Coherent hierarchical culling's queries on the geometry of parts drawn untested
/// (SchedulerFeatures::useDrawQueries): issued around this frame's draws, read next frame
/// without waiting, dropped if they have not answered by the end of that frame.
class DrawQueries {
public:
    /// What last frame issued becomes what this frame reads.
    void beginFrame(QueryBackend& backend) {
        toRead_.releaseAll(backend);  // empty unless last frame ended early
        toRead_.swap(issued_);
    }
    void add(const SceneObjects& objects, NodeRef ref, QueryId id) { issued_.add(objects, ref, id); }
    bool waiting() const { return !toRead_.empty(); }
    /// Records the answers that have arrived into `history` (non-blocking). A part already
    /// reached this frame keeps this frame's decision (the answer is older).
    void collect(QueryScheduler::Frame& f, VisibilityHistory& history);
    /// End of frame: answers that have not arrived would be two frames old at the next
    /// read, so they are dropped and counted (drawQueriesLate); those parts keep their history.
    void dropLate(QueryScheduler::Frame& f);
    /// Releases everything (the mode changed away from Queries).
    void releaseAll(QueryBackend& backend) {
        issued_.releaseAll(backend);
        toRead_.releaseAll(backend);
    }

private:
    DeferredQueries issued_, toRead_;
};

}  // namespace dyncull
