// Cluster culling (SchedulerParams::useClusters) draws exactly the image of whole parts:
// spheres whose back faces are culled — rotated, scaled, one mirrored, some crossing the
// frustum's edge, some behind a wall — seen from a camera circling them, in vfc (cones and
// frustum) and full (the depth pyramid too), each frame compared pixel for pixel with the
// same mode drawing whole parts. And the clusters do cull: triangles are saved. Cluster
// history (useClusterHistory) keeps the same image while early parts draw fewer clusters,
// with its bits from boxes or from the draws' marks.
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "dyncull/engine/engine.hpp"
#include "dyncull/measure/image_compare.hpp"
#include "engine/gl_test_util.hpp"
#include "engine/procedural_meshes.hpp"
#include "objects/transform_at.hpp"

namespace dyncull {
namespace {

using test::at;

std::uint64_t differingPixels(const Image& a, const Image& b) {
    auto d = compareImages(a, b);
    EXPECT_TRUE(d.ok()) << d.error().message;
    return d.ok() ? d->differingPixels : ~std::uint64_t{0};
}

SchedulerParams paramsOf(CullMode mode, bool clusters) {
    SchedulerParams p;
    p.mode = mode;
    p.features.useClusters = clusters;
    p.features.useCostModel = false;  // test every cluster
    return p;
}

/// A ring of spheres round a box wall at the origin that hides some of them, drawn by a
/// headless engine; the camera circles them.
class SphereRing : public ::testing::Test {
protected:
    struct Ring {
        std::uint32_t maxLeafTriangles;  ///< local-BSP leaf size: parts of several clusters each
        int count;
        float radius, size;  ///< of the ring, and the smallest sphere's scale
        glm::vec3 wallScale;
    };

    void build(const Ring& r) {
        ctx_ = test::headless(160, 120);
        ASSERT_TRUE(ctx_);
        auto e = Engine::create(*ctx_);
        ASSERT_TRUE(e.ok()) << e.error().message;
        engine_ = e.take();
        LocalBspParams lp;
        lp.faces = FacePolicy::CullBack;
        lp.maxLeafTriangles = r.maxLeafTriangles;
        const ModelId sphere = *engine_->addModel(test::sphereMesh(1.0f, 48, 96), lp);
        ASSERT_GT(engine_->objects().model(sphere).clusters.clusters.size(), 40u);
        sceneClusters_ = engine_->objects().model(sphere).clusters.clusters.size() * std::size_t(r.count);
        const ModelId wall = *engine_->addModel(test::cubeMesh(1.0f));
        for (int i = 0; i < r.count; ++i) {
            const float a = 6.2831853f * float(i) / float(r.count), size = r.size + 0.1f * float(i % 4);
            Transform t = at({r.radius * std::cos(a), 0.3f * float(i % 3), r.radius * std::sin(a)}, size,
                             glm::angleAxis(0.7f * float(i), glm::normalize(glm::vec3(1.0f, 2.0f, 0.5f))));
            if (i == 3) t.scale = size * glm::vec3(-1.0f, 1.1f, 0.9f);  // mirrored: winding flips
            if (i == 6) t.scale = size * glm::vec3(1.5f, 0.5f, 1.0f);   // non-uniform
            ASSERT_TRUE(engine_->addObject(sphere, t).ok());
        }
        Transform w = at({0.0f, 0.0f, 0.0f});
        w.scale = r.wallScale;
        ASSERT_TRUE(engine_->addObject(wall, w).ok());
    }

    /// The camera on a circle of `radius` round the ring's centre at `height`, at `angle`.
    void circle(float angle, float radius, float height) {
        Camera cam = test::cameraOnZ(3.0f);
        cam.position = {radius * std::cos(angle), height, radius * std::sin(angle)};
        cam.target = {0.0f, 0.0f, 0.0f};
        cam.aspect = 160.0f / 120.0f;
        ASSERT_TRUE(engine_->setCamera(cam).ok());
    }

    /// One frame of `scheduler` from a cleared framebuffer, and its image.
    FrameStats render(QueryScheduler& scheduler, Image& image) {
        ctx_->clearFramebuffer(Renderer::kClearColour);
        auto st = engine_->renderFrame(scheduler);
        EXPECT_TRUE(st.ok()) << st.error().message;
        image = engine_->renderer().readPixels();
        return st.ok() ? *st : FrameStats{};
    }

