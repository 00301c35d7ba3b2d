// An OpenGL 4.5 core context: headless EGL, a GLFW window, or a game's own context that
// dyncull borrows. Dyncull's own contexts render into an offscreen FBO with RGBA8 colour and
// 32-bit float depth (reversed Z needs float depth; objects/camera.hpp); a window's present()
// copies the colour to the window. The Engine never uses the FBO: it draws into whatever
// framebuffer and viewport are bound when it is called (engine/frame_contract.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <glm/glm.hpp>

#include "dyncull/objects/error.hpp"

namespace dyncull {

enum class ContextKind : std::uint8_t {
    HeadlessEgl,  ///< EGL without a surface (Mesa surfaceless / device platform), offscreen FBO
    GlfwWindow,   ///< GLFW window on an X display (or Xvfb): the demos' viewer (dyncull/viewer/window_context.hpp)
    Borrowed,     ///< the caller's context, current when GlContext::borrowCurrent was called
};

struct ContextOptions {
    ContextKind kind = ContextKind::HeadlessEgl;
    int width = 1280;   ///< pixels, >= 1: FBO size (headless) or window size
    int height = 720;   ///< pixels, >= 1
    int glMajor = 4;    ///< requested core-profile version; 4.5 is what the engine needs
    int glMinor = 5;
    bool debug = false;  ///< debug context + KHR_debug callback that counts GL errors
    bool visible = true;  ///< windows only: show the window
    std::string title = "dyncull";  ///< windows only
};

/// Why glGetGraphicsResetStatus reported a reset (GL_GUILTY/INNOCENT/UNKNOWN_CONTEXT_RESET).
enum class ResetKind : std::uint8_t { None, Guilty, Innocent, Unknown };

/// Test-only fault injection: llvmpipe never loses a context and rarely runs out of
/// memory, so tests/engine/gl_faults_test.cpp sets these to drive the error paths that a
/// real GPU reset or GL_OUT_OF_MEMORY would take. Nothing in dyncull sets them; they are
/// reachable only through GlContext::faultInjectionForTesting().
struct GlFaultInjection {
    /// checkReset() reports this reset as if glGetGraphicsResetStatus had returned it.
    ResetKind simulateReset = ResetKind::None;
    /// After `allocationsBeforeFailure` more checkAllocation() calls succeed, the next
    /// `failBufferAllocations` report GL_OUT_OF_MEMORY (each call uses up one of either).
    std::uint32_t allocationsBeforeFailure = 0;
    std::uint32_t failBufferAllocations = 0;
};

/// Owns the native context (and, headless, its FBO), except when Borrowed. Not copyable.
/// The context is made current on creation; GL calls must happen on a thread where it is
/// current (one thread at a time, as GL itself requires).
class GlContext {
public:
    /// Creates a headless EGL context and makes it current. Never throws or aborts: failures
    /// come back as an Error naming every attempt, e.g. "EGL: surfaceless Mesa platform:
    /// eglInitialize failed (EGL_NOT_INITIALIZED); device platform: no devices; ...".
    /// Windows are not part of the runtime: kind GlfwWindow is refused (Unsupported).
    static Expected<std::unique_ptr<GlContext>> create(const ContextOptions& options);
    /// Wraps the context current on this thread, which the caller (a game) created and keeps
    /// owning: destroying the wrapper leaves the native context, its framebuffers and its GL
    /// state alone. framebuffer() is 0 and size() the viewport at the time of the call;
    /// makeCurrent() and present() do nothing (the game does both). Errors: no context
    /// current (WrongContext), or one older than OpenGL 4.5 (Unsupported).
    static Expected<std::unique_ptr<GlContext>> borrowCurrent();

    virtual ~GlContext() = default;
    GlContext(const GlContext&) = delete;
    GlContext& operator=(const GlContext&) = delete;

    virtual void makeCurrent() = 0;
    /// Makes no context current on this thread (dyncull's own kinds; Borrowed: nothing).
    virtual void releaseCurrent() = 0;
    /// True if this context is current on the calling thread. It recognises its own context
    /// by a labelled vertex array made at creation (vertex arrays are never shared between
    /// contexts), so it works for every kind, borrowed ones included; no context current
    /// gives false.
    bool isCurrent() const;
    /// isCurrent() as a Status: "<what>: the GL context current on this thread is not the one
    /// <...> was made on" (ErrorCode::WrongContext), so a call on the wrong context fails at
    /// once instead of waiting on another context's queries or deleting its objects.
    Status checkCurrent(const char* what) const;
    /// Dyncull's own frames (demos, tests; never the Engine): binds framebuffer(), sets the
    /// viewport to size(), and clears colour to `colour` and depth to the far plane of the
    /// reversed-Z convention (0).
    void clearFramebuffer(const glm::vec3& colour);
    /// Windows: copy the FBO's colour to the window, swap buffers, poll events, and follow
    /// a resize (size() and the FBO change with the window). Headless: glFlush.
    virtual void present() = 0;

