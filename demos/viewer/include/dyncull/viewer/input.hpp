// Keyboard and mouse input of a window, as plain data (no GLFW types), so an interactive
// loop can be driven by a real window or by a scripted sequence in tests alike.
#pragma once

#include <array>
#include <bitset>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace dyncull {

/// The keys dyncull's viewers use (a subset of a US keyboard). Layout-independent:
/// they name physical positions as GLFW does.
enum class Key : std::uint8_t {
    Unknown,
    A, B, C, D, E, F, G, H, I, J, K, L, M, N, O, P, Q, R, S, T, U, V, W, X, Y, Z,
    Num0, Num1, Num2, Num3, Num4, Num5, Num6, Num7, Num8, Num9,
    Space, Escape, Enter, Tab, Backspace,
    LeftShift, RightShift, LeftControl, RightControl, LeftAlt, RightAlt,
    Equal, Minus, KeypadAdd, KeypadSubtract,
    Up, Down, Left, Right,
    F1, F2, F3, F4,
    Count,  ///< number of keys, not a key
};

enum class MouseButton : std::uint8_t { Left, Right, Middle, Count };

/// Input gathered between two polls: which keys and buttons are held now, the key presses
/// in order (auto-repeat excluded), and how far the cursor moved, in window pixels
/// (x right, y down).
struct InputFrame {
    std::bitset<static_cast<std::size_t>(Key::Count)> keysDown;
    std::array<bool, static_cast<std::size_t>(MouseButton::Count)> buttonsDown{};
    std::vector<Key> pressed;
    glm::vec2 mouseDelta{0.0f};
    bool closeRequested = false;  ///< the window's close button (or Esc handled elsewhere)

    bool down(Key k) const { return keysDown.test(static_cast<std::size_t>(k)); }
    bool down(MouseButton b) const { return buttonsDown[static_cast<std::size_t>(b)]; }
    /// True if `k` was pressed (went down) since the previous poll.
    bool wasPressed(Key k) const {
        for (Key p : pressed)
            if (p == k) return true;
        return false;
    }
    void press(Key k) {
        keysDown.set(static_cast<std::size_t>(k));
        pressed.push_back(k);
    }
};

/// Printable name of a key ("A", "1", "Space", ...), for help texts.
const char* keyName(Key k);

}  // namespace dyncull
