// OpenGL 4.5 core context in a GLFW window (needs an X display, e.g. Xvfb). Renders into
// the window's default framebuffer; present() swaps and polls events.
#include <string>

#include <epoxy/gl.h>  // before GLFW so GLFW does not pull in the system GL header
#include <GLFW/glfw3.h>

#include "dyncull/engine/gl_context.hpp"
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

class GlfwContext final : public GlContext {
public:
    GlfwContext() : GlContext(ContextKind::GlfwWindow) {}
    ~GlfwContext() override {
        if (window_) glfwDestroyWindow(window_);
        if (--liveWindows() == 0) glfwTerminate();
    }
    void makeCurrent() override { glfwMakeContextCurrent(window_); }
    void present() override {
        glfwSwapBuffers(window_);
        glfwPollEvents();
        int w = 0, h = 0;
        glfwGetFramebufferSize(window_, &w, &h);
        if (w > 0 && h > 0) size_ = {w, h};  // follow user resizes; 0x0 while minimised
    }
    bool shouldClose() const override { return glfwWindowShouldClose(window_) != 0; }
    InputFrame takeInput() override { return input_.take(); }
    void setCursorCaptured(bool captured) override { input_.setCursorCaptured(captured); }

    GLFWwindow* window_ = nullptr;
    detail::GlfwInputCollector input_;
};

}  // namespace

Expected<std::unique_ptr<GlContext>> createGlfwContext(const ContextOptions& o) {
    glfwSetErrorCallback(onGlfwError);
    lastGlfwError().clear();
    if (!glfwInit()) return Error{"GLFW: glfwInit failed: " + lastGlfwError()};
    auto ctx = std::make_unique<GlfwContext>();
    ++liveWindows();  // balanced by ~GlfwContext even on failure below

    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, o.glMajor);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, o.glMinor);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, o.debug ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_VISIBLE, o.visible ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_DEPTH_BITS, 24);
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
    ctx->size_ = {w, h};
    ctx->framebuffer_ = 0;
    int vmaj = 0, vmin = 0, vrev = 0;
    glfwGetVersion(&vmaj, &vmin, &vrev);
    ctx->platform_ = "GLFW " + std::to_string(vmaj) + "." + std::to_string(vmin) + "." + std::to_string(vrev) + " window";
    ctx->initCommon(o.debug);
    return std::unique_ptr<GlContext>(std::move(ctx));
}

}  // namespace dyncull
