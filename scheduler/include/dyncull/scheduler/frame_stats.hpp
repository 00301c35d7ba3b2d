// What one culled frame cost and did. Times in milliseconds of wall clock (steady_clock).
#pragma once

#include <cstdint>

namespace dyncull {

struct FrameStats {
    double traversalMs = 0.0;  ///< CPU in traversal and scheduling (excludes backend calls, waits and draws)
    double queryMs = 0.0;      ///< in the query backend: issuing volumes, polling (a poll may flush GL)
    double waitMs = 0.0;       ///< blocked waiting for query results
    double drawMs = 0.0;       ///< CPU time submitting parts (and query volumes)
    double frameMs = 0.0;      ///< whole frame including the final glFinish
    double updateMs = 0.0;     ///< loose-BSP relink and lazy rebuild
    /// Times the drawing was handed to the GPU during the frame (filled by the engine:
    /// EngineOptions::submitTriangles), besides the reads that submit it themselves.
    std::uint32_t drawSubmits = 0;
    std::uint32_t queriesIssued = 0;
    std::uint32_t depthTests = 0;    ///< two-phase: nodes tested against the depth pyramid
    double depthReadMs = 0.0;        ///< two-phase: reading the depth back (waits for the early pass) and building the pyramid
    std::uint32_t pyramidBuilds = 0;  ///< two-phase: depth pyramids built (each from a depth readback)
    std::uint32_t rasterTests = 0;    ///< two-phase: volumes in batched raster tests (QueryBackend::testVolumes)
    std::uint32_t rasterBatches = 0;  ///< two-phase: batched raster tests issued
    double rasterMs = 0.0;            ///< two-phase: building, drawing and waiting for the batched raster tests
    /// Two-phase with SchedulerTuning::splitDrawWaits: of depthReadMs and rasterMs, the time
    /// spent waiting for the drawing submitted before them, and the CPU in the late pass's
    /// pyramid tests (footprint and pyramid reads; in traversalMs). 0 otherwise.
    double drawWaitMs = 0.0;
    double pyramidTestMs = 0.0;
    std::uint32_t triangleTests = 0;  ///< two-phase: parts tested on their own triangles (PartSink::testParts)
    double triangleTestMs = 0.0;      ///< two-phase: drawing and waiting for the triangle tests, and reading the draw marks
    std::uint32_t drawMarksHidden = 0;  ///< two-phase: parts drawn whose draw showed no sample
    std::uint32_t clusterTests = 0;     ///< clusters of drawn parts tested (SchedulerFeatures::useClusters)
    std::uint32_t clustersCulled = 0;   ///< of those, left undrawn: facing away, outside the frustum or behind the pyramid
    std::uint64_t clusterTrianglesCulled = 0;  ///< their triangles (not in trianglesDrawn)
    /// Two-phase with cluster history: clusters of early parts held back from the early
    /// pass (hidden at the end of the frame their part was last drawn in), and of those
    /// the late pass drew (the pyramid could not reject them).
    std::uint32_t clustersDeferred = 0;
    std::uint32_t deferredClustersDrawn = 0;
    /// Two-phase with cluster history's record: clusters whose verdict the record took from
    /// the frame's own cluster tests (SchedulerFeatures::useLearnedClusters) rather than
    /// projecting them again.
    std::uint32_t clustersLearned = 0;
    /// Two-phase: volumes hidden texel by texel (SchedulerTuning::texelTestTexels) that the
    /// pyramid test at its span let through; in depthTests already.
    std::uint32_t texelOccluded = 0;
    /// Two-phase: clusters projected and compared with a depth pyramid: in the late pass
    /// (the early pyramid, or one built again before a round) and in cluster history's
    /// record (the final depth's). Volume tests as much as depthTests; their CPU is in clusterMs.
    std::uint32_t clusterPyramidTests = 0;
    double clusterMs = 0.0;             ///< CPU in the cluster tests, and in the final-depth tests of cluster history
    std::uint64_t queryTriangles = 0;   ///< triangles of the query volumes drawn (12 per box)
    std::uint32_t queriesOccluded = 0;  ///< answered "occluded"
    std::uint32_t queriesTimedOut = 0;  ///< never answered within the bound; counted visible
    /// Queries on parts drawn without a query (SchedulerFeatures::useDrawQueries); not in queriesIssued.
    std::uint32_t drawQueries = 0;
    std::uint32_t drawQueriesOccluded = 0;  ///< last frame's draw queries read this frame that drew no sample
    std::uint32_t drawQueriesLate = 0;      ///< last frame's draw queries still unanswered at this frame's end (dropped)
    std::uint32_t skippedByHistory = 0;  ///< queries not issued thanks to visibility history
    std::uint32_t skippedByCost = 0;  ///< two-phase: volumes left untested by the cost model (SchedulerFeatures::useCostModel)
    std::uint32_t skippedByOccupancy = 0;  ///< visible without a query: rectangle touched empty screen
    std::uint32_t visibleNearOrInside = 0;  ///< visible without a query: camera inside / near plane crossed
    std::uint32_t visibleFront = 0;  ///< visible without a query: front-most leaves (SchedulerTuning::frontPercent)
    std::uint32_t frustumCulled = 0;
    std::uint32_t smallFeatureCulled = 0;  ///< approximate small-feature setting
    std::uint32_t budgetCulled = 0;  ///< two-phase: parts culled within the error budget (SchedulerApproximations)
    /// What the approximate settings claim this frame lost: an upper bound on the pixels
    /// showing something else than they would with every visible part drawn, summed over
    /// the nodes culled approximately (each node's own bound: the samples its volume passed,
    /// for the error budget and the sample threshold; its screen rectangle's area, for small
    /// features). 0 for conservative settings.
    std::uint64_t claimedErrorPixels = 0;
    /// A setting without a bound culled something this frame (last frame's answers,
    /// SchedulerApproximations::useLastFrameResults): claimedErrorPixels does not cover it.
    bool claimUnbounded = false;
    std::uint32_t nodesVisited = 0;
    std::uint32_t batches = 0;
    /// Local-BSP leaves (object parts) drawn, whole or as the clusters that survived; a part
    /// none of whose clusters survived is not drawn and not counted.
    std::uint32_t partsDrawn = 0;
    std::uint64_t trianglesDrawn = 0;
    /// Two-phase: of trianglesDrawn, those of the early pass, and those of the parts drawn
    /// after the batched raster test let them through (the rest the late pass drew untested,
    /// and the early parts' deferred clusters).
    std::uint64_t earlyTriangles = 0;
    std::uint64_t testedTriangles = 0;
};

}  // namespace dyncull
