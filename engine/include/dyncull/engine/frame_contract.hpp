// The frame contract: what a game's GL state must be when it calls the Engine, what the
// Engine changes while it works, and what it leaves behind. Every Engine call that touches
// GL keeps it (engine/src/gl_state_scope.cpp implements it, docs/EMBEDDING.md explains it).
//
// In (the caller's state when it calls renderFrame):
//   - the GL context the Engine was made on is current on this thread (else WrongContext);
//   - a draw framebuffer is bound: the game's own or the default one, with a depth buffer
//     that holds what the game drew so far in dyncull's depth convention (reversed Z:
//     cleared to 0, nearer is greater, clip z/w in [0, 1]; see objects/camera.hpp) or was
//     just cleared to 0; a single-sample depth buffer lets the two-phase mode read it back
//     (a multisampled one still works, without the CPU depth pyramid);
//   - the viewport is the view's rectangle (the camera's aspect should match it). Scissor
//     and sRGB writes are the game's and apply to dyncull's draws too.
// During the call the Engine sets, for its own draws and tests only: clip control
// (GL_LOWER_LEFT, GL_ZERO_TO_ONE), depth range [0, 1], depth test with GL_GREATER, depth
// and colour writes, face culling per mesh, polygon mode fill, and blending, stencil test,
// depth clamp and rasteriser discard off; its own programs, vertex arrays and buffers
// (storage-buffer binding points 0 and 1 included); the pixel-pack state of its depth
// readback.
// Out: every one of those is as the caller left it, and so are the framebuffer bindings,
// the viewport and the framebuffer's pixels outside what dyncull's renderer drew (nothing
// is cleared). It calls glFinish only if asked (Engine::setFinishEachFrame).
// Errors: a GL error raised inside the call, by dyncull or by a draw callback it ran, comes
// back as ErrorCode::GlError; errors already pending when the call began are the caller's,
// taken off the error flags and counted in Engine::callerGlErrors().
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace dyncull {

/// Where a frame is drawn, read from the caller's state when the frame begins: the GL name
/// of the bound draw framebuffer (0: the default framebuffer) and the viewport in pixels
/// (x, y from the bottom-left corner, width, height).
struct FrameTarget {
    std::uint32_t framebuffer = 0;
    glm::ivec4 viewport{0, 0, 1, 1};
    /// The framebuffer's depth can be read with glReadPixels (single-sample, with a depth attachment).
    bool depthReadable = false;

    int width() const { return viewport.z; }
    int height() const { return viewport.w; }
};

}  // namespace dyncull
