// Headless OpenGL 4.5 core context through EGL, no window system: tries the Mesa
// surfaceless platform, then every EGL device (EGL_EXT_platform_device), then the default
// display; renders into an FBO because there is no surface.
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include "dyncull/engine/gl_context.hpp"
#include "sanitizer_driver_pin.hpp"

namespace dyncull {

namespace {

const char* eglErrorName(EGLint e) {
    switch (e) {
        case EGL_SUCCESS: return "EGL_SUCCESS";
        case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
        case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
        case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
        case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
        case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
        case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
        case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
        case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
        case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
        case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
        case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
        case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
        case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
        case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
        default: return "unknown EGL error";
    }
}

std::string failed(const char* call) { return std::string(call) + " failed (" + eglErrorName(eglGetError()) + ")"; }

bool hasExtension(const char* list, const char* name) {
    if (!list) return false;
    const std::size_t n = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n) {
        const bool startOk = p == list || p[-1] == ' ';
        if (startOk && (p[n] == ' ' || p[n] == '\0')) return true;
    }
    return false;
}

// EGLDisplays are process-wide per (platform, native display): eglTerminate on one would
// kill every other context on it, so terminate only when the last of ours goes away.
std::map<EGLDisplay, int>& displayRefs() {
    static std::map<EGLDisplay, int> refs;
    return refs;
}

void releaseDisplay(EGLDisplay dpy) {
    auto& refs = displayRefs();
    auto it = refs.find(dpy);
    if (it == refs.end() || --it->second > 0) return;
    refs.erase(it);
    eglTerminate(dpy);
}

class EglContext final : public GlContext {
public:
    EglContext() : GlContext(ContextKind::HeadlessEgl) {}
    ~EglContext() override {
        if (context_ != EGL_NO_CONTEXT) {
            // Whatever context the caller had current is current again afterwards.
            const EGLContext previous = eglGetCurrentContext();
            const EGLDisplay previousDisplay = eglGetCurrentDisplay();
            const EGLSurface previousDraw = eglGetCurrentSurface(EGL_DRAW), previousRead = eglGetCurrentSurface(EGL_READ);
            eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_);
            releaseCommon();
            if (framebuffer_) glDeleteFramebuffers(1, &framebuffer_);
            if (colour_) glDeleteRenderbuffers(1, &colour_);
            if (depth_) glDeleteRenderbuffers(1, &depth_);
            eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            eglDestroyContext(display_, context_);
            if (previous != EGL_NO_CONTEXT && previous != context_)
                eglMakeCurrent(previousDisplay, previousDraw, previousRead, previous);
        }
        if (display_ != EGL_NO_DISPLAY) releaseDisplay(display_);
    }

