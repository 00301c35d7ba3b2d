// Wireframe boxes land on the projected box edges, in their colour, and nowhere inside.
#include <gtest/gtest.h>

#include "dyncull/viewer/debug_draw.hpp"
#include "gl_test_util.hpp"
#include "procedural_meshes.hpp"

namespace dyncull {
namespace {

// Framebuffer pixel (top-down rows) of a world point.
glm::ivec2 project(const glm::mat4& viewProj, const glm::vec3& p, glm::ivec2 size) {
    const glm::vec4 c = viewProj * glm::vec4(p, 1.0f);
    const glm::vec2 ndc = glm::vec2(c) / c.w;
    return {static_cast<int>((ndc.x * 0.5f + 0.5f) * static_cast<float>(size.x)),
            static_cast<int>((0.5f - ndc.y * 0.5f) * static_cast<float>(size.y))};
}

TEST(DebugDraw, BoxEdgesAppearAtTheirProjection) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    {
        auto r = Renderer::create(*ctx);
        ASSERT_TRUE(r.ok()) << r.error().message;
        DebugDraw lines;
        ASSERT_TRUE(lines.valid()) << lines.log();
        const Camera cam = test::cameraOnZ(3.0f);
        const Aabb box = Aabb::fromMinMax({-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f});
        ctx->clearFramebuffer(Renderer::kClearColour);
        (*r)->beginFrame(cam);
        lines.addBox(box, {0, 1, 0, 1});
        EXPECT_EQ(lines.queuedLines(), 12u);
        lines.flush(cam.viewProjection(), ctx->size(), LineDepth::Overlay, 3.0f);
        EXPECT_EQ(lines.queuedLines(), 0u);
        (*r)->endFrame();
        const Image img = (*r)->readPixels();
        const glm::mat4 vp = cam.viewProjection();
        // Midpoints of the front face's edges (z = +0.5, nearest the camera).
        for (const glm::vec3 mid : {glm::vec3(0, 0.5f, 0.5f), glm::vec3(0, -0.5f, 0.5f), glm::vec3(0.5f, 0, 0.5f),
                                    glm::vec3(-0.5f, 0, 0.5f)}) {
            const glm::ivec2 px = project(vp, mid, ctx->size());
            const glm::u8vec4 p = img.at(px.x, px.y);
            EXPECT_GT(p.g, 200) << "edge midpoint at " << px.x << "," << px.y;
            EXPECT_LT(p.r, 60);
        }
        // The centre of the box is empty (wireframe, no faces), and so is far outside.
        const glm::ivec2 centre = project(vp, {0, 0, 0}, ctx->size());
        EXPECT_TRUE(test::isClear(img.at(centre.x, centre.y)));
        EXPECT_TRUE(test::isClear(img.at(1, 1)));
    }
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

TEST(DebugDraw, DepthModesHideOrFadeLinesBehindGeometry) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    {
        auto r = Renderer::create(*ctx);
        ASSERT_TRUE(r.ok()) << r.error().message;
        DebugDraw lines;
        const Camera cam = test::cameraOnZ(3.0f);
        const MeshId wall = *(*r)->upload(test::quadMesh(2.0f));  // z = 0 plane, covers the view centre
        // A box behind the wall.
        const Aabb box = Aabb::fromMinMax({-0.3f, -0.3f, -1.5f}, {0.3f, 0.3f, -1.0f});
        const glm::ivec2 size = ctx->size();
        const glm::ivec2 px = project(cam.viewProjection(), {0.3f, 0.0f, -1.0f}, size);
        auto render = [&](LineDepth mode) {
            ctx->clearFramebuffer(Renderer::kClearColour);
            (*r)->beginFrame(cam);
            (*r)->drawMesh(wall, glm::mat4(1.0f), {0.2f, 0.2f, 0.2f});
            lines.addBox(box, {1, 0, 0, 1});
            lines.flush(cam.viewProjection(), size, mode, 3.0f, 0.5f);
            (*r)->endFrame();
            return (*r)->readPixels().at(px.x, px.y);
        };
        const glm::u8vec4 tested = render(LineDepth::Tested);
        const glm::u8vec4 overlay = render(LineDepth::Overlay);
        const glm::u8vec4 xray = render(LineDepth::XRay);
        EXPECT_LT(tested.r, 120) << "hidden edge drawn with depth test";
        EXPECT_GT(overlay.r, 240);
        EXPECT_GT(xray.r, tested.r + 40);  // faded, not hidden
        EXPECT_LT(xray.r, overlay.r - 40);
    }
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

TEST(DebugDraw, SegmentsCrossingTheEyePlaneAreClippedNotFlipped) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    {
        auto r = Renderer::create(*ctx);
        ASSERT_TRUE(r.ok()) << r.error().message;
        DebugDraw lines;
        const Camera cam = test::cameraOnZ(3.0f);
        ctx->clearFramebuffer(Renderer::kClearColour);
        (*r)->beginFrame(cam);
        // From in front of the camera on the right to behind it: only the right half may light up.
        lines.addLine({0.5f, 0.0f, 0.0f}, {0.5f, 0.0f, 10.0f}, {1, 1, 1, 1});
        lines.addBox(Aabb{}, {1, 1, 1, 1});  // empty box: nothing queued
        EXPECT_EQ(lines.queuedLines(), 1u);
        lines.flush(cam.viewProjection(), ctx->size(), LineDepth::Overlay, 2.0f);
        (*r)->endFrame();
        const Image img = (*r)->readPixels();
        int litLeft = 0, litRight = 0;
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x)
                if (!test::isClear(img.at(x, y))) (x < img.width / 2 ? litLeft : litRight)++;
        EXPECT_GT(litRight, 0);
        EXPECT_EQ(litLeft, 0);
    }
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

}  // namespace
}  // namespace dyncull
