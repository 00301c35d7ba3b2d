// Orthographic cameras (Camera::orthoHeight): the projection's depth convention, its
// frustum, and every mode drawing the vfc image through one, including an object that
// crosses the near plane and a second, orthographic view beside a perspective one (a
// shadow-map camera).
#include <vector>

#include <gtest/gtest.h>

#include "dyncull/engine/engine.hpp"
#include "engine/gl_test_util.hpp"
#include "engine/procedural_meshes.hpp"
#include "objects/transform_at.hpp"

namespace dyncull {
namespace {

using test::at;

Camera orthoOnZ() {
    Camera c = test::cameraOnZ(3.0f);
    c.orthoHeight = 3.0f;  // 3 world units from bottom to top
    c.nearPlane = 1.0f;
    c.farPlane = 10.0f;
    return c;
}

TEST(Orthographic, ProjectionIsReversedZeroToOneAndLinear) {
    const Camera c = orthoOnZ();
    ASSERT_TRUE(validateCamera(c).ok());
    const glm::dmat4 vp = c.viewProjectionRelativeDouble();
    auto clipOf = [&](glm::dvec3 world) { return vp * glm::dvec4(world - glm::dvec3(c.position), 1.0); };
    EXPECT_NEAR(clipOf({0, 0, 2}).z, 1.0, 1e-12);   // distance 1: the near plane
    EXPECT_NEAR(clipOf({0, 0, -7}).z, 0.0, 1e-12);  // distance 10: the far plane
    EXPECT_NEAR(clipOf({0, 0, -2.5}).z, 0.5, 1e-12);  // linear in between
    EXPECT_NEAR(clipOf({1.5, 1.5, 0}).y, 1.0, 1e-12);  // half the height, whatever the distance
    EXPECT_NEAR(clipOf({1.5, 1.5, -5}).y, 1.0, 1e-12);
    EXPECT_EQ(clipOf({1.5, 1.5, -5}).w, 1.0);
    EXPECT_NEAR(glm::dot(c.distanceRowRelative(), glm::dvec4(0, 0, -4, 1)), 4.0, 1e-12);

    const Frustum f = Frustum::fromCamera(c);
    EXPECT_FALSE(f.outside(Aabb::fromMinMax({1.4f, 1.4f, -6.5f}, {1.6f, 1.6f, -6.0f})));  // a far corner: no perspective shrink
    EXPECT_TRUE(f.outside(Aabb::fromMinMax({1.6f, 0.0f, -1.0f}, {2.0f, 0.5f, 0.0f})));   // beside the view
    EXPECT_TRUE(f.outside(Aabb::fromMinMax({0.0f, 0.0f, 2.2f}, {0.5f, 0.5f, 2.9f})));    // before the near plane

    Camera bad = c;
    bad.orthoHeight = -1.0f;
    EXPECT_FALSE(validateCamera(bad).ok());
}

SchedulerParams modeParams(CullMode mode, bool triangles = false) {
    SchedulerParams p;
    p.mode = mode;
    p.features.useCostModel = false;
    p.features.useTriangleTests = triangles;
    return p;
}

std::uint64_t differing(const Image& a, const Image& b) {
    std::uint64_t n = 0;
    for (std::size_t i = 0; i < a.rgba.size() && i < b.rgba.size(); ++i) n += a.rgba[i] != b.rgba[i];
    return n;
}

TEST(Orthographic, EveryModeDrawsTheVfcImageAndCullsBehindAWall) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    auto made = Engine::create(*ctx);
    ASSERT_TRUE(made.ok()) << made.error().message;
    Engine& engine = **made;
    const ModelId quad = *engine.addModel(test::quadMesh(1.0f));
    const ModelId ball = *engine.addModel(test::sphereMesh(0.3f, 16, 32));
    ASSERT_TRUE(engine.addObject(quad, at({0, 0, 0})).ok());
    const ObjectHandle hidden = *engine.addObject(ball, at({0.2f, -0.2f, -2.0f}));
    const ObjectHandle front = *engine.addObject(ball, at({0.6f, 0.6f, 1.0f}));
    const ObjectHandle crossing = *engine.addObject(ball, at({-1.2f, 1.1f, 2.0f}));  // through the near plane (z = 2)
    // Beside the wall: in perspective the wall would hide it, orthographic does not shrink it.
    const ObjectHandle beside = *engine.addObject(ball, at({1.2f, 0.0f, -6.0f}));
    ASSERT_TRUE(engine.setCamera(orthoOnZ()).ok());

    auto run = [&](const SchedulerParams& p, int frames) {
        QueryScheduler scheduler(p);
        for (int f = 0; f < frames; ++f) {
            ctx->clearFramebuffer(Renderer::kClearColour);
            auto st = engine.renderFrame(scheduler);
            EXPECT_TRUE(st.ok()) << st.error().message;
        }
        EXPECT_EQ(ctx->checkErrors(), 0u);
        return engine.renderer().readPixels();
    };
    const Image reference = run(modeParams(CullMode::Vfc), 1);
    struct Mode {
        const char* name;
        SchedulerParams params;
    };
    const Mode modes[] = {{"simple", modeParams(CullMode::Simple)},
                          {"queries", modeParams(CullMode::Queries)},
                          {"full", modeParams(CullMode::TwoPhase)},
                          {"full-tri", modeParams(CullMode::TwoPhase, true)}};
    for (const Mode& m : modes) {
        const Image image = run(m.params, 4);
        EXPECT_EQ(differing(reference, image), 0u) << m.name;
        EXPECT_FALSE(engine.isVisible(hidden)) << m.name;
        EXPECT_TRUE(engine.isVisible(front)) << m.name;
        EXPECT_TRUE(engine.isVisible(crossing)) << m.name;
        EXPECT_TRUE(engine.isVisible(beside)) << m.name;
    }

    // An orthographic view beside the perspective main view, each drawn alone and side by side.
    Camera perspective = test::cameraOnZ(3.0f);
    ASSERT_TRUE(engine.setCamera(perspective).ok());
    auto shadow = engine.addView(orthoOnZ(), modeParams(CullMode::TwoPhase));
    ASSERT_TRUE(shadow.ok()) << shadow.error().message;
    for (int f = 0; f < 3; ++f) {
        ctx->clearFramebuffer(Renderer::kClearColour);
        ASSERT_TRUE(engine.renderView(*shadow).ok());
    }
    EXPECT_EQ(differing(reference, engine.renderer().readPixels()), 0u);
    EXPECT_FALSE(engine.isVisible(hidden, *shadow));
    EXPECT_TRUE(engine.isVisible(beside, *shadow));
}

}  // namespace
}  // namespace dyncull