    void makeCurrent() override { eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_); }
    void releaseCurrent() override { eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }
    void present() override { glFlush(); }

    // Initialise `dpy` and create a current context on it; on failure returns why and
    // leaves nothing initialised by us.
    std::string tryDisplay(EGLDisplay dpy, const ContextOptions& o) {
        if (dpy == EGL_NO_DISPLAY) return failed("eglGetPlatformDisplay");
        EGLint major = 0, minor = 0;
        if (!eglInitialize(dpy, &major, &minor)) return failed("eglInitialize");
        detail::pinLoadedGlDrivers();  // the driver is loaded now, even if context creation fails
        ++displayRefs()[dpy];
        display_ = dpy;  // from here the destructor releases it
        if (!eglBindAPI(EGL_OPENGL_API)) return failed("eglBindAPI(EGL_OPENGL_API)");
        const EGLint configAttribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                        EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_NONE};
        EGLConfig config = nullptr;
        EGLint count = 0;
        if (!eglChooseConfig(dpy, configAttribs, &config, 1, &count)) return failed("eglChooseConfig");
        if (count < 1) {
            // Surfaceless contexts need no config at all if the display supports it.
            const char* ext = eglQueryString(dpy, EGL_EXTENSIONS);
            if (!hasExtension(ext, "EGL_KHR_no_config_context")) return "no OpenGL pbuffer config";
            config = EGL_NO_CONFIG_KHR;
        }
        std::vector<EGLint> attribs = {EGL_CONTEXT_MAJOR_VERSION, o.glMajor,
                                       EGL_CONTEXT_MINOR_VERSION, o.glMinor,
                                       EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                       EGL_CONTEXT_OPENGL_DEBUG, o.debug ? EGL_TRUE : EGL_FALSE};
        // Context with reset notification, so a GPU reset shows up in
        // glGetGraphicsResetStatus instead of as undefined behaviour: EGL 1.5 core
        // attribute, else EGL_EXT_create_context_robustness (which ties it to robust
        // access); a driver that refuses gets a plain context (GlContext::resetNotification()
        // says which). EGL 1.5 lets us skip robust buffer access, which costs frame time
        // (docs/RELIABILITY.md) and which dyncull, never indexing past its buffers, needs not.
        std::vector<EGLint> robust = attribs;
        if (major > 1 || (major == 1 && minor >= 5)) {
            robust.insert(robust.end(), {EGL_CONTEXT_OPENGL_RESET_NOTIFICATION_STRATEGY, EGL_LOSE_CONTEXT_ON_RESET});
        } else if (hasExtension(eglQueryString(dpy, EGL_EXTENSIONS), "EGL_EXT_create_context_robustness")) {
            robust.insert(robust.end(), {EGL_CONTEXT_OPENGL_ROBUST_ACCESS_EXT, EGL_TRUE,
                                         EGL_CONTEXT_OPENGL_RESET_NOTIFICATION_STRATEGY_EXT, EGL_LOSE_CONTEXT_ON_RESET_EXT});
        }
        attribs.push_back(EGL_NONE);
        robust.push_back(EGL_NONE);
        if (robust.size() > attribs.size()) context_ = eglCreateContext(dpy, config, EGL_NO_CONTEXT, robust.data());
        if (context_ == EGL_NO_CONTEXT) context_ = eglCreateContext(dpy, config, EGL_NO_CONTEXT, attribs.data());
        if (context_ == EGL_NO_CONTEXT)
            return failed(("eglCreateContext(OpenGL " + std::to_string(o.glMajor) + "." + std::to_string(o.glMinor) +
                           " core)").c_str());
        if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
            return failed("eglMakeCurrent(EGL_NO_SURFACE)");
        return {};
    }

    std::string createFramebuffer(int w, int h) {
        glCreateRenderbuffers(1, &colour_);
        glNamedRenderbufferStorage(colour_, GL_RGBA8, w, h);
        glCreateRenderbuffers(1, &depth_);
        glNamedRenderbufferStorage(depth_, GL_DEPTH_COMPONENT32F, w, h);
        glCreateFramebuffers(1, &framebuffer_);
        glNamedFramebufferRenderbuffer(framebuffer_, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_);
        glNamedFramebufferRenderbuffer(framebuffer_, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
        const GLenum status = glCheckNamedFramebufferStatus(framebuffer_, GL_FRAMEBUFFER);
        if (status != GL_FRAMEBUFFER_COMPLETE) return "offscreen framebuffer incomplete (status " + std::to_string(status) + ")";
        glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
        size_ = {w, h};
        return {};
    }

private:
    EGLDisplay display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
    GLuint colour_ = 0, depth_ = 0;
};

}  // namespace

Expected<std::unique_ptr<GlContext>> createEglContext(const ContextOptions& o) {
    std::string tried;
    auto note = [&tried](const std::string& what, const std::string& why) {
        tried += (tried.empty() ? "" : "; ") + what + ": " + why;
    };
    // Returns the context if `dpy` works, else records why and returns null.
    auto attempt = [&](EGLDisplay dpy, const std::string& what) -> std::unique_ptr<EglContext> {
        auto ctx = std::make_unique<EglContext>();
        std::string why = ctx->tryDisplay(dpy, o);
        if (why.empty()) why = ctx->createFramebuffer(o.width, o.height);
        if (!why.empty()) {
            note(what, why);
            return nullptr;
        }
        ctx->platform_ = "EGL " + what;
        return ctx;
    };

    const char* clientExt = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);  // null without EGL_EXT_client_extensions
    const bool platformBase = hasExtension(clientExt, "EGL_EXT_platform_base");

    std::unique_ptr<EglContext> ctx;
    if (platformBase && hasExtension(clientExt, "EGL_MESA_platform_surfaceless")) {
        ctx = attempt(eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr),
                      "surfaceless Mesa platform");
    } else {
        note("surfaceless Mesa platform", "EGL_MESA_platform_surfaceless not supported");
    }

    if (!ctx) {
        if (platformBase && hasExtension(clientExt, "EGL_EXT_platform_device") &&
            (hasExtension(clientExt, "EGL_EXT_device_enumeration") || hasExtension(clientExt, "EGL_EXT_device_base"))) {
            EGLint n = 0;
            if (!eglQueryDevicesEXT(0, nullptr, &n) || n <= 0) {
                note("device platform", "no devices");
            } else {
                std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(n));
                eglQueryDevicesEXT(n, devices.data(), &n);
                for (EGLint i = 0; i < n && !ctx; ++i)
                    ctx = attempt(eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[static_cast<std::size_t>(i)], nullptr),
                                  "device platform (device " + std::to_string(i) + ")");
            }
        } else {
            note("device platform", "EGL_EXT_platform_device not supported");
        }
    }

    if (!ctx) ctx = attempt(eglGetDisplay(EGL_DEFAULT_DISPLAY), "default display");
    if (!ctx) return Error{"EGL: " + tried, ErrorCode::Unsupported};

    ctx->initCommon(o.debug);
    return std::unique_ptr<GlContext>(std::move(ctx));
}

}  // namespace dyncull
