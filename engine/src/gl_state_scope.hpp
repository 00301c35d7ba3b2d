// Internal: the frame contract (dyncull/engine/frame_contract.hpp) as code. A scope saves
// every piece of the caller's GL state an Engine call may change, sets the state dyncull's
// draws and tests assume, and restores the caller's state when it ends.
#pragma once

#include <cstdint>

#include <epoxy/gl.h>

#include "dyncull/engine/frame_contract.hpp"

namespace dyncull::detail {

class GlStateScope {
public:
    /// Saves the caller's state and reads the frame target; then sets dyncull's baseline.
    GlStateScope();
    /// Restores (once; restore() may have done it already).
    ~GlStateScope() { restore(); }
    GlStateScope(const GlStateScope&) = delete;
    GlStateScope& operator=(const GlStateScope&) = delete;

    /// The caller's draw framebuffer and viewport, where this frame is drawn.
    const FrameTarget& target() const { return target_; }
    /// Puts back every saved piece of state; later calls do nothing.
    void restore();

private:
    FrameTarget target_;
    bool restored_ = false;
    GLint drawFbo_ = 0, readFbo_ = 0, viewport_[4] = {0, 0, 0, 0};
    GLint program_ = 0, vao_ = 0, arrayBuffer_ = 0, ssbo_ = 0, pixelPackBuffer_ = 0;
    GLint marksSsbo_ = 0;  // the indexed binding the part renderer's marks use (kMarksBinding)
    GLint64 marksStart_ = 0, marksSize_ = 0;
    GLint packAlignment_ = 4, packRowLength_ = 0, packSkipRows_ = 0, packSkipPixels_ = 0;
    GLint depthFunc_ = GL_LESS, cullMode_ = GL_BACK, frontFace_ = GL_CCW, polygonMode_ = GL_FILL;
    GLint clipOrigin_ = GL_LOWER_LEFT, clipDepth_ = GL_NEGATIVE_ONE_TO_ONE;
    GLboolean depthMask_ = GL_TRUE, colourMask_[4] = {GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE};
    GLfloat depthRange_[2] = {0.0f, 1.0f}, offsetFactor_ = 0.0f, offsetUnits_ = 0.0f;
    // Capabilities in the order of kCapabilities (gl_state_scope.cpp).
    static constexpr int kCapabilityCount = 8;
    GLboolean enabled_[kCapabilityCount] = {};
};

}  // namespace dyncull::detail
