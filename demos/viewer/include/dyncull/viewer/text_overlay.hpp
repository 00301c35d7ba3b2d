// Screen text from a built-in 5x7 bitmap font (ASCII 32..126, no font files): stats lines
// and legends drawn over a finished frame, crisp at integer scales.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

namespace dyncull {

/// Glyph cell of the built-in font, in font pixels: 5 wide, 7 high; characters advance by
/// 6 and lines by 9 (one pixel of spacing, two of leading).
inline constexpr int kGlyphWidth = 5, kGlyphHeight = 7, kGlyphAdvance = 6, kLineAdvance = 9;

/// Row `row` (0 = top) of the glyph of `c` as 5 bits, bit 4 = leftmost column. Characters
/// outside 32..126 use the '?' glyph.
std::uint8_t glyphRow(char c, int row);

/// Owns a font texture, a program and a VAO. Needs a current GL 4.5 context for its whole
/// life (construct and destroy with the context current). Coordinates are framebuffer
/// pixels with the origin at the top-left corner, y down.
class TextOverlay {
public:
    TextOverlay();
    ~TextOverlay();
    TextOverlay(const TextOverlay&) = delete;
    TextOverlay& operator=(const TextOverlay&) = delete;

    bool valid() const { return program_ != 0; }
    const char* log() const { return log_; }

    /// Queues `text` with its top-left corner at `topLeft`, each font pixel `scale` x
    /// `scale` framebuffer pixels. '\n' starts a new line. RGBA colour 0..1.
    void addText(glm::ivec2 topLeft, std::string_view text, const glm::vec4& colour, int scale = 2);
    /// Queues a filled rectangle (e.g. a translucent panel behind text); drawn before text
    /// queued later, after text queued earlier.
    void addRect(glm::ivec2 topLeft, glm::ivec2 size, const glm::vec4& colour);
    /// Size in framebuffer pixels of `text` at `scale` (widest line x number of lines).
    static glm::ivec2 measure(std::string_view text, int scale = 2);
    void clear() { quads_.clear(); }

    /// Draws and clears the queue into the bound framebuffer; `viewportPixels` is its size.
    /// Depth test off and blending on while drawing; leaves depth test on, blending off.
    void flush(glm::ivec2 viewportPixels);

private:
    struct Quad {
        glm::vec2 topLeft;  // framebuffer pixels
        glm::vec2 size;     // framebuffer pixels
        glm::vec4 colour;
        std::int32_t glyph;  // 0..94, or -1 for a filled rectangle
    };
    std::vector<Quad> quads_;
    std::uint32_t program_ = 0, vao_ = 0, vbo_ = 0, texture_ = 0;
    std::size_t capacity_ = 0;
    int locViewport_ = -1;
    char log_[512] = {};
};

}  // namespace dyncull