    /// An ablation's check: two-phase with clusters with `feature` on (its default) and
    /// off each draw vfc's image in each of `frames` frames, the camera stepping `step`
    /// radians round the ring; `each(x, y)` takes both frames' stats (on, off).
    template <class Each>
    void onOffAgainstVfc(bool SchedulerFeatures::*feature, int frames, float step, Each each) {
        ASSERT_TRUE(paramsOf(CullMode::TwoPhase, true).features.*feature) << "the feature is on by default";
        onOffAgainstVfc([&](SchedulerParams& p) { p.features.*feature = false; }, frames, step, each);
    }
    /// The same with what `turnOff(params)` turns off.
    template <class TurnOff, class Each>
    void onOffAgainstVfc(TurnOff turnOff, int frames, float step, Each each) {
        SchedulerParams on = paramsOf(CullMode::TwoPhase, true), off = on;
        turnOff(off);
        QueryScheduler a(on), b(off), vfc(paramsOf(CullMode::Vfc, true));
        for (int f = 0; f < frames; ++f) {
            SCOPED_TRACE("frame " + std::to_string(f));
            circle(step * float(f), 8.0f, 1.0f);
            Image images[3];
            const FrameStats x = render(a, images[0]);
            const FrameStats y = render(b, images[1]);
            render(vfc, images[2]);
            EXPECT_EQ(differingPixels(images[0], images[2]), 0u);
            EXPECT_EQ(differingPixels(images[1], images[2]), 0u);
            each(x, y);
        }
        EXPECT_EQ(ctx_->checkErrors(), 0u);
    }

    /// Two-phase with the cost model where only cluster history's record is priced: the
    /// frame's tests always pay, and a probe comes every 8 frames.
    static SchedulerParams recordPricedParams() {
        SchedulerParams p = paramsOf(CullMode::TwoPhase, true);
        p.features.useCostModel = true;
        p.tuning.costs.depthReadNs = 0.0;
        p.tuning.costs.probeFrames = 8;
        return p;
    }

