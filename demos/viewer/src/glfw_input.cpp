// GLFW keyboard/mouse callbacks -> dyncull::InputFrame, and key names for help texts.
#include "glfw_input.hpp"

#include <epoxy/gl.h>  // before GLFW so GLFW does not pull in the system GL header
#include <GLFW/glfw3.h>

namespace dyncull {

const char* keyName(Key k) {
    static const char* const kNames[] = {
        "?", "A", "B", "C", "D", "E", "F", "G", "H", "I", "J", "K", "L", "M", "N", "O", "P", "Q", "R", "S", "T",
        "U", "V", "W", "X", "Y", "Z", "0", "1", "2", "3", "4", "5", "6", "7", "8", "9", "Space", "Esc", "Enter",
        "Tab", "Backspace", "LShift", "RShift", "LCtrl", "RCtrl", "LAlt", "RAlt", "=", "-", "Keypad+", "Keypad-",
        "Up", "Down", "Left", "Right", "F1", "F2", "F3", "F4"};
    static_assert(sizeof kNames / sizeof kNames[0] == static_cast<std::size_t>(Key::Count));
    const auto i = static_cast<std::size_t>(k);
    return i < static_cast<std::size_t>(Key::Count) ? kNames[i] : "?";
}

namespace detail {

Key keyFromGlfw(int g) {
    if (g >= GLFW_KEY_A && g <= GLFW_KEY_Z) return static_cast<Key>(static_cast<int>(Key::A) + (g - GLFW_KEY_A));
    if (g >= GLFW_KEY_0 && g <= GLFW_KEY_9) return static_cast<Key>(static_cast<int>(Key::Num0) + (g - GLFW_KEY_0));
    if (g >= GLFW_KEY_F1 && g <= GLFW_KEY_F4) return static_cast<Key>(static_cast<int>(Key::F1) + (g - GLFW_KEY_F1));
    switch (g) {
        case GLFW_KEY_SPACE: return Key::Space;
        case GLFW_KEY_ESCAPE: return Key::Escape;
        case GLFW_KEY_ENTER: return Key::Enter;
        case GLFW_KEY_TAB: return Key::Tab;
        case GLFW_KEY_BACKSPACE: return Key::Backspace;
        case GLFW_KEY_LEFT_SHIFT: return Key::LeftShift;
        case GLFW_KEY_RIGHT_SHIFT: return Key::RightShift;
        case GLFW_KEY_LEFT_CONTROL: return Key::LeftControl;
        case GLFW_KEY_RIGHT_CONTROL: return Key::RightControl;
        case GLFW_KEY_LEFT_ALT: return Key::LeftAlt;
        case GLFW_KEY_RIGHT_ALT: return Key::RightAlt;
        case GLFW_KEY_EQUAL: return Key::Equal;
        case GLFW_KEY_MINUS: return Key::Minus;
        case GLFW_KEY_KP_ADD: return Key::KeypadAdd;
        case GLFW_KEY_KP_SUBTRACT: return Key::KeypadSubtract;
        case GLFW_KEY_UP: return Key::Up;
        case GLFW_KEY_DOWN: return Key::Down;
        case GLFW_KEY_LEFT: return Key::Left;
        case GLFW_KEY_RIGHT: return Key::Right;
        default: return Key::Unknown;
    }
}

namespace {
GlfwInputCollector* collectorOf(GLFWwindow* w) { return static_cast<GlfwInputCollector*>(glfwGetWindowUserPointer(w)); }
}  // namespace

void GlfwInputCollector::attach(GLFWwindow* window) {
    window_ = window;
    glfwSetWindowUserPointer(window, this);
    glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int, int action, int) { collectorOf(w)->onKey(key, action); });
    glfwSetMouseButtonCallback(window,
                               [](GLFWwindow* w, int button, int action, int) { collectorOf(w)->onButton(button, action); });
    glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) { collectorOf(w)->onCursor(x, y); });
}

InputFrame GlfwInputCollector::take() {
    InputFrame out = pending_;
    out.closeRequested = window_ && glfwWindowShouldClose(window_);
    pending_.pressed.clear();
    pending_.mouseDelta = {0.0f, 0.0f};
    return out;
}

void GlfwInputCollector::setCursorCaptured(bool captured) {
    if (!window_) return;
    glfwSetInputMode(window_, GLFW_CURSOR, captured ? GLFW_CURSOR_DISABLED : GLFW_CURSOR_NORMAL);
    haveCursor_ = false;  // the cursor jumps when the mode changes: not a user motion
}

void GlfwInputCollector::onKey(int glfwKey, int action) {
    const Key k = keyFromGlfw(glfwKey);
    if (k == Key::Unknown) return;
    if (action == GLFW_PRESS) {
        pending_.press(k);
    } else if (action == GLFW_RELEASE) {
        pending_.keysDown.reset(static_cast<std::size_t>(k));
    }  // GLFW_REPEAT: held already, not a new press
}

void GlfwInputCollector::onButton(int glfwButton, int action) {
    int b = -1;
    if (glfwButton == GLFW_MOUSE_BUTTON_LEFT) b = static_cast<int>(MouseButton::Left);
    if (glfwButton == GLFW_MOUSE_BUTTON_RIGHT) b = static_cast<int>(MouseButton::Right);
    if (glfwButton == GLFW_MOUSE_BUTTON_MIDDLE) b = static_cast<int>(MouseButton::Middle);
    if (b >= 0) pending_.buttonsDown[static_cast<std::size_t>(b)] = action == GLFW_PRESS;
}

void GlfwInputCollector::onCursor(double x, double y) {
    if (haveCursor_)
        pending_.mouseDelta += glm::vec2(static_cast<float>(x - lastX_), static_cast<float>(y - lastY_));
    lastX_ = x;
    lastY_ = y;
    haveCursor_ = true;
}

}  // namespace detail
}  // namespace dyncull
