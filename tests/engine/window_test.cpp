// GLFW window path; needs an X display (ctest also runs it under xvfb-run).
#include <cstdlib>

#include <gtest/gtest.h>

#include "dyncull/viewer/window_context.hpp"
#include "dyncull/engine/renderer.hpp"
#include "gl_test_util.hpp"
#include "procedural_meshes.hpp"

namespace dyncull {
namespace {

TEST(Window, RendersIntoAFloatDepthFramebufferAndPresents) {
    if (!std::getenv("DISPLAY")) GTEST_SKIP() << "no X display (DISPLAY unset)";
    ContextOptions o;
    o.kind = ContextKind::GlfwWindow;
    o.width = 64;
    o.height = 48;
    o.visible = false;
    o.debug = true;
    auto ctx = WindowContext::create(o);
    ASSERT_TRUE(ctx.ok()) << ctx.error().message;
    EXPECT_EQ((*ctx)->kind(), ContextKind::GlfwWindow);
    EXPECT_NE((*ctx)->framebuffer(), 0u);  // offscreen, float depth: reversed Z
    test::expectReversedZFloatDepth(**ctx);
    EXPECT_EQ((*ctx)->size(), glm::ivec2(64, 48));
    auto r = Renderer::create(**ctx);
    ASSERT_TRUE(r.ok()) << r.error().message;
    const MeshId quad = *(*r)->upload(test::quadMesh(0.5f));
    Camera cam;
    cam.position = {0, 0, 3};
    cam.aspect = 64.0f / 48.0f;
    (*ctx)->clearFramebuffer(Renderer::kClearColour);
    (*r)->beginFrame(cam);
    (*r)->drawMesh(quad, glm::mat4(1.0f), {1, 0, 0});
    (*r)->endFrame();
    const Image img = (*r)->readPixels();
    EXPECT_GT(img.at(32, 24).r, 150);
    EXPECT_LT(img.at(32, 24).g, 30);
    EXPECT_LT(img.at(1, 1).r, 60);
    (*ctx)->present();
    EXPECT_FALSE((*ctx)->shouldClose());
    r = Error{""};  // destroy the renderer before its context
    EXPECT_EQ((*ctx)->checkErrors(), 0u);
}

TEST(Window, NoDisplayIsAnErrorNotACrash) {
    const char* saved = std::getenv("DISPLAY");
    const std::string keep = saved ? saved : "";
    setenv("DISPLAY", ":987", 1);  // no server there
    ContextOptions o;
    o.kind = ContextKind::GlfwWindow;
    o.width = o.height = 8;
    auto ctx = WindowContext::create(o);
    if (saved) setenv("DISPLAY", keep.c_str(), 1); else unsetenv("DISPLAY");
    ASSERT_FALSE(ctx.ok());
    EXPECT_EQ(ctx.error().message.rfind("GLFW: ", 0), 0u) << ctx.error().message;
}

}  // namespace
}  // namespace dyncull
