// One frame of culling as a stack object: what cullFrame's caller lends for the frame
// (tree, backend, sink, view), what the frame learns (its stats and trace), and the flags
// that live no longer than it. Every stage of QueryScheduler takes it; nothing borrowed
// outlives the frame in a member.
#pragma once

#include <chrono>
#include <vector>

#include "dyncull/scheduler/query_scheduler.hpp"
#include "screen_projection.hpp"

namespace dyncull {

using SchedulerClock = std::chrono::steady_clock;
inline double msSince(SchedulerClock::time_point t0) {
    return std::chrono::duration<double, std::milli>(SchedulerClock::now() - t0).count();
}

struct QueryScheduler::Frame {
    const TwoLevelTree& tree;
    const SceneObjects& objects;  ///< tree.objects()
    QueryBackend& backend;
    PartSink& sink;
    const FrameView& view;  ///< world space; camera-relative matrices
    ScreenProjection screen;
    FrameStats& stats;
    std::vector<NodeTrace>* trace;  ///< null unless the caller asked for one (setTrace)
    std::uint32_t index;  ///< this frame's number (QueryScheduler::frameIndex)

    // frontPercent: the leaves to draw untested, and how many were met so far.
    std::uint32_t frontBudget = 0, frontLeavesSeen = 0;
    /// TwoPhase with triangle tests: the sink marks this frame's draws.
    bool marking = false;
    /// The depth pyramid holds this frame's early depth: cluster culling may test against it.
    bool clusterPyramid = false;
    /// TwoPhase with cluster history (SchedulerFeatures::useClusterHistory): the early pass
    /// draws only the clusters that showed last frame (their bits were recorded then), and
    /// this frame records which of its drawn parts' clusters show at its end.
    bool useClusterBits = false, recordClusterBits = false;
    /// Recording cluster bits from the sink's range marks (SchedulerFeatures::useClusterMarks):
    /// every part drawn as clusters is drawn one range per cluster, each marked.
    bool markClusters = false;
    /// TwoPhase, the cost model's probe in a frame that does not test: every part drawn
    /// (but those certainly visible) is tested against the final depth at the frame's end.
    bool probeAtEnd = false;
    /// The depth pyramid holds this frame's final depth (testOnFinalPyramid read it).
    bool finalPyramid = false;

    const Camera& camera() const { return view.camera; }
    const Frustum& frustum() const { return view.frustum; }

    void note(NodeRef ref, const Aabb& box, NodeState s) {
        if (trace) trace->push_back({ref, box, s});
    }
    /// note() with the box looked up only when tracing.
    void note(NodeRef ref, NodeState s) {
        if (trace) trace->push_back({ref, tree.worldBox(ref), s});
    }

    // Backend calls, their time charged to the stats apart from scheduling: on a software
    // rasteriser a poll may flush the command stream, which is GL work, not the scheduler's.
    void beginBatch() {
        const auto t0 = SchedulerClock::now();
        backend.beginBatch();
        stats.queryMs += msSince(t0);
    }
    void endBatch() {
        const auto t0 = SchedulerClock::now();
        backend.endBatch();
        stats.queryMs += msSince(t0);
    }
    /// Issues a query of `volume`, counting its triangles.
    QueryId issue(const QueryVolume& volume) {
        stats.queryTriangles += volume.isBox() ? 12u : volume.triangleCount;
        ++stats.queriesIssued;
        const auto t0 = SchedulerClock::now();
        const QueryId id = backend.issue(volume);
        stats.queryMs += msSince(t0);
        return id;
    }
    QueryResult poll(QueryId id) {
        const auto t0 = SchedulerClock::now();
        const QueryResult r = backend.poll(id);
        stats.queryMs += msSince(t0);
        return r;
    }
    /// Blocks for query `id` (NotReady if it timed out), charged to waitMs.
    QueryResult wait(QueryId id, double timeoutMs) {
        const auto t0 = SchedulerClock::now();
        const QueryResult r = backend.wait(id, timeoutMs);
        stats.waitMs += msSince(t0);
        return r;
    }
};

}  // namespace dyncull
