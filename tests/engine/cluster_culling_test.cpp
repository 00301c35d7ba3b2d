// Cluster culling (SchedulerParams::useClusters) draws exactly the image of whole parts:
// spheres whose back faces are culled — rotated, scaled, one mirrored, some crossing the
// frustum's edge, some behind a wall — seen from a camera circling them, in vfc (cones and
// frustum) and full (the depth pyramid too), each frame compared pixel for pixel with the
// same mode drawing whole parts. And the clusters do cull: triangles are saved.
#include <cmath>
#include <cstdio>
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

TEST(ClusterCulling, DrawsTheImageOfWholePartsAndCulls) {
    auto ctx = test::headless(160, 120);
    ASSERT_TRUE(ctx);
    auto e = Engine::create(*ctx);
    ASSERT_TRUE(e.ok()) << e.error().message;
    auto engine = e.take();
    LocalBspParams lp;
    lp.faces = FacePolicy::CullBack;
    lp.maxLeafTriangles = 600;  // parts of several clusters each
    const ModelId sphere = *engine->addModel(test::sphereMesh(1.0f, 48, 96), lp);
    ASSERT_GT(engine->objects().model(sphere).clusters.clusters.size(), 40u);
    const ModelId wall = *engine->addModel(test::cubeMesh(1.0f));
    // A ring of spheres around the origin and a wall in the middle hiding some of them.
    for (int i = 0; i < 10; ++i) {
        const float a = 0.628f * float(i);
        Transform t = at({4.0f * std::cos(a), 0.3f * float(i % 3), 4.0f * std::sin(a)}, 0.6f + 0.1f * float(i % 4),
                         glm::angleAxis(0.7f * float(i), glm::normalize(glm::vec3(1.0f, 2.0f, 0.5f))));
        if (i == 3) t.scale = glm::vec3(-0.8f, 0.9f, 1.1f);  // mirrored: winding flips
        if (i == 6) t.scale = glm::vec3(1.5f, 0.5f, 1.0f);   // non-uniform
        ASSERT_TRUE(engine->addObject(sphere, t).ok());
    }
    Transform w = at({0.0f, 0.0f, 0.0f});
    w.scale = glm::vec3(2.5f, 2.0f, 2.5f);
    ASSERT_TRUE(engine->addObject(wall, w).ok());

    for (CullMode mode : {CullMode::Vfc, CullMode::TwoPhase}) {
        SCOPED_TRACE(toString(mode));
        QueryScheduler clustered(paramsOf(mode, true)), whole(paramsOf(mode, false));
        std::uint64_t culledTriangles = 0, drawnClustered = 0, drawnWhole = 0;
        for (int f = 0; f < 12; ++f) {
            // Circling at the ring's radius: spheres near, far, behind the wall and half
            // outside the frustum's edges.
            const float a = 0.3f * float(f);
            Camera cam = test::cameraOnZ(3.0f);
            cam.position = {9.0f * std::cos(a), 1.5f, 9.0f * std::sin(a)};
            cam.target = {0.0f, 0.0f, 0.0f};
            cam.aspect = 160.0f / 120.0f;
            ASSERT_TRUE(engine->setCamera(cam).ok());
            ctx->clearFramebuffer(Renderer::kClearColour);
            auto a1 = engine->renderFrame(clustered);
            ASSERT_TRUE(a1.ok()) << a1.error().message;
            const Image withClusters = engine->renderer().readPixels();
            ctx->clearFramebuffer(Renderer::kClearColour);
            auto a2 = engine->renderFrame(whole);
            ASSERT_TRUE(a2.ok()) << a2.error().message;
            const Image wholeParts = engine->renderer().readPixels();
            EXPECT_EQ(differingPixels(withClusters, wholeParts), 0u) << "frame " << f;
            EXPECT_EQ(a2->clusterTests, 0u);
            culledTriangles += a1->clusterTrianglesCulled;
            drawnClustered += a1->trianglesDrawn;
            drawnWhole += a2->trianglesDrawn;
        }
        std::printf("%s: %llu triangles drawn whole, %llu as clusters, %llu culled by cluster tests\n", toString(mode),
                    static_cast<unsigned long long>(drawnWhole), static_cast<unsigned long long>(drawnClustered),
                    static_cast<unsigned long long>(culledTriangles));
        EXPECT_EQ(ctx->checkErrors(), 0u);
        // Closed spheres seen from outside: about half their triangles face away, and a
        // good share of those lie in clusters that face away whole.
        EXPECT_GT(culledTriangles, drawnWhole / 5);
        EXPECT_LT(drawnClustered, drawnWhole);
    }
}

