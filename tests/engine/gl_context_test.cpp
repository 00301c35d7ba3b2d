#include <cstdio>
#include <string>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "gl_test_util.hpp"

namespace dyncull {
namespace {

TEST(GlContext, HeadlessEglCreatesGl45CoreWithFbo) {
    auto ctx = test::headless(96, 40);
    ASSERT_TRUE(ctx);
    EXPECT_EQ(ctx->kind(), ContextKind::HeadlessEgl);
    EXPECT_EQ(ctx->size(), glm::ivec2(96, 40));
    EXPECT_NE(ctx->framebuffer(), 0u);
    EXPECT_FALSE(ctx->rendererName().empty());
    GLint major = 0, minor = 0, profile = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    EXPECT_GE(major * 10 + minor, 45);
    EXPECT_TRUE(profile & GL_CONTEXT_CORE_PROFILE_BIT);
    EXPECT_TRUE(ctx->isDebug());
    test::expectReversedZFloatDepth(*ctx);
    std::printf("renderer: %s via %s, GL %s\n", ctx->rendererName().c_str(), ctx->platformName().c_str(),
                ctx->versionString().c_str());
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

TEST(GlContext, ImpossibleVersionIsAnErrorNotACrash) {
    ContextOptions o;
    o.width = o.height = 8;
    o.glMajor = 9;
    o.glMinor = 9;
    auto ctx = GlContext::create(o);
    ASSERT_FALSE(ctx.ok());
    const std::string& msg = ctx.error().message;
    EXPECT_EQ(msg.rfind("EGL: ", 0), 0u) << msg;
    EXPECT_NE(msg.find("eglCreateContext(OpenGL 9.9 core)"), std::string::npos) << msg;
    EXPECT_NE(msg.find("EGL_BAD_MATCH"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line";
}

TEST(GlContext, BadSizeIsAnError) {
    ContextOptions o;
    o.width = 0;
    auto ctx = GlContext::create(o);
    ASSERT_FALSE(ctx.ok());
    EXPECT_NE(ctx.error().message.find("0x720"), std::string::npos) << ctx.error().message;
}

TEST(GlContext, DebugCallbackCountsErrors) {
    auto ctx = test::headless(8, 8);
    ASSERT_TRUE(ctx);
    EXPECT_EQ(ctx->glErrorCount(), 0u);
    glBindBuffer(GL_ARRAY_BUFFER, 424242);  // never generated: GL_INVALID_OPERATION in core profile
    EXPECT_GE(ctx->checkErrors(), 1u);
}

TEST(GlContext, TwoContextsShareADisplaySafely) {
    auto a = test::headless(8, 8);
    auto b = test::headless(8, 8);
    ASSERT_TRUE(a && b);
    b.reset();  // must not terminate the display under `a`
    a->makeCurrent();
    glClearColor(0, 1, 0, 1);
    glBindFramebuffer(GL_FRAMEBUFFER, a->framebuffer());
    glClear(GL_COLOR_BUFFER_BIT);
    std::uint8_t px[4] = {};
    glReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
    EXPECT_EQ(px[1], 255);
    EXPECT_EQ(a->checkErrors(), 0u);
}

}  // namespace
}  // namespace dyncull
