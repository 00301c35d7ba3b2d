// Occlusion roles (OcclusionRole, Engine::setRole) in every mode: an occluder-only wall is
// drawn untested and first, so even the first two-phase frame culls what it hides; an
// occludee-only pane is tested but hides nothing (no depth), and is culled only behind what
// does occlude; and the roles' bookkeeping survives removal, slot reuse and setModel.
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "dyncull/engine/engine.hpp"
#include "engine/gl_test_util.hpp"
#include "engine/procedural_meshes.hpp"
#include "objects/transform_at.hpp"

namespace dyncull {
namespace {

using test::at;

SchedulerParams modeParams(CullMode mode, bool triangles = false) {
    SchedulerParams p;
    p.mode = mode;
    p.features.useCostModel = false;  // two-phase tests every frame
    p.features.useTriangleTests = triangles;
    return p;
}

struct Mode {
    const char* name;
    SchedulerParams params;
};

std::vector<Mode> everyMode() {
    return {{"vfc", modeParams(CullMode::Vfc)},
            {"simple", modeParams(CullMode::Simple)},
            {"queries", modeParams(CullMode::Queries)},
            {"full", modeParams(CullMode::TwoPhase)},
            {"full-tri", modeParams(CullMode::TwoPhase, true)}};
}

struct Scene {
    std::unique_ptr<GlContext> ctx = test::headless();
    std::unique_ptr<Engine> engine;
    ModelId quad = 0, ball = 0;