TEST(ClusterHistory, EarlyPartsDrawOnlyWhatShowedAndTheImageStaysExact) {
    // Two-phase with cluster history draws an early part's clusters hidden last frame only
    // when the late pass finds them visible. Spheres half behind a wall, the camera
    // circling: clusters go into and out of hiding while their parts stay visible. Every
    // frame's image equals the one drawn with early parts whole, and with vfc's.
    auto ctx = test::headless(160, 120);
    ASSERT_TRUE(ctx);
    auto e = Engine::create(*ctx);
    ASSERT_TRUE(e.ok()) << e.error().message;
    auto engine = e.take();
    LocalBspParams lp;
    lp.faces = FacePolicy::CullBack;
    lp.maxLeafTriangles = 2000;  // large parts, each of many clusters: parts stay visible while clusters hide
    const ModelId sphere = *engine->addModel(test::sphereMesh(1.0f, 48, 96), lp);
    const ModelId wall = *engine->addModel(test::cubeMesh(1.0f));
    for (int i = 0; i < 8; ++i) {
        const float a = 0.785f * float(i);
        Transform t = at({3.2f * std::cos(a), 0.2f * float(i % 3), 3.2f * std::sin(a)}, 1.0f + 0.1f * float(i % 3),
                         glm::angleAxis(0.5f * float(i), glm::normalize(glm::vec3(1.0f, 2.0f, 0.5f))));
        if (i == 5) t.scale = glm::vec3(-1.0f, 1.1f, 0.9f);  // mirrored
        ASSERT_TRUE(engine->addObject(sphere, t).ok());
    }
    Transform w = at({0.0f, 0.0f, 0.0f});
    w.scale = glm::vec3(2.2f, 1.6f, 2.2f);
    ASSERT_TRUE(engine->addObject(wall, w).ok());

    SchedulerParams withHistory = paramsOf(CullMode::TwoPhase, true), without = withHistory;
    without.features.useClusterHistory = false;
    QueryScheduler history(withHistory), whole(without), vfc(paramsOf(CullMode::Vfc, true));
    std::uint64_t deferred = 0, deferredDrawn = 0, drawnHistory = 0, drawnWhole = 0;
    for (int f = 0; f < 24; ++f) {
        const float a = 0.12f * float(f);
        Camera cam = test::cameraOnZ(3.0f);
        cam.position = {8.0f * std::cos(a), 1.0f, 8.0f * std::sin(a)};
        cam.target = {0.0f, 0.0f, 0.0f};
        cam.aspect = 160.0f / 120.0f;
        ASSERT_TRUE(engine->setCamera(cam).ok());
        Image images[3];
        QueryScheduler* scheds[3] = {&history, &whole, &vfc};
        for (int m = 0; m < 3; ++m) {
            ctx->clearFramebuffer(Renderer::kClearColour);
            auto st = engine->renderFrame(*scheds[m]);
            ASSERT_TRUE(st.ok()) << st.error().message;
            images[m] = engine->renderer().readPixels();
            if (m == 0) {
                deferred += st->clustersDeferred;
                deferredDrawn += st->deferredClustersDrawn;
                drawnHistory += st->trianglesDrawn;
                EXPECT_LE(st->deferredClustersDrawn, st->clustersDeferred);
            } else if (m == 1) {
                drawnWhole += st->trianglesDrawn;
                EXPECT_EQ(st->clustersDeferred, 0u);
            }
        }
        EXPECT_EQ(differingPixels(images[0], images[1]), 0u) << "frame " << f;
        EXPECT_EQ(differingPixels(images[0], images[2]), 0u) << "frame " << f;
    }
    std::printf("cluster history: %llu clusters deferred, %llu of them drawn late; %llu triangles drawn against %llu\n",
                static_cast<unsigned long long>(deferred), static_cast<unsigned long long>(deferredDrawn),
                static_cast<unsigned long long>(drawnHistory), static_cast<unsigned long long>(drawnWhole));
    EXPECT_EQ(ctx->checkErrors(), 0u);
    // Clusters hid behind the wall and held back from early passes; some came out again
    // (the camera moves) and the late pass drew them; in all, fewer triangles were drawn.
    EXPECT_GT(deferred, 0u);
    EXPECT_GT(deferredDrawn, 0u);
    EXPECT_LT(drawnHistory, drawnWhole);
}

}  // namespace
}  // namespace dyncull
