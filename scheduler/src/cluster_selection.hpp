// Internal: one part's cluster tests (cluster_culling.cpp) split into what the render
// thread decides (which tests, from the cost model and the frame) and the tests themselves,
// a function of read-only inputs, so that a worker thread can run them while the render
// thread draws. The late pass's deferred clusters are selected so, ahead of their draws.
#pragma once

#include <atomic>
#include <cstdint>
#include <span>
#include <thread>
#include <vector>

#include "cull_frame.hpp"

namespace dyncull {

/// What one part's cluster tests read. Built on the render thread; read-only afterwards,
/// and everything it borrows stays unchanged until the tests are done.
struct QueryScheduler::ClusterJob {
    std::span<const LeafCluster> clusters;  ///< the part's (the model's, borrowed)
    std::uint32_t firstBit = 0;             ///< the first cluster's bit in `shown`
    std::span<const std::uint64_t> shown;   ///< cluster bits (split passes; borrowed)
    glm::mat4 matrix{1.0f};                 ///< object to world
    ObjectProjection object;                ///< `matrix` prepared (pyramid tests)
    ObjectSpaceEye eye;                     ///< cone tests
    ClusterPass pass = ClusterPass::All;
    bool split = false;    ///< early or deferred: the bits divide the clusters between passes
    bool cones = false, frustum = false, pyramid = false;  ///< the tests to run
    bool markRanges = false;  ///< one range per cluster, never merged (marked clusters)
    /// With cluster history's record this frame: the tests keep what they learn of each
    /// cluster (ClusterSelection::learned), for the record to take rather than project
    /// the cluster again; and the part's entry in clusterParts_ that it goes to.
    bool keepLearned = false;
    std::uint32_t recordIndex = kInvalidIndex;
};

/// What a cluster's tests learned this frame, handed on to cluster history's record at the
/// frame's end. Depth only grows nearer within a frame, and the camera and objects hold
/// still, so a cluster facing away, outside the frustum or behind an earlier pyramid is
/// hidden in the final depth too; one in front of the near plane keeps its footprint.
struct QueryScheduler::LearnedCluster {
    enum class Fate : std::uint8_t {
        Untested,   ///< not tested this frame (drawn early, or tests off): the record projects it
        Hidden,     ///< facing away, outside the frustum, or behind an earlier pyramid
        Crossing,   ///< reaches the near plane or holds the eye: shows
        Projected,  ///< in front, not rejected: `centres` and `nearest` are its footprint
    };
    ScreenRect centres;     ///< window pixels whose centres it may cover (Projected)
    float nearest = 0.0f;   ///< its nearest window depth, reversed Z (Projected)
    Fate fate = Fate::Untested;
};

/// What they decided: the ranges to draw and the counts the stats and cost models take.
struct QueryScheduler::ClusterSelection {
    std::vector<IndexRange> ranges;
    std::vector<std::uint32_t> rangeIds;  ///< with markRanges: each range's cluster (model index)
    std::vector<LearnedCluster> learned;  ///< with keepLearned: one per cluster of the job, in order
    std::uint64_t culledTriangles = 0, deferredTriangles = 0, drawnTriangles = 0;
    std::uint32_t culledClusters = 0, deferred = 0, drawn = 0;
    std::uint32_t pyramidTests = 0;  ///< clusters projected against the pyramid (FrameStats::clusterPyramidTests)
    double ms = 0.0;  ///< spent testing
};

/// The deferred clusters of the early parts (deferredParts_, in order) selected on a worker
/// thread while the render thread runs the late pass and then draws them, each part as soon
/// as its selection is done: they depend only on the early pyramid, fixed by then. The
/// bits are copied, since the late pass may grow the history.
struct QueryScheduler::DeferredSelection {
    std::vector<ClusterJob> jobs;
    std::vector<ClusterSelection> out;
    std::vector<std::uint64_t> bits;  ///< the jobs' `shown` words, copied
    std::atomic<std::size_t> done{0};  ///< jobs whose `out` is written (release by the worker)
    std::thread worker;               ///< joinable while it runs

    /// Waits until job `i`'s selection is written.
    void waitFor(std::size_t i) {
        std::size_t ready = done.load(std::memory_order_acquire);
        while (ready <= i) {
            done.wait(ready, std::memory_order_acquire);
            ready = done.load(std::memory_order_acquire);
        }
    }

    ~DeferredSelection() {
        if (worker.joinable()) worker.join();
    }
};

}  // namespace dyncull