    std::unique_ptr<GlContext> ctx_;
    std::unique_ptr<Engine> engine_;
    std::size_t sceneClusters_ = 0;  ///< the spheres' clusters (the wall has none)
};
using ClusterCulling = SphereRing;
using ClusterHistory = SphereRing;

TEST_F(ClusterCulling, DrawsTheImageOfWholePartsAndCulls) {
    build({600, 10, 4.0f, 0.6f, {2.5f, 2.0f, 2.5f}});
    if (HasFatalFailure()) return;
    for (CullMode mode : {CullMode::Vfc, CullMode::TwoPhase}) {
        SCOPED_TRACE(toString(mode));
        QueryScheduler clustered(paramsOf(mode, true)), whole(paramsOf(mode, false));
        std::uint64_t culledTriangles = 0, drawnClustered = 0, drawnWhole = 0, pyramidTests = 0;
        for (int f = 0; f < 12; ++f) {
            // Circling at the ring's radius: spheres near, far, behind the wall and half
            // outside the frustum's edges.
            circle(0.3f * float(f), 9.0f, 1.5f);
            Image withClusters, wholeParts;
            const FrameStats a1 = render(clustered, withClusters);
            const FrameStats a2 = render(whole, wholeParts);
            EXPECT_EQ(differingPixels(withClusters, wholeParts), 0u) << "frame " << f;
            EXPECT_EQ(a2.clusterTests, 0u);
            EXPECT_EQ(a2.clusterPyramidTests, 0u);
            // A cluster meets a pyramid at most twice a frame: in the late pass (its part's,
            // or as a deferred cluster of an early part) and in cluster history's record.
            EXPECT_LE(a1.clusterPyramidTests, 2 * sceneClusters_);
            pyramidTests += a1.clusterPyramidTests;
            culledTriangles += a1.clusterTrianglesCulled;
            drawnClustered += a1.trianglesDrawn;
            drawnWhole += a2.trianglesDrawn;
        }
        std::printf("%s: %llu triangles drawn whole, %llu as clusters, %llu culled by cluster tests\n", toString(mode),
                    static_cast<unsigned long long>(drawnWhole), static_cast<unsigned long long>(drawnClustered),
                    static_cast<unsigned long long>(culledTriangles));
        EXPECT_EQ(ctx_->checkErrors(), 0u);
        // Closed spheres seen from outside: about half their triangles face away, and a
        // good share of those lie in clusters that face away whole.
        EXPECT_GT(culledTriangles, drawnWhole / 5);
        EXPECT_LT(drawnClustered, drawnWhole);
        // Only two-phase has a pyramid to test clusters against.
        if (mode == CullMode::Vfc) {
            EXPECT_EQ(pyramidTests, 0u);
        } else {
            EXPECT_GT(pyramidTests, 0u);
        }
    }
}

TEST_F(ClusterHistory, EarlyPartsDrawOnlyWhatShowedAndTheImageStaysExact) {
    // Two-phase with cluster history draws an early part's clusters hidden last frame only
    // when the late pass finds them visible. Large spheres half behind a wall, the camera
    // circling: clusters go into and out of hiding while their parts stay visible. Every
    // frame's image equals the one drawn with early parts whole, and vfc's; whether a
    // cluster showed is judged by its box against the final depth (the default) or by its
    // fragments' marks when drawn (useClusterMarks).
    build({2000, 8, 3.2f, 1.0f, {2.2f, 1.6f, 2.2f}});
    if (HasFatalFailure()) return;
    for (const bool marks : {false, true}) {
        SCOPED_TRACE(marks ? "bits from marks" : "bits from boxes");
        SchedulerParams withHistory = paramsOf(CullMode::TwoPhase, true), without = withHistory;
        withHistory.features.useClusterMarks = marks;
        without.features.useClusterHistory = false;
        QueryScheduler history(withHistory), whole(without), vfc(paramsOf(CullMode::Vfc, true));
        std::uint64_t deferred = 0, deferredDrawn = 0, drawnHistory = 0, drawnWhole = 0;
        for (int f = 0; f < 24; ++f) {
            circle(0.12f * float(f), 8.0f, 1.0f);
            Image images[3];
            const FrameStats h = render(history, images[0]);
            const FrameStats w = render(whole, images[1]);
            render(vfc, images[2]);
            deferred += h.clustersDeferred;
            deferredDrawn += h.deferredClustersDrawn;
            drawnHistory += h.trianglesDrawn;
            drawnWhole += w.trianglesDrawn;
            EXPECT_LE(h.deferredClustersDrawn, h.clustersDeferred);
            EXPECT_EQ(w.clustersDeferred, 0u);
            EXPECT_EQ(differingPixels(images[0], images[1]), 0u) << "frame " << f;
            EXPECT_EQ(differingPixels(images[0], images[2]), 0u) << "frame " << f;
        }
        std::printf("cluster history (%s): %llu clusters deferred, %llu of them drawn late; %llu triangles drawn against %llu\n",
                    marks ? "marks" : "boxes", static_cast<unsigned long long>(deferred),
                    static_cast<unsigned long long>(deferredDrawn), static_cast<unsigned long long>(drawnHistory),
                    static_cast<unsigned long long>(drawnWhole));
        EXPECT_EQ(ctx_->checkErrors(), 0u);
        // Clusters hid behind the wall and were held back from early passes; some came out
        // again (the camera moves) and the late pass drew them; in all, fewer triangles drawn.
        EXPECT_GT(deferred, 0u);
        EXPECT_GT(deferredDrawn, 0u);
        EXPECT_LT(drawnHistory, drawnWhole);
    }
}

TEST_F(ClusterHistory, TheWorkerDecidesAsTheRenderThreadDoes) {
    // The late pass's deferred clusters selected on a worker thread (useClusterWorker, the
    // default) against the same tests on the render thread as each part is drawn (the
    // reference): the same clusters deferred, culled and drawn, and the same image, every
    // frame. The frame-end record shares its tests with a second thread here at any size,
    // and its bits decide what the next frame defers. With the cost model off, nothing
    // else can make the two differ.
    build({2000, 8, 3.2f, 1.0f, {2.2f, 1.6f, 2.2f}});
    if (HasFatalFailure()) return;
    SchedulerParams worker = paramsOf(CullMode::TwoPhase, true), inline_ = worker;
    ASSERT_TRUE(worker.features.useClusterWorker);
    worker.tuning.recordWorkerClusters = 0;
    inline_.features.useClusterWorker = false;
    QueryScheduler a(worker), b(inline_);
    std::uint64_t deferredDrawn = 0;
    for (int f = 0; f < 24; ++f) {
        SCOPED_TRACE("frame " + std::to_string(f));
        circle(0.12f * float(f), 8.0f, 1.0f);
        Image images[2];
        const FrameStats x = render(a, images[0]);
        const FrameStats y = render(b, images[1]);
        EXPECT_EQ(x.trianglesDrawn, y.trianglesDrawn);
        EXPECT_EQ(x.partsDrawn, y.partsDrawn);
        EXPECT_EQ(x.clustersDeferred, y.clustersDeferred);
        EXPECT_EQ(x.deferredClustersDrawn, y.deferredClustersDrawn);
        EXPECT_EQ(x.clustersCulled, y.clustersCulled);
        EXPECT_EQ(x.clusterTrianglesCulled, y.clusterTrianglesCulled);
        EXPECT_EQ(x.clusterTests, y.clusterTests);
        EXPECT_EQ(x.clustersLearned, y.clustersLearned);
        EXPECT_EQ(differingPixels(images[0], images[1]), 0u);
        deferredDrawn += x.deferredClustersDrawn;
    }
    EXPECT_GT(deferredDrawn, 0u) << "the late pass drew no deferred cluster: the worker was never compared";
    EXPECT_EQ(ctx_->checkErrors(), 0u);
}

TEST_F(ClusterHistory, TheRecordTakesWhatTheFramesTestsLearned) {
    // The frame-end record takes the verdicts and footprints of the clusters the late pass
    // tested against an earlier pyramid (useLearnedClusters, the default) instead of
    // projecting them again (the reference): vfc's image every frame either way, and in
    // every frame that drew deferred clusters the record learned some. A cluster hidden by
    // an earlier pyramid is hidden in the final depth too, and a footprint in double is no
    // coarser than the record's own in float, so the early sets stay as small (the pyramid
    // levels the two read may differ: within 2%).
    build({2000, 8, 3.2f, 1.0f, {2.2f, 1.6f, 2.2f}});
    if (HasFatalFailure()) return;
    std::uint64_t learned = 0, earlyLearning = 0, earlyOwn = 0;
    onOffAgainstVfc(&SchedulerFeatures::useLearnedClusters, 24, 0.12f, [&](const FrameStats& x, const FrameStats& y) {
        EXPECT_EQ(y.clustersLearned, 0u);
        if (x.deferredClustersDrawn > 0) {
            EXPECT_GT(x.clustersLearned, 0u);
        }
        learned += x.clustersLearned;
        earlyLearning += x.earlyTriangles;
        earlyOwn += y.earlyTriangles;
    });
    std::printf("record with learned clusters: %llu learned; early triangles %llu against %llu projecting every cluster\n",
                static_cast<unsigned long long>(learned), static_cast<unsigned long long>(earlyLearning),
                static_cast<unsigned long long>(earlyOwn));
    EXPECT_GT(learned, 0u);
    EXPECT_LE(double(earlyLearning), 1.02 * double(earlyOwn));
}

TEST_F(ClusterCulling, PerTexelTestsHideMoreAndDrawVfcsImage) {
    // A volume or cluster the pyramid test at its span lets through is tested again texel
    // by texel against its front faces' planes (SchedulerTuning::texelTestTexels,
    // clusterTexelTests): it may hide more, never a pixel of vfc's image.
    build({2000, 8, 3.2f, 1.0f, {2.2f, 1.6f, 2.2f}});
    if (HasFatalFailure()) return;
    const SchedulerParams defaults = paramsOf(CullMode::TwoPhase, true);
    ASSERT_GT(defaults.tuning.texelTestTexels, 0);
    ASSERT_GT(defaults.tuning.clusterTexelTests, 0);
    std::uint64_t hiddenParts = 0, drawnOn = 0, drawnOff = 0;
    onOffAgainstVfc([](SchedulerParams& p) { p.tuning.texelTestTexels = p.tuning.clusterTexelTests = 0; }, 24, 0.12f,
                    [&](const FrameStats& x, const FrameStats& y) {
                        EXPECT_EQ(y.texelOccluded, 0u);
                        hiddenParts += x.texelOccluded;
                        drawnOn += x.trianglesDrawn;
                        drawnOff += y.trianglesDrawn;
                    });
    std::printf("per-texel tests: %llu parts hidden; %llu triangles drawn against %llu without\n",
                static_cast<unsigned long long>(hiddenParts), static_cast<unsigned long long>(drawnOn),
                static_cast<unsigned long long>(drawnOff));
    EXPECT_LT(drawnOn, drawnOff);
}

TEST_F(ClusterHistory, TheRecordIsPricedFromCountsSoTwinsDecideAlike) {
    // With the cost model on, cluster history's frame-end record runs while what its bits
    // saved exceeds its price, and otherwise every probeFrames frames. The price comes from
    // counts (TestCosts), not from the record's time, so two schedulers with the same
    // parameters decide alike in every frame however the threads were scheduled; a record
    // priced above any saving runs only on probe frames, and the frames after them are the
    // only ones that defer clusters; priced at nothing, it runs wherever it saved something.
    build({2000, 8, 3.2f, 1.0f, {2.2f, 1.6f, 2.2f}});
    if (HasFatalFailure()) return;
    SchedulerParams cheap = recordPricedParams();
    SchedulerParams dear = cheap;
    cheap.tuning.costs.pyramidNs = 0.0;
    cheap.tuning.costs.recordNsPerCluster = 0.0;
    dear.tuning.costs.recordNsPerCluster = 1e12;  // more than any drawing it could save
    QueryScheduler a(dear), twin(dear), c(cheap);
    constexpr int kFrames = 24;
    int deferringDear = 0, deferringCheap = 0;
    for (int f = 0; f < kFrames; ++f) {
        SCOPED_TRACE("frame " + std::to_string(f));
        circle(0.12f * float(f), 8.0f, 1.0f);
        Image images[3];
        const FrameStats x = render(a, images[0]);
        const FrameStats y = render(twin, images[1]);
        const FrameStats z = render(c, images[2]);
        EXPECT_EQ(x.trianglesDrawn, y.trianglesDrawn);
        EXPECT_EQ(x.pyramidBuilds, y.pyramidBuilds);
        EXPECT_EQ(x.clustersDeferred, y.clustersDeferred);
        EXPECT_EQ(x.earlyTriangles, y.earlyTriangles);
        EXPECT_EQ(differingPixels(images[0], images[2]), 0u);
        deferringDear += x.clustersDeferred > 0;
        deferringCheap += z.clustersDeferred > 0;
    }
    std::printf("frames deferring clusters: %d with the record priced above any saving, %d priced at nothing (of %d)\n",
                deferringDear, deferringCheap, kFrames);
    EXPECT_GE(deferringDear, 1);  // the probes still record
    // Until a frame with bits has measured what they save, the record runs (frames 0 and
    // 1); then once every probeFrames frames.
    EXPECT_LE(deferringDear, 1 + kFrames / 8);
    EXPECT_GT(deferringCheap, kFrames / 2);
    EXPECT_EQ(ctx_->checkErrors(), 0u);
}

TEST_F(ClusterHistory, ARecordSharingTheRefreshsReadIsNotChargedForIt) {
    // Where the parts' refresh has read the final depth already, the record's read would
    // otherwise have been the refresh's round of raster tests: it is priced at what it
    // costs beyond that round (pyramidNs - testNsPerBatch), not at pyramidNs. With both
    // at a price above any saving and the projections free, a record that shares the read
    // runs in more frames than one charged for it in full.
    build({2000, 8, 3.2f, 1.0f, {2.2f, 1.6f, 2.2f}});
    if (HasFatalFailure()) return;
    SchedulerParams shared = recordPricedParams();
    shared.tuning.costs.recordNsPerCluster = shared.tuning.costs.recordNsPerLearned = 0.0;
    shared.tuning.costs.pyramidNs = shared.tuning.costs.testNsPerBatch = 1e12;
    SchedulerParams charged = shared;
    charged.tuning.costs.testNsPerBatch = 0.0;
    QueryScheduler a(shared), b(charged), vfc(paramsOf(CullMode::Vfc, true));
    constexpr int kFrames = 24;
    int deferringShared = 0, deferringCharged = 0;
    for (int f = 0; f < kFrames; ++f) {
        SCOPED_TRACE("frame " + std::to_string(f));
        circle(0.12f * float(f), 8.0f, 1.0f);
        Image images[3];
        const FrameStats x = render(a, images[0]);
        const FrameStats y = render(b, images[1]);
        render(vfc, images[2]);
        EXPECT_EQ(differingPixels(images[0], images[2]), 0u);
        EXPECT_EQ(differingPixels(images[1], images[2]), 0u);
        deferringShared += x.clustersDeferred > 0;
        deferringCharged += y.clustersDeferred > 0;
    }
    std::printf("frames deferring clusters: %d with the shared read priced beyond a round, %d charged in full (of %d)\n",
                deferringShared, deferringCharged, kFrames);
    EXPECT_LE(deferringCharged, 1 + kFrames / 8);  // the probes, and frame 1
    EXPECT_GT(deferringShared, deferringCharged);
    EXPECT_EQ(ctx_->checkErrors(), 0u);
}

TEST_F(ClusterHistory, TheRefreshSharesTheRecordsReadAndKeepsTheImage) {
    // The parts drawn early are tested for next frame against the pyramid of the final
    // depth that the record reads anyway (useRefreshPyramid), not in a batched raster test
    // (the reference): vfc's image every frame, one batch a frame fewer, and no more
    // depth reads. The pyramid's answer is coarser, so the early set may hold more.
    build({2000, 8, 3.2f, 1.0f, {2.2f, 1.6f, 2.2f}});
    if (HasFatalFailure()) return;
    std::uint64_t batchesPyramid = 0, batchesRaster = 0, readsPyramid = 0, readsRaster = 0, earlyPyramid = 0, earlyRaster = 0;
    onOffAgainstVfc(&SchedulerFeatures::useRefreshPyramid, 24, 0.12f, [&](const FrameStats& x, const FrameStats& y) {
        batchesPyramid += x.rasterBatches;
        batchesRaster += y.rasterBatches;
        readsPyramid += x.pyramidBuilds;
        readsRaster += y.pyramidBuilds;
        earlyPyramid += x.earlyTriangles;
        earlyRaster += y.earlyTriangles;
    });
    std::printf("refresh on the record's pyramid: %llu raster batches against %llu, %llu depth reads against %llu, "
                "%llu early triangles against %llu\n",
                static_cast<unsigned long long>(batchesPyramid), static_cast<unsigned long long>(batchesRaster),
                static_cast<unsigned long long>(readsPyramid), static_cast<unsigned long long>(readsRaster),
                static_cast<unsigned long long>(earlyPyramid), static_cast<unsigned long long>(earlyRaster));
    // A batch fewer in each frame with parts to refresh (history skips some frames' parts).
    EXPECT_LT(batchesPyramid, batchesRaster);
    EXPECT_LE(readsPyramid, readsRaster);
}

TEST_F(ClusterCulling, PixelSizedClustersKeepTheImageExact) {
    // Spheres of one to a few pixels, so that most clusters cover a pixel centre or two, or
    // none: the depth-pyramid tests read only the pixels whose centres a box can cover
    // (DepthFootprint::centres), and call a box that covers none hidden. Every frame, with the
    // camera circling (so the boxes slide across pixel centres), two-phase with clusters draws
    // vfc's image.
    build({600, 40, 4.0f, 0.04f, {2.5f, 2.0f, 2.5f}});
    if (HasFatalFailure()) return;
    QueryScheduler twoPhase(paramsOf(CullMode::TwoPhase, true)), vfc(paramsOf(CullMode::Vfc, false));
    std::uint64_t culled = 0;
    for (int f = 0; f < 16; ++f) {
        circle(0.05f * float(f), 9.0f, 1.0f + 0.013f * float(f));
        Image images[2];
        culled += render(twoPhase, images[0]).clusterTrianglesCulled;
        render(vfc, images[1]);
        EXPECT_EQ(differingPixels(images[0], images[1]), 0u) << "frame " << f;
    }
    EXPECT_EQ(ctx_->checkErrors(), 0u);
    EXPECT_GT(culled, 0u);
}

}  // namespace
}  // namespace dyncull

