// Shared helpers for GL tests: a small headless context and a camera looking down -Z.
#pragma once

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "dyncull/engine/gl_context.hpp"
#include "dyncull/engine/renderer.hpp"
#include "dyncull/objects/camera.hpp"

namespace dyncull::test {

inline constexpr int kW = 64, kH = 64;

/// Debug headless context so every GL error is counted; null (test fails) if EGL is unusable.
inline std::unique_ptr<GlContext> headless(int w = kW, int h = kH) {
    ContextOptions o;
    o.width = w;
    o.height = h;
    o.debug = true;
    auto ctx = GlContext::create(o);
    EXPECT_TRUE(ctx.ok()) << (ctx.ok() ? "" : ctx.error().message);
    return ctx.ok() ? ctx.take() : nullptr;
}

/// Camera on +Z at distance `dist` looking at the origin, square aspect.
inline Camera cameraOnZ(float dist = 3.0f) {
    Camera c;
    c.position = {0, 0, dist};
    c.target = {0, 0, 0};
    c.aspect = static_cast<float>(kW) / static_cast<float>(kH);
    c.nearPlane = 0.1f;
    c.farPlane = 100.0f;
    return c;
}

/// The context renders with the engine's depth convention (objects/camera.hpp): a 32-bit
/// float depth attachment and clip z / w used as depth unchanged (GL_ZERO_TO_ONE).
inline void expectReversedZFloatDepth(const GlContext& ctx) {
    GLint type = 0, bits = 0, origin = 0, depthMode = 0;
    glGetNamedFramebufferAttachmentParameteriv(ctx.framebuffer(), GL_DEPTH_ATTACHMENT,
                                               GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &type);
    glGetNamedFramebufferAttachmentParameteriv(ctx.framebuffer(), GL_DEPTH_ATTACHMENT,
                                               GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE, &bits);
    glGetIntegerv(GL_CLIP_ORIGIN, &origin);
    glGetIntegerv(GL_CLIP_DEPTH_MODE, &depthMode);
    EXPECT_EQ(type, GL_FLOAT);
    EXPECT_EQ(bits, 32);
    EXPECT_EQ(origin, GL_LOWER_LEFT);
    EXPECT_EQ(depthMode, GL_ZERO_TO_ONE);
}

inline bool isClear(glm::u8vec4 p) {
    auto near = [](std::uint8_t a, float b) { return std::abs(static_cast<float>(a) - b * 255.0f) <= 2.0f; };
    return near(p.r, Renderer::kClearColour.r) && near(p.g, Renderer::kClearColour.g) && near(p.b, Renderer::kClearColour.b);
}

}  // namespace dyncull::test
