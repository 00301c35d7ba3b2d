// Parts of GlContext shared by the EGL and GLFW back ends: dispatch, strings, error counting.
#include "dyncull/engine/gl_context.hpp"

#include <cstdio>
#include <string>

#include <epoxy/gl.h>

#include "depth_convention.hpp"
#include "sanitizer_driver_pin.hpp"

namespace dyncull {

namespace {

// KHR_debug callback. userParam is the owning GlContext's error counter. Only errors are
// counted and printed (capped) so performance notes from the driver don't spam soak runs.
void GLAPIENTRY debugCallback(GLenum /*source*/, GLenum type, GLuint /*id*/, GLenum severity, GLsizei /*length*/,
                              const GLchar* message, const void* userParam) {
    if (type != GL_DEBUG_TYPE_ERROR && severity != GL_DEBUG_SEVERITY_HIGH) return;
    auto* counter = static_cast<std::uint64_t*>(const_cast<void*>(userParam));
    ++*counter;
    if (*counter <= 20) std::fprintf(stderr, "GL debug: %s\n", message);
}

}  // namespace

Expected<std::unique_ptr<GlContext>> GlContext::create(const ContextOptions& options) {
    if (options.width < 1 || options.height < 1 || options.width > 16384 || options.height > 16384)
        return Error{"context: size " + std::to_string(options.width) + "x" + std::to_string(options.height) +
                     " out of range (1..16384)"};
    if (options.kind == ContextKind::GlfwWindow) return createGlfwContext(options);
    return createEglContext(options);
}

void GlContext::initCommon(bool debug) {
    auto str = [](GLenum e) {
        const GLubyte* s = glGetString(e);
        return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
    };
    detail::pinLoadedGlDrivers();  // sanitizer builds only (no leak reports from an unloaded driver)
    renderer_ = str(GL_RENDERER);
    version_ = str(GL_VERSION);
    debug_ = false;
    if (debug) {
        GLint flags = 0;
        glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
        if (flags & GL_CONTEXT_FLAG_DEBUG_BIT) {
            glEnable(GL_DEBUG_OUTPUT);
            glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);  // so a breakpoint lands on the offending call
            glDebugMessageCallback(debugCallback, &errorCount_);
            debug_ = true;
        }
    }
    GLint strategy = 0;
    glGetIntegerv(GL_RESET_NOTIFICATION_STRATEGY, &strategy);
    resetNotification_ = strategy == GL_LOSE_CONTEXT_ON_RESET;
    detail::useReversedDepth();  // the depth convention of Camera::projection, for every pass
    while (glGetError() != GL_NO_ERROR) {
    }  // nothing the caller did yet: discard creation-time noise
}

Status GlContext::checkReset() {
    if (lost_) return Error{lostMessage_};
    ResetKind kind = faults_.simulateReset;
    if (kind == ResetKind::None) {
        // NO_ERROR on a context without reset notification, so calling it is always safe.
        switch (glGetGraphicsResetStatus()) {
            case GL_GUILTY_CONTEXT_RESET: kind = ResetKind::Guilty; break;
            case GL_INNOCENT_CONTEXT_RESET: kind = ResetKind::Innocent; break;
            case GL_UNKNOWN_CONTEXT_RESET: kind = ResetKind::Unknown; break;
            default: return {};
        }
    }
    const char* why = kind == ResetKind::Guilty     ? "guilty reset: this context's commands caused it"
                      : kind == ResetKind::Innocent ? "innocent reset: another context caused it"
                                                    : "unknown reset: the driver gives no cause";
    lost_ = true;
    lostMessage_ = std::string("OpenGL context lost (") + why + "); recreate the GlContext and the Engine";
    return Error{lostMessage_};
}

Status GlContext::checkAllocation(const std::string& what, std::size_t bytes) {
    bool outOfMemory = false;
    for (int guard = 0; guard < 64; ++guard) {  // as in checkErrors: bounded on a lost context
        const GLenum e = glGetError();
        if (e == GL_NO_ERROR) break;
        if (e == GL_OUT_OF_MEMORY) outOfMemory = true;  // still a GL error: counted like any other
        if (debug_) continue;
        ++errorCount_;
        if (errorCount_ <= 20) std::fprintf(stderr, "GL error 0x%04x\n", static_cast<unsigned>(e));
    }
    if (faults_.allocationsBeforeFailure > 0) {
        --faults_.allocationsBeforeFailure;
    } else if (faults_.failBufferAllocations > 0) {
        --faults_.failBufferAllocations;
        outOfMemory = true;
    }
    if (!outOfMemory) return {};
    return Error{"out of GPU memory " + what + " (" + std::to_string(bytes) + " bytes)"};
}

std::uint64_t GlContext::checkErrors() {
    for (int guard = 0; guard < 64; ++guard) {  // glGetError may never clear on a lost context
        const GLenum e = glGetError();
        if (e == GL_NO_ERROR) break;
        if (debug_) continue;  // the debug callback already counted it when it happened
        ++errorCount_;
        if (errorCount_ <= 20) std::fprintf(stderr, "GL error 0x%04x\n", static_cast<unsigned>(e));
    }
    return errorCount_;
}

}  // namespace dyncull
