// The frame contract's save / set / restore (dyncull/engine/frame_contract.hpp).
#include "gl_state_scope.hpp"

#include <iterator>

#include "depth_convention.hpp"
#include "shader_program.hpp"

namespace dyncull::detail {
namespace {

// Capabilities a dyncull draw or test sets, with the value it needs (GL_TRUE: on).
// Face culling and polygon offset fill vary per draw; they are saved and set off here.
struct Capability {
    GLenum cap;
    GLboolean needed;
};
constexpr Capability kCapabilities[] = {
    {GL_DEPTH_TEST, GL_TRUE},         {GL_BLEND, GL_FALSE},        {GL_STENCIL_TEST, GL_FALSE},
    {GL_DEPTH_CLAMP, GL_FALSE},       {GL_RASTERIZER_DISCARD, GL_FALSE}, {GL_CULL_FACE, GL_FALSE},
    {GL_POLYGON_OFFSET_FILL, GL_FALSE}, {GL_COLOR_LOGIC_OP, GL_FALSE},
};
static_assert(std::size(kCapabilities) == 8);

void setCapability(GLenum cap, GLboolean on) { on ? glEnable(cap) : glDisable(cap); }

}  // namespace

GlStateScope::GlStateScope() {
    static_assert(std::size(kCapabilities) == kCapabilityCount);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFbo_);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &readFbo_);
    glGetIntegerv(GL_VIEWPORT, viewport_);
    glGetIntegerv(GL_CURRENT_PROGRAM, &program_);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &vao_);
    glGetIntegerv(GL_ARRAY_BUFFER_BINDING, &arrayBuffer_);
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_BINDING, &ssbo_);
    glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, kMarksBinding, &marksSsbo_);
    glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_START, kMarksBinding, &marksStart_);
    glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_SIZE, kMarksBinding, &marksSize_);
    glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &pixelPackBuffer_);
    glGetIntegerv(GL_PACK_ALIGNMENT, &packAlignment_);
    glGetIntegerv(GL_PACK_ROW_LENGTH, &packRowLength_);
    glGetIntegerv(GL_PACK_SKIP_ROWS, &packSkipRows_);
    glGetIntegerv(GL_PACK_SKIP_PIXELS, &packSkipPixels_);
    glGetIntegerv(GL_DEPTH_FUNC, &depthFunc_);
    glGetIntegerv(GL_CULL_FACE_MODE, &cullMode_);
    glGetIntegerv(GL_FRONT_FACE, &frontFace_);
    glGetIntegerv(GL_POLYGON_MODE, &polygonMode_);  // core profile: one value for both faces
    glGetIntegerv(GL_CLIP_ORIGIN, &clipOrigin_);
    glGetIntegerv(GL_CLIP_DEPTH_MODE, &clipDepth_);
    glGetBooleanv(GL_DEPTH_WRITEMASK, &depthMask_);
    glGetBooleanv(GL_COLOR_WRITEMASK, colourMask_);
    glGetFloatv(GL_DEPTH_RANGE, depthRange_);
    glGetFloatv(GL_POLYGON_OFFSET_FACTOR, &offsetFactor_);
    glGetFloatv(GL_POLYGON_OFFSET_UNITS, &offsetUnits_);
    for (int i = 0; i < kCapabilityCount; ++i) enabled_[i] = glIsEnabled(kCapabilities[i].cap);

    target_.framebuffer = static_cast<std::uint32_t>(drawFbo_);
    target_.viewport = {viewport_[0], viewport_[1], viewport_[2], viewport_[3]};
    // glReadPixels of depth needs a single-sample framebuffer with depth bits.
    // (Querying the size of an empty attachment is an error, so ask for its type first.)
    const GLuint fbo = static_cast<GLuint>(drawFbo_);
    const GLenum depthAttachment = fbo != 0 ? GL_DEPTH_ATTACHMENT : GL_DEPTH;
    GLint sampleBuffers = 0, depthType = GL_NONE, depthBits = 0;
    glGetIntegerv(GL_SAMPLE_BUFFERS, &sampleBuffers);
    glGetNamedFramebufferAttachmentParameteriv(fbo, depthAttachment, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &depthType);
    if (depthType != GL_NONE)
        glGetNamedFramebufferAttachmentParameteriv(fbo, depthAttachment, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE, &depthBits);
    target_.depthReadable = sampleBuffers == 0 && depthBits > 0;

    for (const Capability& c : kCapabilities) setCapability(c.cap, c.needed);
    useReversedDepth();
    glDepthRange(0.0, 1.0);
    glDepthFunc(kDepthNearer);
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
}

void GlStateScope::restore() {
    if (restored_) return;
    restored_ = true;
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(drawFbo_));
    glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(readFbo_));
    glViewport(viewport_[0], viewport_[1], viewport_[2], viewport_[3]);
    glUseProgram(static_cast<GLuint>(program_));
    glBindVertexArray(static_cast<GLuint>(vao_));
    glBindBuffer(GL_ARRAY_BUFFER, static_cast<GLuint>(arrayBuffer_));
    if (marksSize_ > 0)
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kMarksBinding, static_cast<GLuint>(marksSsbo_), marksStart_, marksSize_);
    else
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kMarksBinding, static_cast<GLuint>(marksSsbo_));
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(ssbo_));  // the generic binding, after the indexed one
    glBindBuffer(GL_PIXEL_PACK_BUFFER, static_cast<GLuint>(pixelPackBuffer_));
    glPixelStorei(GL_PACK_ALIGNMENT, packAlignment_);
    glPixelStorei(GL_PACK_ROW_LENGTH, packRowLength_);
    glPixelStorei(GL_PACK_SKIP_ROWS, packSkipRows_);
    glPixelStorei(GL_PACK_SKIP_PIXELS, packSkipPixels_);
    glDepthFunc(static_cast<GLenum>(depthFunc_));
    glCullFace(static_cast<GLenum>(cullMode_));
    glFrontFace(static_cast<GLenum>(frontFace_));
    glPolygonMode(GL_FRONT_AND_BACK, static_cast<GLenum>(polygonMode_));
    glClipControl(static_cast<GLenum>(clipOrigin_), static_cast<GLenum>(clipDepth_));
    glDepthMask(depthMask_);
    glColorMask(colourMask_[0], colourMask_[1], colourMask_[2], colourMask_[3]);
    glDepthRange(depthRange_[0], depthRange_[1]);
    glPolygonOffset(offsetFactor_, offsetUnits_);
    for (int i = 0; i < kCapabilityCount; ++i) setCapability(kCapabilities[i].cap, enabled_[i]);
}

}  // namespace dyncull::detail