namespace dyncull {
namespace {

TEST_F(ClusterHistory, RoundPyramidsKeepTheImageAndCullMore) {
    // The clusters of the parts a round of raster tests lets through are tested against a
    // pyramid built again from the depth drawn so far (useRoundPyramids), not the early
    // pass's: the same image as without, and as vfc's, every frame, with fewer triangles.
    build({2000, 8, 3.2f, 1.0f, {2.2f, 1.6f, 2.2f}});
    if (HasFatalFailure()) return;
    std::uint64_t drawnRound = 0, drawnEarly = 0, extraBuilds = 0;
    onOffAgainstVfc(&SchedulerFeatures::useRoundPyramids, 24, 0.25f, [&](const FrameStats& x, const FrameStats& y) {
        drawnRound += x.trianglesDrawn;
        drawnEarly += y.trianglesDrawn;
        extraBuilds += x.pyramidBuilds - y.pyramidBuilds;
    });
    std::printf("round pyramids: %llu more built, %llu triangles drawn against %llu\n", static_cast<unsigned long long>(extraBuilds),
                static_cast<unsigned long long>(drawnRound), static_cast<unsigned long long>(drawnEarly));
    EXPECT_GT(extraBuilds, 0u);
    EXPECT_LT(drawnRound, drawnEarly);
}

}  // namespace
}  // namespace dyncull
