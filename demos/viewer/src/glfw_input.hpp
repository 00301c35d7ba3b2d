// Internal: collects a GLFW window's keyboard/mouse events into dyncull::InputFrame.
#pragma once

#include "dyncull/viewer/input.hpp"

struct GLFWwindow;

namespace dyncull::detail {

/// Installs key/button/cursor callbacks on a window (using its user pointer, which must
/// point at this collector) and accumulates events until take(). Must outlive the window's
/// callbacks (destroy the window first or detach()).
class GlfwInputCollector {
public:
    void attach(GLFWwindow* window);
    /// Current held state plus the presses and motion since the previous take().
    InputFrame take();
    void setCursorCaptured(bool captured);

    // Called from the GLFW callbacks.
    void onKey(int glfwKey, int action);
    void onButton(int glfwButton, int action);
    void onCursor(double x, double y);

private:
    GLFWwindow* window_ = nullptr;
    InputFrame pending_;
    bool haveCursor_ = false;
    double lastX_ = 0.0, lastY_ = 0.0;
};

/// dyncull key for a GLFW key code (Key::Unknown for keys dyncull does not name).
Key keyFromGlfw(int glfwKey);

}  // namespace dyncull::detail
