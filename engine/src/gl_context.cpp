// Parts of GlContext shared by the EGL and GLFW back ends: dispatch, strings, error counting.
#include "dyncull/engine/gl_context.hpp"

#include <cstdio>

#include <epoxy/gl.h>

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
    while (glGetError() != GL_NO_ERROR) {
    }  // nothing the caller did yet: discard creation-time noise
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
