// Tests on the parts' own triangles (SchedulerParams::useTriangleTests): stricter than any
// test on a volume, and still conservative. A thin strip runs in depth behind a wall: every
// triangle of it is hidden, but its box pokes out past the wall's edge, so every volume
// test calls it visible. The triangle test culls it; moved so that its far end shows
// beside the wall, it is drawn; and every frame is the image frustum culling draws.
#include <vector>

#include <gtest/gtest.h>

#include "dyncull/engine/engine.hpp"
#include "engine/gl_test_util.hpp"
#include "engine/procedural_meshes.hpp"
#include "objects/transform_at.hpp"

namespace dyncull {
namespace {

using test::at;

/// A strip 0.1 wide in y from (farX, 0, -3) to (0.9, 0, -0.05): with the camera on +Z at
/// 3 and a wall [-1, 1]^2 at z = 0, the wall hides x < 2 at z = -3, so farX < 2 hides the
/// whole strip (the wall's shadow is convex) while its box's corner (farX, 0, -0.05) shows
/// beside the wall.
Mesh strip(float farX) {
    Mesh m;
    m.name = "strip";
    m.positions = {{farX, -0.05f, -3.0f}, {farX, 0.05f, -3.0f}, {0.9f, 0.05f, -0.05f}, {0.9f, -0.05f, -0.05f}};
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
}

struct StripScene {
    std::unique_ptr<GlContext> ctx = test::headless(96, 96);
    std::unique_ptr<Engine> engine;
    ObjectHandle wall, strip;

    explicit StripScene(float farX) {
        if (!ctx) return;
        auto e = Engine::create(*ctx);
        EXPECT_TRUE(e.ok()) << (e.ok() ? "" : e.error().message);
        if (!e) return;
        engine = e.take();
        wall = *engine->addObject(*engine->addModel(test::quadMesh(1.0f)), at({0, 0, 0}));
        this->strip = *engine->addObject(*engine->addModel(dyncull::strip(farX)), at({0, 0, 0}));
        Camera cam = test::cameraOnZ(3.0f);
        cam.aspect = 1.0f;
        EXPECT_TRUE(engine->setCamera(cam).ok());
    }

    /// Frames with `params` (the last one's image returned); whether the strip was drawn in it.
    bool drawsStrip(const SchedulerParams& params, int frames, Image& image) {
        QueryScheduler scheduler(params);
        for (int f = 0; f < frames; ++f) {
            ctx->clearFramebuffer(Renderer::kClearColour);
            auto st = engine->renderFrame(scheduler);
            EXPECT_TRUE(st.ok()) << st.error().message;
        }
        image = engine->renderer().readPixels();
        EXPECT_EQ(ctx->checkErrors(), 0u);
        return engine->isVisible(strip);
    }
};

SchedulerParams twoPhase(bool triangles) {
    SchedulerParams p;
    p.mode = CullMode::TwoPhase;
    p.features.useCostModel = false;      // test every volume and every part
    p.features.useTightVolumes = false;   // boxes: the strip's pokes out whatever the k-DOP would do
    p.features.useTriangleTests = triangles;
    return p;
}

std::uint64_t differingPixels(const Image& a, const Image& b) {
    EXPECT_EQ(a.rgba.size(), b.rgba.size());
    std::uint64_t n = 0;
    for (std::size_t i = 0; i + 3 < a.rgba.size() && i + 3 < b.rgba.size(); i += 4)
        n += a.rgba[i] != b.rgba[i] || a.rgba[i + 1] != b.rgba[i + 1] || a.rgba[i + 2] != b.rgba[i + 2];
    return n;
}

TEST(TriangleTests, AHiddenStripWhoseBoxShowsIsCulledOnlyByItsTriangles) {
    StripScene scene(1.8f);
    ASSERT_TRUE(scene.engine);
    SchedulerParams vfc;
    vfc.mode = CullMode::Vfc;
    Image reference, volumes, triangles;
    EXPECT_TRUE(scene.drawsStrip(vfc, 1, reference));
    // From the third frame on, the wall is in the early set and the strip is tested against it.
    EXPECT_TRUE(scene.drawsStrip(twoPhase(false), 3, volumes)) << "the strip's box shows beside the wall";
    EXPECT_FALSE(scene.drawsStrip(twoPhase(true), 3, triangles)) << "none of the strip's triangles shows";
    EXPECT_TRUE(scene.engine->isVisible(scene.wall));
    EXPECT_EQ(differingPixels(reference, volumes), 0u);
    EXPECT_EQ(differingPixels(reference, triangles), 0u);
}

TEST(TriangleTests, AStripShowingBesideTheWallIsDrawnEveryFrame) {
    StripScene scene(2.6f);  // its far end beyond the wall's shadow
    ASSERT_TRUE(scene.engine);
    SchedulerParams vfc;
    vfc.mode = CullMode::Vfc;
    Image reference, triangles;
    EXPECT_TRUE(scene.drawsStrip(vfc, 1, reference));
    for (int frames = 1; frames <= 4; ++frames) {
        EXPECT_TRUE(scene.drawsStrip(twoPhase(true), frames, triangles)) << frames << " frames";
        EXPECT_EQ(differingPixels(reference, triangles), 0u) << frames << " frames";
    }
}

}  // namespace
}  // namespace dyncull
