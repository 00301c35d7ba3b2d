// Numerical extremes and degenerate input through the whole pipeline (issue: robustness).
// Each case renders with vfc (the reference image) and with conservative full occlusion
// culling, and asserts concrete outcomes: the images are identical (<= 0.01% of pixels),
// full mode misses no part the ID-pass ground truth sees, and bad values are rejected at
// the Engine boundary with an error while the previous state stays.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "engine/extremes_rig.hpp"
#include "engine/procedural_meshes.hpp"

namespace dyncull {
namespace {

using test::expectConservative;
using test::kHeight;
using test::kWidth;
using test::look;
using test::nonBackground;
using test::Rig;

// ---- API boundary -----------------------------------------------------------------

TEST(Extremes, NonFiniteTransformsAndCamerasAreRejectedAndTheOldStateStays) {
    Rig rig;
    ASSERT_TRUE(rig.ok());
    const ModelId cube = rig.model(test::cubeMesh(0.5f));
    const ObjectHandle h = rig.object(cube, {0, 0, 0});
    const glm::mat4 before = rig.engine->objects().matrix(h.index);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    for (float bad : {nan, inf, -inf}) {
        Transform t;
        t.translation = {0, bad, 0};
        EXPECT_FALSE(rig.engine->setTransform(h, t).ok());
        EXPECT_FALSE(rig.engine->addObject(cube, t).ok());
        t = Transform{};
        t.scale = {1, 1, bad};
        EXPECT_FALSE(rig.engine->setTransform(h, t).ok());
        t = Transform{};
        t.rotation.x = bad;
        EXPECT_FALSE(rig.engine->setTransform(h, t).ok());
        EXPECT_EQ(rig.engine->objects().matrix(h.index), before);

        const Camera good = look({0, 0, 5}, {0, 0, 0});
        ASSERT_TRUE(rig.engine->setCamera(good).ok());
        Camera c = good;
        c.position.x = bad;
        EXPECT_FALSE(rig.engine->setCamera(c).ok());
        c = good;
        c.target.z = bad;
        EXPECT_FALSE(rig.engine->setCamera(c).ok());
        c = good;
        c.fovYRadians = bad;
        EXPECT_FALSE(rig.engine->setCamera(c).ok());
        c = good;
        c.nearPlane = bad;
        EXPECT_FALSE(rig.engine->setCamera(c).ok());
        c = good;
        c.farPlane = bad;
        EXPECT_FALSE(rig.engine->setCamera(c).ok());
        c = good;
        c.aspect = bad;
        EXPECT_FALSE(rig.engine->setCamera(c).ok());
        EXPECT_EQ(rig.engine->camera().position, good.position);
    }
    Mesh m = test::cubeMesh(0.5f);
    m.positions[3].y = nan;
    EXPECT_FALSE(rig.engine->addModel(m).ok());  // non-finite vertex: error, nothing uploaded
    // The scene still renders after all the rejected calls.
    const auto r = rig.frame(look({0, 0, 5}, {0, 0, 0}));
    expectConservative(r, "after rejections");
    EXPECT_GT(nonBackground(r.queriesImage), 100u);
}

// ---- Degenerate meshes -------------------------------------------------------------

TEST(Extremes, ZeroAreaDuplicateAndSingleTriangleMeshesRenderConservatively) {
    Rig rig;
    ASSERT_TRUE(rig.ok());
    Mesh one;  // a single triangle
    one.positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
    one.indices = {0, 1, 2};
    Mesh degenerate = test::cubeMesh(0.5f);
    const std::size_t real = degenerate.indices.size();
    for (std::size_t i = 0; i < real; i += 3) {  // every triangle twice, plus zero-area ones
        degenerate.indices.insert(degenerate.indices.end(), {degenerate.indices[i], degenerate.indices[i + 1], degenerate.indices[i + 2]});
        degenerate.indices.insert(degenerate.indices.end(), {degenerate.indices[i], degenerate.indices[i], degenerate.indices[i + 1]});
    }
    degenerate.positions.push_back({0.2f, 0.2f, 0.2f});  // collinear sliver and a point triangle
    degenerate.positions.push_back({0.3f, 0.3f, 0.3f});
    degenerate.positions.push_back({0.4f, 0.4f, 0.4f});
    const auto n = static_cast<std::uint32_t>(degenerate.positions.size());
    degenerate.indices.insert(degenerate.indices.end(), {n - 3, n - 2, n - 1, n - 1, n - 1, n - 1});
    degenerate.normals.clear();
    Mesh allDegenerate;  // only zero-area triangles: nothing to see, nothing to break
    allDegenerate.positions = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
    allDegenerate.indices = {0, 1, 2, 0, 0, 0};

    const ModelId a = rig.model(one), b = rig.model(degenerate), c = rig.model(allDegenerate);
    rig.object(a, {0, 0, 0});
    rig.object(b, {0, 0, -3});  // behind the triangle, partly hidden
    rig.object(b, {2.5f, 0, -1});
    rig.object(c, {-2, 0, -1});
    const auto r = rig.frame(look({0, 0, 4}, {0, 0, -1}));
    expectConservative(r, "degenerate meshes");
    EXPECT_GT(nonBackground(r.vfcImage), 500u);
    EXPECT_GT(r.visibleParts, 1u);
}

TEST(Extremes, OneMillionTriangleObject) {
    // A single 1,000,000-triangle sphere (500 rings x 1,000 segments x 2), half hidden by
    // a box in front: the local BSP builds, and full mode draws exactly what vfc draws.
    Rig rig;
    ASSERT_TRUE(rig.ok());
    const Mesh big = test::sphereMesh(1.0f, 500, 1000);
    ASSERT_EQ(big.indices.size() / 3, 1000000u);
    const auto t0 = std::chrono::steady_clock::now();
    const ModelId sphere = rig.model(big);
    const double buildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const LocalBsp& bsp = rig.engine->model(sphere);
    EXPECT_GE(bsp.stats.trianglesAfter, 1000000u);
    EXPECT_GT(bsp.stats.leaves, 100u);
    rig.object(sphere, {0, 0, 0});
    rig.object(rig.model(test::cubeMesh(0.6f)), {0.5f, 0, 1.8f});
    const auto r = rig.frame(look({0, 0, 4}, {0, 0, 0}));
    expectConservative(r, "1M triangles");
    EXPECT_GT(r.queriesStats.queriesOccluded, 0u);  // the hidden back half was culled by queries
    std::printf("1M-triangle sphere: local BSP %u leaves, %zu triangles after splitting, built in %.0f ms; "
                "full drew %u of %u parts\n",
                bsp.stats.leaves, bsp.stats.trianglesAfter, buildMs, r.queriesStats.partsDrawn, r.vfcStats.partsDrawn);
}

// ---- Scale and position ------------------------------------------------------------

TEST(Extremes, ObjectsScaledByOneMillionthAndOneMillion) {
    // The same 3-object arrangement (a sphere behind a cube, one beside) at scale 1e-6
    // and 1e6, camera and clip planes scaled with it: same picture, full exact.
    Image reference;
    for (float scale : {1.0f, 1e-6f, 1e6f}) {
        Rig rig;
        ASSERT_TRUE(rig.ok());
        const ModelId cube = rig.model(test::cubeMesh(0.5f)), sphere = rig.model(test::sphereMesh(0.5f, 16, 32));
        rig.object(cube, glm::vec3(0, 0, 1) * scale, glm::vec3(scale));
        rig.object(sphere, glm::vec3(0, 0, -1) * scale, glm::vec3(scale));
        rig.object(sphere, glm::vec3(1.5f, 0, 0) * scale, glm::vec3(scale));
        const auto r = rig.frame(look(glm::vec3(0, 0.5f, 5) * scale, glm::vec3(0), 0.05f * scale, 100.0f * scale));
        expectConservative(r, "scale " + std::to_string(scale));
        EXPECT_GT(r.queriesStats.queriesOccluded + r.queriesStats.skippedByOccupancy, 0u);
        if (scale == 1.0f) {
            reference = r.vfcImage;
            continue;
        }
        auto d = compareImages(reference, r.vfcImage);
        ASSERT_TRUE(d.ok());
        EXPECT_LE(d->percentDiffering, 0.5) << "scale " << scale;  // same picture up to rounding at edges
    }
}

TEST(Extremes, CameraInsideAnObjectBoxAndInsideALocalBspNode) {
    // A big hollow-looking sphere (many local-BSP leaves) with the camera inside it near
    // the wall: the camera is inside the object's box, inside the root node and inside
    // some leaf boxes. Those are never queried (a query volume around the eye is clipped)
    // and the picture matches vfc.
    Rig rig;
    ASSERT_TRUE(rig.ok());
    const ModelId sphere = rig.model(test::sphereMesh(5.0f, 64, 128));
    ASSERT_GT(rig.engine->model(sphere).nodes.size(), 3u);
    rig.object(sphere, {0, 0, 0});
    rig.object(rig.model(test::cubeMesh(0.5f)), {0, 0, -2});
    for (const glm::vec3& eye : {glm::vec3(0, 0, 0), glm::vec3(0, 0, 4.6f), glm::vec3(3.2f, 3.2f, 0)}) {
        const auto r = rig.frame(look(eye, eye + glm::vec3(0, 0, -1)));
        expectConservative(r, "camera inside");
        EXPECT_GT(r.queriesStats.visibleNearOrInside, 1u);  // the object box and at least one node
        EXPECT_GT(nonBackground(r.queriesImage), static_cast<std::uint64_t>(kWidth * kHeight / 2));
    }
}

TEST(Extremes, BoxesStraddlingTheNearPlane) {
    // Cubes cut by the near plane (camera just outside them, near plane inside them) hide
    // a row of spheres behind; some are cut at the image edge too.
    Rig rig;
    ASSERT_TRUE(rig.ok());
    const ModelId cube = rig.model(test::cubeMesh(0.5f)), sphere = rig.model(test::sphereMesh(0.3f, 12, 24));
    for (int i = -2; i <= 2; ++i) {
        rig.object(cube, {static_cast<float>(i) * 1.1f, 0, 0});
        rig.object(sphere, {static_cast<float>(i) * 1.1f, 0, -3});
    }
    for (float nearPlane : {0.4f, 0.55f, 0.9f}) {
        const auto r = rig.frame(look({0, 0, 0.8f}, {0, 0, -1}, nearPlane));
        expectConservative(r, "near " + std::to_string(nearPlane));
        EXPECT_GT(r.queriesStats.visibleNearOrInside, 0u);
    }
}

TEST(Extremes, SceneFarFromTheOriginRendersLikeAtTheOrigin) {
    // The same scene (unit cubes and spheres at integer positions, one hiding others)
    // translated 1e3, 1e5 and 1e7 units along (1, 1, 1), the camera moved with it: the
    // picture must match the scene at the origin within 0.01% of pixels, and full mode
    // stay exact. Integer offsets are exact in float even at 1e7 (spacing 1), so any
    // difference is precision lost in rendering, which camera-relative transforms avoid.
    Image atOrigin;
    for (double offset : {0.0, 1e3, 1e5, 1e7}) {
        Rig rig;
        ASSERT_TRUE(rig.ok());
        const glm::vec3 o(static_cast<float>(offset));
        const ModelId cube = rig.model(test::cubeMesh(0.5f)), sphere = rig.model(test::sphereMesh(0.5f, 16, 32));
        rig.object(cube, o + glm::vec3(0, 0, 1));
        for (int i = -2; i <= 2; ++i) rig.object(sphere, o + glm::vec3(static_cast<float>(i), 0, -2));
        rig.object(cube, o + glm::vec3(2, 1, 0));
        const auto r = rig.frame(look(o + glm::vec3(1, 2, 6), o + glm::vec3(0, 0, -1)));
        expectConservative(r, "offset " + std::to_string(offset));
        if (offset == 0.0) {
            atOrigin = r.vfcImage;
            EXPECT_GT(nonBackground(atOrigin), 2000u);
            continue;
        }
        auto d = compareImages(atOrigin, r.vfcImage);
        ASSERT_TRUE(d.ok());
        std::printf("offset %.0e: %.4f%% of pixels differ from the scene at the origin\n", offset, d->percentDiffering);
        EXPECT_LE(d->percentDiffering, 0.01) << "offset " << offset;
    }
}

TEST(Extremes, ObjectsCrossingTheWholeWorldInOneFrameAndLeavingIt) {
    // Twenty objects jump between opposite corners of a 2,000-unit world every frame, and
    // then leave the world box (1e6 units out); the tree stays valid and full mode exact.
    Rig rig;
    ASSERT_TRUE(rig.ok());
    const ModelId cube = rig.model(test::cubeMesh(0.5f));
    std::vector<ObjectHandle> hs;
    for (int i = 0; i < 20; ++i) hs.push_back(rig.object(cube, {static_cast<float>(i % 5) * 2 - 4, static_cast<float>(i / 5) * 2 - 3, -1000}));
    rig.object(cube, {1000, 1000, 1000});  // fixes the world box corners
    for (int frame = 0; frame < 6; ++frame) {
        for (int i = 0; i < 20; ++i) {
            Transform t;
            const float side = ((frame + i) % 2) ? 1000.0f : -1000.0f;
            t.translation = {static_cast<float>(i % 5) * 2 - 4 + (frame >= 4 ? 1e6f : 0.0f), static_cast<float>(i / 5) * 2 - 3, side};
            ASSERT_TRUE(rig.engine->setTransform(hs[static_cast<std::size_t>(i)], t).ok());
        }
        rig.engine->updateSceneTree();
        EXPECT_TRUE(rig.engine->sceneTree().validate(rig.engine->objects()).empty()) << "frame " << frame;
        const auto r = rig.frame(look({0, 0, -1010}, {0, 0, 0}, 0.5f, 5000.0f));
        expectConservative(r, "frame " + std::to_string(frame));
        if (frame < 4) {
            EXPECT_GT(nonBackground(r.vfcImage), 100u) << "frame " << frame;
        }
    }
}

}  // namespace
}  // namespace dyncull
