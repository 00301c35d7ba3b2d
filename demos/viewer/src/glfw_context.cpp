// OpenGL 4.5 core context in a GLFW window (needs an X display, e.g. Xvfb). Renders into
// an offscreen FBO with a 32-bit float depth buffer, like the headless context: reversed Z
// (objects/camera.hpp) needs float depth, and a window's default depth buffer is 24-bit
// fixed point. present() copies the colour to the window, swaps and polls events.
#include <algorithm>
#include <string>

#include <epoxy/gl.h>  // before GLFW so GLFW does not pull in the system GL header
#include <GLFW/glfw3.h>

#include "dyncull/viewer/window_context.hpp"
#include "glfw_input.hpp"

namespace dyncull {

namespace {

std::string& lastGlfwError() {
    static std::string message;
    return message;
}

void onGlfwError(int code, const char* description) {
    lastGlfwError() = std::string(description ? description : "unknown") + " (code " + std::to_string(code) + ")";
}

// glfwInit/glfwTerminate are process-wide; terminate only after the last window closes.
int& liveWindows() {
    static int n = 0;
    return n;
}

class GlfwContext final : public WindowContext {
public:
    ~GlfwContext() override {
        if (window_) {
            GLFWwindow* previous = glfwGetCurrentContext();
            glfwMakeContextCurrent(window_);
            releaseCommon();
            if (framebuffer_) glDeleteFramebuffers(1, &framebuffer_);
            if (colour_) glDeleteRenderbuffers(1, &colour_);
            if (depth_) glDeleteRenderbuffers(1, &depth_);
            glfwDestroyWindow(window_);
            if (previous != window_) glfwMakeContextCurrent(previous);  // the caller's context stays current
        }
        if (--liveWindows() == 0) glfwTerminate();
    }
    void makeCurrent() override { glfwMakeContextCurrent(window_); }
    void releaseCurrent() override { glfwMakeContextCurrent(nullptr); }
    void present() override {
        glBlitNamedFramebuffer(framebuffer_, 0, 0, 0, size_.x, size_.y, 0, 0, size_.x, size_.y, GL_COLOR_BUFFER_BIT,
                               GL_NEAREST);
        glfwSwapBuffers(window_);
        glfwPollEvents();
        int w = 0, h = 0;
        glfwGetFramebufferSize(window_, &w, &h);
        // Follow user resizes (0x0 while minimised: keep the last size).
        if (w > 0 && h > 0 && glm::ivec2(w, h) != size_) resizeFramebuffer(w, h);
    }
    /// Creates the FBO on first use; later calls re-specify its attachments' storage.
    std::string resizeFramebuffer(int w, int h) {
        if (!framebuffer_) {
            glCreateRenderbuffers(1, &colour_);
            glCreateRenderbuffers(1, &depth_);
            glCreateFramebuffers(1, &framebuffer_);
        }
        glNamedRenderbufferStorage(colour_, GL_RGBA8, w, h);
        glNamedRenderbufferStorage(depth_, GL_DEPTH_COMPONENT32F, w, h);
        glNamedFramebufferRenderbuffer(framebuffer_, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_);
        glNamedFramebufferRenderbuffer(framebuffer_, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
        const GLenum status = glCheckNamedFramebufferStatus(framebuffer_, GL_FRAMEBUFFER);
        if (status != GL_FRAMEBUFFER_COMPLETE) return "window framebuffer incomplete (status " + std::to_string(status) + ")";
        size_ = {w, h};
        return {};
    }
    bool shouldClose() const override { return glfwWindowShouldClose(window_) != 0; }
    InputFrame takeInput() override { return input_.take(); }
    void setCursorCaptured(bool captured) override { input_.setCursorCaptured(captured); }

    GLFWwindow* window_ = nullptr;
    GLuint colour_ = 0, depth_ = 0;
    detail::GlfwInputCollector input_;
};

}  // namespace

Expected<std::unique_ptr<WindowContext>> WindowContext::create(const ContextOptions& o) {
    if (o.width < 1 || o.height < 1 || o.width > 16384 || o.height > 16384)
        return Error{"window: size " + std::to_string(o.width) + "x" + std::to_string(o.height) + " out of range (1..16384)"};
    glfwSetErrorCallback(onGlfwError);
    lastGlfwError().clear();
    if (!glfwInit()) return Error{"GLFW: glfwInit failed: " + lastGlfwError(), ErrorCode::Unsupported};
    auto ctx = std::make_unique<GlfwContext>();
    ++liveWindows();  // balanced by ~GlfwContext even on failure below

    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, o.glMajor);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, o.glMinor);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, o.debug ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_VISIBLE, o.visible ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_DEPTH_BITS, 0);  // depth lives in the offscreen FBO
    // Robust context with reset notification where the driver offers it (see
    // GlContext::resetNotification); otherwise the same window without.
    glfwWindowHint(GLFW_CONTEXT_ROBUSTNESS, GLFW_LOSE_CONTEXT_ON_RESET);
    ctx->window_ = glfwCreateWindow(o.width, o.height, o.title.c_str(), nullptr, nullptr);
    if (!ctx->window_) {
        glfwWindowHint(GLFW_CONTEXT_ROBUSTNESS, GLFW_NO_ROBUSTNESS);
        lastGlfwError().clear();
        ctx->window_ = glfwCreateWindow(o.width, o.height, o.title.c_str(), nullptr, nullptr);
    }
    if (!ctx->window_)
        return Error{"GLFW: window with OpenGL " + std::to_string(o.glMajor) + "." + std::to_string(o.glMinor) +
                     " core context: " + lastGlfwError()};
    glfwMakeContextCurrent(ctx->window_);
    ctx->input_.attach(ctx->window_);
    glfwSwapInterval(0);  // measurements must not be paced by vsync
    int w = 0, h = 0;
    glfwGetFramebufferSize(ctx->window_, &w, &h);
    int vmaj = 0, vmin = 0, vrev = 0;
    glfwGetVersion(&vmaj, &vmin, &vrev);
    ctx->platform_ = "GLFW " + std::to_string(vmaj) + "." + std::to_string(vmin) + "." + std::to_string(vrev) + " window";
    ctx->initCommon(o.debug);
    if (std::string e = ctx->resizeFramebuffer(std::max(w, 1), std::max(h, 1)); !e.empty()) return Error{"GLFW: " + e};
    glBindFramebuffer(GL_FRAMEBUFFER, ctx->framebuffer_);
    return std::unique_ptr<WindowContext>(std::move(ctx));
}

Expected<std::unique_ptr<GlContext>> createContext(const ContextOptions& options) {
    if (options.kind != ContextKind::GlfwWindow) return GlContext::create(options);
    auto window = WindowContext::create(options);
    if (!window) return window.error();
    return std::unique_ptr<GlContext>(window.take());
}

}  // namespace dyncull
