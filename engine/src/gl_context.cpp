// Parts of GlContext shared by the EGL, GLFW and borrowed kinds: strings, the fingerprint
// that tells whether the context is current, error counting, and the borrowed kind itself.
#include "dyncull/engine/gl_context.hpp"

#include <algorithm>

#include <atomic>
#include <cstdio>
#include <cstring>
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

// The caller's context: dyncull neither makes it current nor presents it, and its destructor
// deletes only the fingerprint.
class BorrowedContext final : public GlContext {
public:
    BorrowedContext() : GlContext(ContextKind::Borrowed) {}
    ~BorrowedContext() override {
        if (isCurrent()) releaseCommon();  // else it dies with the game's context
    }
    void makeCurrent() override {}
    void releaseCurrent() override {}
    void present() override {}
    void setSize(glm::ivec2 size) { size_ = size; }
};

}  // namespace

Expected<std::unique_ptr<GlContext>> GlContext::borrowCurrent() {
    // With no context current, GLVND's dispatch answers every GL call with zeros.
    const GLubyte* version = glGetString(GL_VERSION);
    if (!version) return Error{"borrowing the current GL context: no OpenGL context is current on this thread", ErrorCode::WrongContext};
    GLint major = 0, minor = 0, profile = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    if (major * 10 + minor < 45)
        return Error{"borrowing the current GL context: OpenGL " + std::to_string(major) + "." + std::to_string(minor) +
                         " (" + reinterpret_cast<const char*>(version) + "); dyncull needs 4.5",
                     ErrorCode::Unsupported};
    auto ctx = std::make_unique<BorrowedContext>();
    GLint viewport[4] = {0, 0, 0, 0};
    glGetIntegerv(GL_VIEWPORT, viewport);
    ctx->setSize({std::max(viewport[2], 1), std::max(viewport[3], 1)});
    ctx->platform_ = "borrowed";
    ctx->initCommon(false);
    return std::unique_ptr<GlContext>(std::move(ctx));
}

bool GlContext::isCurrent() const {
    if (!fingerprint_ || !glIsVertexArray(fingerprint_)) return false;
    // Another context may hold a vertex array of the same name: compare the label.
    char label[64] = {};
    GLsizei length = 0;
    glGetObjectLabel(GL_VERTEX_ARRAY, fingerprint_, sizeof label, &length, label);
    return static_cast<std::size_t>(length) == fingerprintLabel_.size() &&
           std::memcmp(label, fingerprintLabel_.data(), fingerprintLabel_.size()) == 0;
}

Status GlContext::checkCurrent(const char* what) const {
    if (isCurrent()) return {};
    return Error{std::string(what) + ": the GL context current on this thread is not the one it was made on (" +
                     platform_ + "); make that context current first",
                 ErrorCode::WrongContext};
}

void GlContext::clearFramebuffer(const glm::vec3& colour) {
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
    glViewport(0, 0, size_.x, size_.y);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glClearColor(colour.r, colour.g, colour.b, 1.0f);
    glClearDepth(detail::kDepthCleared);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

Expected<std::unique_ptr<GlContext>> GlContext::create(const ContextOptions& options) {
    if (options.width < 1 || options.height < 1 || options.width > 16384 || options.height > 16384)
        return Error{"context: size " + std::to_string(options.width) + "x" + std::to_string(options.height) +
                     " out of range (1..16384)"};
    if (options.kind == ContextKind::GlfwWindow)
        return Error{"context: windows are the demos' viewer (dyncull/viewer/window_context.hpp), not the runtime",
                     ErrorCode::Unsupported};
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
    // Unique per GlContext in the process, so no other context's vertex array carries it.
    static std::atomic<std::uint64_t> serial{0};
    fingerprintLabel_ = "dyncull context " + std::to_string(++serial);
    glCreateVertexArrays(1, &fingerprint_);
    glObjectLabel(GL_VERTEX_ARRAY, fingerprint_, static_cast<GLsizei>(fingerprintLabel_.size()), fingerprintLabel_.data());
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
    if (kind_ == ContextKind::Borrowed) return;  // the game's state and error flags stay its own
    detail::useReversedDepth();  // the depth convention of Camera::projection, for every pass
    while (glGetError() != GL_NO_ERROR) {
    }  // nothing the caller did yet: discard creation-time noise
}

void GlContext::releaseCommon() {
    if (fingerprint_) glDeleteVertexArrays(1, &fingerprint_);
    fingerprint_ = 0;
}

Status GlContext::checkReset() {
    if (lost_) return Error{lostMessage_, ErrorCode::ContextLost};
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
    return Error{lostMessage_, ErrorCode::ContextLost};
}

GlContext::DrainedErrors GlContext::drainErrors(Tally tally) {
    DrainedErrors d;
    for (int guard = 0; guard < 64; ++guard) {
        const GLenum e = glGetError();
        if (e == GL_NO_ERROR) break;
        if (d.count++ == 0) d.first = e;
        if (e == GL_OUT_OF_MEMORY) d.outOfMemory = true;
        if (tally == Tally::None || debug_) continue;  // a debug context's callback counted it when it happened
        ++errorCount_;
        if (tally == Tally::CountAndReport && errorCount_ <= 20)
            std::fprintf(stderr, "GL error 0x%04x\n", static_cast<unsigned>(e));
    }
    return d;
}

Status GlContext::checkAllocation(const std::string& what, std::size_t bytes) {
    // GL_OUT_OF_MEMORY is still a GL error: counted like any other.
    bool outOfMemory = drainErrors(Tally::CountAndReport).outOfMemory;
    if (faults_.allocationsBeforeFailure > 0) {
        --faults_.allocationsBeforeFailure;
    } else if (faults_.failBufferAllocations > 0) {
        --faults_.failBufferAllocations;
        outOfMemory = true;
    }
    if (!outOfMemory) return {};
    return Error{"out of GPU memory " + what + " (" + std::to_string(bytes) + " bytes)", ErrorCode::OutOfMemory};
}

namespace {
const char* glErrorName(GLenum e) {
    switch (e) {
        case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
        case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
        case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
        case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
        case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
        case GL_STACK_OVERFLOW: return "GL_STACK_OVERFLOW";
        case GL_STACK_UNDERFLOW: return "GL_STACK_UNDERFLOW";
        case GL_CONTEXT_LOST: return "GL_CONTEXT_LOST";
        default: return "unknown GL error";
    }
}
}  // namespace

std::uint32_t GlContext::takeCallerErrors() { return drainErrors(Tally::None).count; }

Status GlContext::checkErrorsDuring(const char* what) {
    const DrainedErrors d = drainErrors(Tally::Count);
    const std::uint32_t n = d.count;
    const GLenum first = d.first;
    if (n == 0) return {};
    char code[16];
    std::snprintf(code, sizeof code, "0x%04x", static_cast<unsigned>(first));
    std::string msg = std::string(what) + " raised GL error " + glErrorName(first) + " (" + code + ")";
    if (n > 1) msg += " and " + std::to_string(n - 1) + " more";
    return Error{msg, ErrorCode::GlError};
}

std::uint64_t GlContext::checkErrors() {
    drainErrors(Tally::CountAndReport);
    return errorCount_;
}

}  // namespace dyncull