    ContextKind kind() const { return kind_; }
    /// GL name of the framebuffer to render into (an FBO with float depth; both kinds).
    std::uint32_t framebuffer() const { return framebuffer_; }
    /// Framebuffer size in pixels (may differ from the window size on HiDPI screens).
    glm::ivec2 size() const { return size_; }
    /// GL_RENDERER / GL_VERSION strings of the context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    const std::string& rendererName() const { return renderer_; }
    const std::string& versionString() const { return version_; }
    /// What created the context, e.g. "EGL surfaceless Mesa" or "GLFW 3.3.8 X11".
    const std::string& platformName() const { return platform_; }

    /// Drains glGetError and adds the count to glErrorCount(); in debug contexts the
    /// KHR_debug callback also counts GL_DEBUG_TYPE_ERROR messages. Soak tests assert 0.
    std::uint64_t checkErrors();
    /// At the start of a dyncull call on a borrowed frame: takes the errors the caller left
    /// pending off the error flags, so they are not blamed on dyncull, and returns how many
    /// there were (they are not added to glErrorCount()).
    std::uint32_t takeCallerErrors();
    /// At the end of a dyncull call: drains the error flags like checkErrors and, if any
    /// was set, returns "<what> raised GL error GL_INVALID_OPERATION (0x0502) and N more"
    /// (ErrorCode::GlError).
    Status checkErrorsDuring(const char* what);
    std::uint64_t glErrorCount() const { return errorCount_; }
    bool isDebug() const { return debug_; }

    /// True if the driver granted a robust context with reset notification
    /// LOSE_CONTEXT_ON_RESET (requested on every platform that offers it; the fallback is
    /// a plain context, on which GL never reports resets).
    bool resetNotification() const { return resetNotification_; }
    /// Polls glGetGraphicsResetStatus (GL 4.5 core). After the first reset the context is
    /// lost for good: every later call returns the same Error without touching GL, e.g.
    /// "OpenGL context lost (innocent reset: ...); recreate the GlContext and the Engine".
    Status checkReset();
    bool lost() const { return lost_; }
    /// Call right after a glNamedBufferStorage/glNamedBufferData: drains glGetError and
    /// returns "out of GPU memory <what> (<bytes> bytes)" if it held GL_OUT_OF_MEMORY
    /// (other errors are counted as in checkErrors).
    Status checkAllocation(const std::string& what, std::size_t bytes);
    /// See GlFaultInjection: for tests only.
    GlFaultInjection& faultInjectionForTesting() { return faults_; }

protected:
    friend Expected<std::unique_ptr<GlContext>> createEglContext(const ContextOptions&);
    explicit GlContext(ContextKind kind) : kind_(kind) {}
    /// Called by subclasses once current: queries strings, makes the fingerprint of
    /// isCurrent(), installs the debug callback (and, for dyncull's own contexts, sets the
    /// reversed-Z clip control and discards creation-time GL errors).
    void initCommon(bool debug);
    /// Deletes the fingerprint (subclass destructors, with the context current).
    void releaseCommon();

private:
    /// What draining the GL error flags found: how many, the first, and whether one was
    /// GL_OUT_OF_MEMORY.
    struct DrainedErrors {
        std::uint32_t count = 0;
        std::uint32_t first = 0;  // GLenum; 0 = GL_NO_ERROR
        bool outOfMemory = false;
    };
    enum class Tally : std::uint8_t {
        None,            ///< the caller's errors: not added to glErrorCount()
        Count,           ///< added (unless the debug callback counted them already)
        CountAndReport,  ///< added, and the first 20 printed to stderr
    };
    /// The one loop over glGetError, bounded because the flags may never clear on a lost context.
    DrainedErrors drainErrors(Tally tally);

protected:
    ContextKind kind_;
    std::uint32_t framebuffer_ = 0;
    glm::ivec2 size_{0};
    std::string renderer_, version_, platform_;
    std::uint64_t errorCount_ = 0;
    bool debug_ = false;
    bool resetNotification_ = false;
    bool lost_ = false;
    std::string lostMessage_;
    std::uint32_t fingerprint_ = 0;  // a vertex array labelled fingerprintLabel_
    std::string fingerprintLabel_;
    GlFaultInjection faults_;
};

/// Headless EGL context with an RGBA8 + depth32F FBO of the requested size.
Expected<std::unique_ptr<GlContext>> createEglContext(const ContextOptions& options);

}  // namespace dyncull
