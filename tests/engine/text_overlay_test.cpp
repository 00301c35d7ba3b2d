// Built-in bitmap font: table sanity, measuring, and the exact pixels a glyph lights.
#include <gtest/gtest.h>

#include "dyncull/viewer/text_overlay.hpp"
#include "gl_test_util.hpp"

namespace dyncull {
namespace {

TEST(TextOverlayFont, EveryPrintableGlyphExceptSpaceHasPixelsWithinFiveColumns) {
    for (int c = 33; c <= 126; ++c) {
        int lit = 0;
        for (int row = 0; row < kGlyphHeight; ++row) {
            EXPECT_EQ(glyphRow(static_cast<char>(c), row) & ~0x1F, 0) << "char " << c;
            lit += glyphRow(static_cast<char>(c), row) != 0;
        }
        EXPECT_GT(lit, 0) << "char " << static_cast<char>(c);
    }
    for (int row = 0; row < kGlyphHeight; ++row) EXPECT_EQ(glyphRow(' ', row), 0);
    // Out-of-range characters and rows are safe.
    EXPECT_EQ(glyphRow('\x01', 0), glyphRow('?', 0));
    EXPECT_EQ(glyphRow('A', 7), 0);
    EXPECT_EQ(glyphRow('A', -1), 0);
}

TEST(TextOverlayFont, MeasureCountsColumnsAndLines) {
    EXPECT_EQ(TextOverlay::measure("", 2), glm::ivec2(0, 0));
    EXPECT_EQ(TextOverlay::measure("A", 1), glm::ivec2(5, 7));
    EXPECT_EQ(TextOverlay::measure("AB", 2), glm::ivec2(22, 14));
    EXPECT_EQ(TextOverlay::measure("ABC\nD", 1), glm::ivec2(17, 16));
}

TEST(TextOverlay, GlyphPixelsMatchTheTable) {
    auto ctx = test::headless(64, 48);
    ASSERT_TRUE(ctx);
    {
        auto r = Renderer::create(*ctx);
        ASSERT_TRUE(r.ok()) << r.error().message;
        TextOverlay text;
        ASSERT_TRUE(text.valid()) << text.log();
        ctx->clearFramebuffer(Renderer::kClearColour);
        (*r)->beginFrame(test::cameraOnZ());
        const int scale = 3;
        const glm::ivec2 at{7, 5};
        text.addText(at, "R", {1, 1, 0, 1}, scale);
        text.flush(ctx->size());
        (*r)->endFrame();
        const Image img = (*r)->readPixels();
        int checked = 0;
        for (int row = 0; row < kGlyphHeight; ++row) {
            for (int col = 0; col < kGlyphWidth; ++col) {
                const bool on = glyphRow('R', row) & (0x10 >> col);
                // Centre of the font pixel's scale x scale block.
                const glm::u8vec4 p = img.at(at.x + col * scale + 1, at.y + row * scale + 1);
                if (on) {
                    EXPECT_GT(p.r, 240) << "col " << col << " row " << row;
                    EXPECT_GT(p.g, 240);
                    EXPECT_LT(p.b, 20);
                } else {
                    EXPECT_TRUE(test::isClear(p)) << "col " << col << " row " << row;
                }
                ++checked;
            }
        }
        EXPECT_EQ(checked, 35);
        // Nothing outside the glyph's cell.
        EXPECT_TRUE(test::isClear(img.at(at.x - 1, at.y)));
        EXPECT_TRUE(test::isClear(img.at(at.x + kGlyphWidth * scale, at.y + 3)));
        EXPECT_TRUE(test::isClear(img.at(at.x, at.y + kGlyphHeight * scale)));
    }
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

TEST(TextOverlay, RectsBlendAndTextDrawsOverThem) {
    auto ctx = test::headless(64, 48);
    ASSERT_TRUE(ctx);
    {
        auto r = Renderer::create(*ctx);
        ASSERT_TRUE(r.ok()) << r.error().message;
        TextOverlay text;
        ctx->clearFramebuffer(Renderer::kClearColour);
        (*r)->beginFrame(test::cameraOnZ());
        text.addRect({0, 0}, {40, 20}, {1, 0, 0, 0.5f});
        text.addText({2, 2}, "|", {0, 1, 0, 1}, 2);  // '|' lights column 2 of every row
        text.flush(ctx->size());
        (*r)->endFrame();
        const Image img = (*r)->readPixels();
        const glm::u8vec4 panel = img.at(30, 10);
        EXPECT_NEAR(panel.r, 0.5 * 255 + 0.5 * Renderer::kClearColour.r * 255, 3.0);
        const glm::u8vec4 bar = img.at(2 + 2 * 2 + 1, 2 + 5);
        EXPECT_GT(bar.g, 240);
        EXPECT_LT(bar.r, 10);
        EXPECT_TRUE(test::isClear(img.at(50, 30)));
    }
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

}  // namespace
}  // namespace dyncull