    Scene() {
        if (!ctx) return;
        auto e = Engine::create(*ctx);
        EXPECT_TRUE(e.ok()) << (e.ok() ? "" : e.error().message);
        if (!e) return;
        engine = e.take();
        quad = *engine->addModel(test::quadMesh(1.0f));
        ball = *engine->addModel(test::sphereMesh(0.3f));
        EXPECT_TRUE(engine->setCamera(test::cameraOnZ(3.0f)).ok());
    }
    /// `frames` frames with a fresh scheduler; the last one's image and window depths.
    void run(const SchedulerParams& params, int frames, Image& image, std::vector<float>* depth = nullptr) {
        QueryScheduler scheduler(params);
        for (int f = 0; f < frames; ++f) {
            ctx->clearFramebuffer(Renderer::kClearColour);
            auto st = engine->renderFrame(scheduler);
            ASSERT_TRUE(st.ok()) << st.error().message;
        }
        image = engine->renderer().readPixels();
        if (depth) {
            depth->resize(std::size_t{test::kW} * test::kH);
            glBindFramebuffer(GL_READ_FRAMEBUFFER, ctx->framebuffer());
            glReadPixels(0, 0, test::kW, test::kH, GL_DEPTH_COMPONENT, GL_FLOAT, depth->data());
        }
        EXPECT_EQ(ctx->checkErrors(), 0u);
    }
};

std::uint64_t differing(const Image& a, const Image& b) {
    std::uint64_t n = 0;
    for (std::size_t i = 0; i < a.rgba.size() && i < b.rgba.size(); ++i) n += a.rgba[i] != b.rgba[i];
    return n;
}

TEST(ObjectRoles, AnOccluderOnlyWallIsDrawnUntestedAndCullsFromTheFirstFrame) {
    Scene s;
    ASSERT_TRUE(s.engine);
    const ObjectHandle wall = *s.engine->addObject(s.quad, at({0, 0, 0}));
    const ObjectHandle hidden = *s.engine->addObject(s.ball, at({0, 0, -1.5f}));
    const ObjectHandle front = *s.engine->addObject(s.ball, at({0.3f, 0.3f, 1.0f}));
    ASSERT_TRUE(s.engine->setRole(wall, OcclusionRole::OccluderOnly).ok());
    Image reference;
    s.run(modeParams(CullMode::Vfc), 1, reference);
    for (const Mode& m : everyMode()) {
        for (int frames : {1, 3}) {
            Image image;
            s.run(m.params, frames, image);
            EXPECT_EQ(differing(reference, image), 0u) << m.name << ", " << frames << " frames";
            EXPECT_TRUE(s.engine->isVisible(wall)) << m.name;
            EXPECT_TRUE(s.engine->isVisible(front)) << m.name;
            // Drawn first, the wall hides the ball in the first frame of every occlusion mode
            // (two-phase has no early set yet, yet its pyramid already holds the wall).
            if (m.params.mode != CullMode::Vfc) {
                EXPECT_FALSE(s.engine->isVisible(hidden)) << m.name << ", " << frames << " frames";
            }
        }
    }
    // Without the role, the first two-phase frame has nothing to test against.
    ASSERT_TRUE(s.engine->setRole(wall, OcclusionRole::Both).ok());
    Image image;
    s.run(modeParams(CullMode::TwoPhase), 1, image);
    EXPECT_TRUE(s.engine->isVisible(hidden));
}

TEST(ObjectRoles, AnOccludeeOnlyPaneHidesNothingAndIsCulledBehindAWall) {
    Scene s;
    ASSERT_TRUE(s.engine);
    // A pane in front of a ball (the ball stays visible through it), and a second pane
    // behind an opaque wall on the left (culled there).
    const ObjectHandle pane = *s.engine->addObject(s.quad, at({0.5f, 0.5f, 0.5f}, 0.4f));
    const ObjectHandle ball = *s.engine->addObject(s.ball, at({0.5f, 0.5f, -0.5f}));
    const ObjectHandle wall = *s.engine->addObject(s.quad, at({-0.8f, -0.8f, 0.0f}, 0.6f));
    const ObjectHandle hiddenPane = *s.engine->addObject(s.quad, at({-0.8f, -0.8f, -1.0f}, 0.3f));
    ASSERT_TRUE(s.engine->setRole(pane, OcclusionRole::OccludeeOnly).ok());
    ASSERT_TRUE(s.engine->setRole(hiddenPane, OcclusionRole::OccludeeOnly).ok());
    Image reference;
    std::vector<float> referenceDepth;
    s.run(modeParams(CullMode::Vfc), 1, reference, &referenceDepth);
    for (const Mode& m : everyMode()) {
        Image image;
        std::vector<float> depth;
        s.run(m.params, 4, image, &depth);
        EXPECT_EQ(differing(reference, image), 0u) << m.name;
        EXPECT_EQ(depth, referenceDepth) << m.name;
        EXPECT_TRUE(s.engine->isVisible(pane)) << m.name;
        EXPECT_TRUE(s.engine->isVisible(ball)) << m.name << ": the pane must not hide it";
        EXPECT_TRUE(s.engine->isVisible(wall)) << m.name;
        EXPECT_EQ(s.engine->isVisible(hiddenPane), m.params.mode == CullMode::Vfc) << m.name;
    }
    // The pane wrote no depth: at a pixel it alone covers (its upper-left corner, beside
    // the ball) the colour is the pane's and the depth the clear value.
    const int x = 36, y = 54;  // from the bottom; (0.15, 0.85) on the pane at z = 0.5
    const std::size_t bottomUp = std::size_t(y) * test::kW + x, topDown = std::size_t(test::kH - 1 - y) * test::kW + x;
    EXPECT_FALSE(test::isClear({reference.rgba[4 * topDown], reference.rgba[4 * topDown + 1], reference.rgba[4 * topDown + 2],
                                reference.rgba[4 * topDown + 3]}));
    EXPECT_EQ(referenceDepth[bottomUp], 0.0f);
}

TEST(ObjectRoles, RolesAreKeptBySetModelAndClearedWithTheObject) {
    Scene s;
    ASSERT_TRUE(s.engine);
    const ObjectHandle a = *s.engine->addObject(s.ball, at({0, 0, 0}));
    const ObjectHandle b = *s.engine->addObject(s.ball, at({1, 0, 0}));
    ASSERT_TRUE(s.engine->setRole(a, OcclusionRole::OccluderOnly).ok());
    ASSERT_TRUE(s.engine->setRole(b, OcclusionRole::OccludeeOnly).ok());
    EXPECT_EQ(s.engine->objects().roleSlots().size(), 2u);
    const ObjectHandle a2 = *s.engine->setModel(a, s.quad);
    EXPECT_EQ(s.engine->objects().role(a2.index), OcclusionRole::OccluderOnly);
    EXPECT_FALSE(s.engine->setRole(a, OcclusionRole::Both).ok()) << "a stale handle";
    ASSERT_TRUE(s.engine->removeObject(b).ok());
    EXPECT_EQ(s.engine->objects().roleSlots().size(), 1u);
    const ObjectHandle c = *s.engine->addObject(s.ball, at({0.5f, 0.5f, 1.0f}));  // reuses b's slot
    EXPECT_EQ(c.index, b.index);
    EXPECT_EQ(s.engine->objects().role(c.index), OcclusionRole::Both);
    ASSERT_TRUE(s.engine->setRole(a2, OcclusionRole::Both).ok());
    EXPECT_TRUE(s.engine->objects().roleSlots().empty());
    Image image;
    s.run(modeParams(CullMode::TwoPhase), 2, image);  // no role left: frames as usual
    EXPECT_TRUE(s.engine->isVisible(c));
}

}  // namespace
}  // namespace dyncull
