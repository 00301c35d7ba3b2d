#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "gl_test_util.hpp"
#include "procedural_meshes.hpp"

namespace dyncull {
namespace {

struct RendererTest : ::testing::Test {
    void SetUp() override {
        ctx = test::headless();
        ASSERT_TRUE(ctx);
        auto r = Renderer::create(*ctx);
        ASSERT_TRUE(r.ok()) << r.error().message;
        renderer = r.take();
    }
    void TearDown() override {
        renderer.reset();
        if (ctx) {
            EXPECT_EQ(ctx->checkErrors(), 0u);
        }
    }
    std::unique_ptr<GlContext> ctx;
    std::unique_ptr<Renderer> renderer;
};

TEST_F(RendererTest, RedQuadFillsTheCentre) {
    const MeshId quad = *renderer->upload(test::quadMesh(0.5f));
    ctx->clearFramebuffer(Renderer::kClearColour);
    renderer->beginFrame(test::cameraOnZ(3.0f));
    renderer->drawMesh(quad, glm::mat4(1.0f), {1, 0, 0});
    renderer->endFrame();
    const Image img = renderer->readPixels();
    ASSERT_EQ(img.width, test::kW);
    ASSERT_EQ(img.height, test::kH);
    const glm::u8vec4 c = img.at(32, 32);
    EXPECT_GT(c.r, 150);
    EXPECT_LT(c.g, 30);
    EXPECT_LT(c.b, 30);
    EXPECT_TRUE(test::isClear(img.at(0, 0)));
    EXPECT_TRUE(test::isClear(img.at(63, 63)));
    // Half-size 0.5 at distance 3 with fov 0.9 spans 0.5 / (3 tan 0.45) = 34.5% of the half
    // height: about 22 x 22 = 484 pixels.
    int covered = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) covered += test::isClear(img.at(x, y)) ? 0 : 1;
    EXPECT_GT(covered, 400);
    EXPECT_LT(covered, 580);
    EXPECT_EQ(renderer->stats().drawCalls, 1u);
    EXPECT_EQ(renderer->stats().triangles, 2u);
}

TEST_F(RendererTest, CulledClosedCubeLooksTwoSidedFromOutsideEvenMirrored) {
    const Mesh cube = test::cubeMesh(0.6f);
    ASSERT_EQ(analyseSurface(cube).mode, FaceMode::CullBack);
    const MeshId culled = *renderer->upload(cube, FaceMode::CullBack);
    const MeshId both = *renderer->upload(cube, FaceMode::TwoSided);
    const glm::mat4 turned = glm::rotate(glm::mat4(1.0f), 0.7f, glm::normalize(glm::vec3(1, 2, 3)));
    for (const glm::mat4& model : {turned, glm::scale(turned, {-1.0f, 1.0f, 1.0f})}) {
        Image img[2];
        for (int i = 0; i < 2; ++i) {
            ctx->clearFramebuffer(Renderer::kClearColour);
            renderer->beginFrame(test::cameraOnZ(3.0f));
            renderer->drawMesh(i == 0 ? culled : both, model, {0.8f, 0.5f, 0.2f});
            renderer->endFrame();
            img[i] = renderer->readPixels();
        }
        EXPECT_FALSE(test::isClear(img[0].at(32, 32))) << "a mirrored cube lost its front faces";
        EXPECT_EQ(img[0].rgba, img[1].rgba);
        // The frame leaves culling as it began it, whatever it drew last.
        GLint front = 0;
        glGetIntegerv(GL_FRONT_FACE, &front);
        EXPECT_FALSE(glIsEnabled(GL_CULL_FACE));
        EXPECT_EQ(front, GL_CCW);
    }
    // From inside, a closed surface shows only back faces: culled, nothing is drawn.
    Image inside[2];
    for (int i = 0; i < 2; ++i) {
        ctx->clearFramebuffer(Renderer::kClearColour);
        renderer->beginFrame(test::cameraOnZ(0.1f));
        renderer->drawMesh(i == 0 ? culled : both, glm::mat4(1.0f), {0.8f, 0.5f, 0.2f});
        renderer->endFrame();
        inside[i] = renderer->readPixels();
    }
    EXPECT_TRUE(test::isClear(inside[0].at(32, 32)));
    EXPECT_FALSE(test::isClear(inside[1].at(32, 32)));
}

TEST_F(RendererTest, ReadPixelsIsTopDown) {
    const MeshId quad = *renderer->upload(test::quadMesh(0.3f));
    ctx->clearFramebuffer(Renderer::kClearColour);
    renderer->beginFrame(test::cameraOnZ(3.0f));
    renderer->drawMesh(quad, glm::translate(glm::mat4(1.0f), {0, 0.9f, 0}), {0, 0, 1});  // world up
    renderer->endFrame();
    const Image img = renderer->readPixels();
    EXPECT_FALSE(test::isClear(img.at(32, 10)));
    EXPECT_TRUE(test::isClear(img.at(32, 54)));
}

TEST_F(RendererTest, NearCubeHidesFarCubeRegardlessOfOrder) {
    const MeshId cube = *renderer->upload(test::cubeMesh(1.0f));
    const glm::mat4 nearM = glm::scale(glm::mat4(1.0f), glm::vec3(0.5f));
    const glm::mat4 farM = glm::scale(glm::translate(glm::mat4(1.0f), {0, 0, -3}), glm::vec3(1.5f));
    ctx->clearFramebuffer(Renderer::kClearColour);
    renderer->beginFrame(test::cameraOnZ(3.0f));
    renderer->drawMesh(cube, nearM, {1, 0, 0});
    renderer->drawMesh(cube, farM, {0, 1, 0});  // drawn second, must lose the depth test in the middle
    renderer->endFrame();
    const Image img = renderer->readPixels();
    const glm::u8vec4 centre = img.at(32, 32);
    EXPECT_GT(centre.r, 100);
    EXPECT_LT(centre.g, 30);
    // Near cube front face spans NDC +-0.41, far cube front face +-0.69: x = 50 is NDC 0.58.
    const glm::u8vec4 side = img.at(50, 32);
    EXPECT_GT(side.g, 100);
    EXPECT_LT(side.r, 30);
    EXPECT_TRUE(test::isClear(img.at(2, 2)));
}

TEST_F(RendererTest, SubRangeDrawsOnlyThoseTriangles) {
    const MeshId quad = *renderer->upload(test::quadMesh(0.5f));
    ctx->clearFramebuffer(Renderer::kClearColour);
    renderer->beginFrame(test::cameraOnZ(3.0f));
    renderer->drawRange(quad, 3, 3, glm::mat4(1.0f), {1, 1, 1});  // second triangle: (0, 2, 3), upper-left half
    renderer->endFrame();
    const Image img = renderer->readPixels();
    EXPECT_FALSE(test::isClear(img.at(26, 26)));  // upper-left of centre
    EXPECT_TRUE(test::isClear(img.at(38, 38)));   // lower-right of centre
    EXPECT_EQ(renderer->stats().triangles, 1u);
}

TEST_F(RendererTest, LightingShadesFacesDifferently) {
    const MeshId sphere = *renderer->upload(test::sphereMesh(1.0f));
    ctx->clearFramebuffer(Renderer::kClearColour);
    renderer->beginFrame(test::cameraOnZ(4.0f));
    renderer->drawMesh(sphere, glm::mat4(1.0f), {0.8f, 0.8f, 0.8f});
    renderer->endFrame();
    const Image img = renderer->readPixels();
    // Key light is up-left: the upper-left limb is brighter than the lower-right one.
    const int upperLeft = img.at(24, 24).r, lowerRight = img.at(40, 40).r;
    EXPECT_GT(upperLeft, lowerRight + 20);
    EXPECT_GT(lowerRight, 30);  // ambient keeps the shadow side visible
}

TEST_F(RendererTest, MissingNormalsAreComputedOnUpload) {
    Mesh m = test::quadMesh(0.5f);
    m.normals.clear();
    const MeshId id = *renderer->upload(m);
    EXPECT_EQ(renderer->indexCount(id), 6u);
    ctx->clearFramebuffer(Renderer::kClearColour);
    renderer->beginFrame(test::cameraOnZ(3.0f));
    renderer->drawMesh(id, glm::mat4(1.0f), {1, 0, 0});
    renderer->endFrame();
    EXPECT_GT(renderer->readPixels().at(32, 32).r, 150);
}

TEST(ColourForId, DistinctAndInRange) {
    for (std::uint32_t i = 0; i < 100; ++i) {
        const glm::vec3 c = colourForId(i);
        EXPECT_TRUE(glm::all(glm::greaterThanEqual(c, glm::vec3(0.0f))) && glm::all(glm::lessThanEqual(c, glm::vec3(1.0f))));
    }
    EXPECT_GT(glm::length(colourForId(0) - colourForId(1)), 0.05f);
    EXPECT_EQ(colourForId(7), colourForId(7));
}

}  // namespace
}  // namespace dyncull
