// The viewer's window: an OpenGL 4.5 core context in a GLFW window (an X display or Xvfb),
// with keyboard and mouse input. Demo side: a game brings its own window and context and
// wraps it with GlContext::borrowCurrent.
#pragma once

#include <memory>

#include "dyncull/engine/gl_context.hpp"
#include "dyncull/viewer/input.hpp"

namespace dyncull {

/// A GLFW window rendering into an RGBA8 + 32-bit float depth FBO of its framebuffer size
/// (present() copies the colour to the window). Owns the window; GLFW is initialised while
/// any window lives and terminated with the last one.
class WindowContext : public GlContext {
public:
    /// Creates the window and makes its context current; fails cleanly (Unsupported) when
    /// there is no display.
    static Expected<std::unique_ptr<WindowContext>> create(const ContextOptions& options);

    /// The user asked to close.
    virtual bool shouldClose() const = 0;
    /// Keyboard/mouse input gathered by present() since the previous call (held keys are
    /// current; presses and mouse motion accumulate).
    virtual InputFrame takeInput() = 0;
    /// Hides and locks the cursor so mouse motion is unbounded (mouse look); false releases it.
    virtual void setCursorCaptured(bool captured) = 0;

protected:
    WindowContext() : GlContext(ContextKind::GlfwWindow) {}
};

/// A window or a headless EGL context, as options.kind says (the CLI's choice).
Expected<std::unique_ptr<GlContext>> createContext(const ContextOptions& options);

}  // namespace dyncull
