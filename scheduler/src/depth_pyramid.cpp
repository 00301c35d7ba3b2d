// Farthest-depth pyramid: each level halves the previous one (rounding up), a texel taking
// the minimum (farthest, reversed Z) of the up-to-2x2 texels below it that exist; a
// rectangle is answered at the finest level where it spans at most kMaxSpan texels a side.
#include "dyncull/scheduler/depth_pyramid.hpp"

#include <algorithm>
#include <cassert>

namespace dyncull {

namespace {

// The rectangle clamped to the screen, inclusive pixel bounds; false if nothing is left.
bool clampRect(const ScreenRect& rect, int width, int height, int& x0, int& y0, int& x1, int& y1) {
    x0 = std::max(rect.x0, 0);
    y0 = std::max(rect.y0, 0);
    x1 = std::min(rect.x1, width) - 1;
    y1 = std::min(rect.y1, height) - 1;
    return x0 <= x1 && y0 <= y1;
}

}  // namespace

void DepthPyramid::build(std::span<const float> depth, int width, int height) {
    assert(width >= 1 && height >= 1);
    assert(depth.size() == static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
    width_ = width;
    height_ = height;
    levels_.clear();
    std::size_t total = 0;
    for (int w = width, h = height;; w = (w + 1) / 2, h = (h + 1) / 2) {
        levels_.push_back({total, w, h});
        total += static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
        if (w == 1 && h == 1) break;
    }
    texels_.resize(total);
    std::copy(depth.begin(), depth.end(), texels_.begin());
    for (std::size_t k = 1; k < levels_.size(); ++k) {
        const Level& src = levels_[k - 1];
        const Level& dst = levels_[k];
        const float* in = texels_.data() + src.offset;
        float* out = texels_.data() + dst.offset;
        for (int y = 0; y < dst.height; ++y) {
            // An odd last row or column has no partner: it is its own farthest.
            const int ya = 2 * y, yb = std::min(2 * y + 1, src.height - 1);
            for (int x = 0; x < dst.width; ++x) {
                const int xa = 2 * x, xb = std::min(2 * x + 1, src.width - 1);
                const std::size_t ra = static_cast<std::size_t>(ya) * static_cast<std::size_t>(src.width);
                const std::size_t rb = static_cast<std::size_t>(yb) * static_cast<std::size_t>(src.width);
                out[static_cast<std::size_t>(y) * static_cast<std::size_t>(dst.width) + static_cast<std::size_t>(x)] =
                    std::min({in[ra + static_cast<std::size_t>(xa)], in[ra + static_cast<std::size_t>(xb)],
                              in[rb + static_cast<std::size_t>(xa)], in[rb + static_cast<std::size_t>(xb)]});
            }
        }
    }
}

float DepthPyramid::texel(int level, int x, int y) const {
    assert(level >= 0 && level < levels());
    const Level& l = levels_[static_cast<std::size_t>(level)];
    assert(x >= 0 && x < l.width && y >= 0 && y < l.height);
    return texels_[l.offset + static_cast<std::size_t>(y) * static_cast<std::size_t>(l.width) + static_cast<std::size_t>(x)];
}

float DepthPyramid::farthestIn(const ScreenRect& rect) const {
    int x0, y0, x1, y1;
    if (levels_.empty() || !clampRect(rect, width_, height_, x0, y0, x1, y1)) return 1.0f;
    return farthestInPixels(x0, y0, x1, y1);
}

float DepthPyramid::farthestInPixels(int x0, int y0, int x1, int y1, int maxSpan) const {
    // The finest level where the rectangle spans at most maxSpan texels on both axes (at
    // the top level, 1x1, it always does); every texel it touches there is read.
    assert(maxSpan >= 2);
    int k = 0;
    while ((x1 >> k) - (x0 >> k) >= maxSpan || (y1 >> k) - (y0 >> k) >= maxSpan) ++k;
    assert(k < levels());
    const Level& l = levels_[static_cast<std::size_t>(k)];
    float farthest = 1.0f;
    for (int ty = y0 >> k; ty <= (y1 >> k); ++ty) {
        const float* row = texels_.data() + l.offset + static_cast<std::size_t>(ty) * static_cast<std::size_t>(l.width);
        for (int tx = x0 >> k; tx <= (x1 >> k); ++tx) farthest = std::min(farthest, row[tx]);
    }
    return farthest;
}

bool DepthPyramid::occluded(const ScreenRect& rect, float nearestDepth, int maxSpan) const {
    int x0, y0, x1, y1;
    if (levels_.empty() || !clampRect(rect, width_, height_, x0, y0, x1, y1)) return false;  // no evidence
    assert(maxSpan >= 2);
    // The answer of farthestInPixels at maxSpan, reading fewer texels: hidden behind a
    // coarser level is hidden behind every finer one (each of its texels is the farthest
    // of those below it), so a look at the level where the rectangle spans 2 texels
    // settles most hidden ones; at the finest level the first texel in front settles a
    // visible one.
    int fine = 0;
    while ((x1 >> fine) - (x0 >> fine) >= maxSpan || (y1 >> fine) - (y0 >> fine) >= maxSpan) ++fine;
    int coarse = fine;
    while ((x1 >> coarse) - (x0 >> coarse) >= 2 || (y1 >> coarse) - (y0 >> coarse) >= 2) ++coarse;
    if (coarse > fine && hiddenAt(coarse, x0, y0, x1, y1, nearestDepth)) return true;
    return hiddenAt(fine, x0, y0, x1, y1, nearestDepth);
}

bool DepthPyramid::hiddenAt(int level, int x0, int y0, int x1, int y1, float nearestDepth) const {
    assert(level < levels());
    const Level& l = levels_[static_cast<std::size_t>(level)];
    for (int ty = y0 >> level; ty <= (y1 >> level); ++ty) {
        const float* row = texels_.data() + l.offset + static_cast<std::size_t>(ty) * static_cast<std::size_t>(l.width);
        for (int tx = x0 >> level; tx <= (x1 >> level); ++tx) {
            // Reversed Z: behind means smaller. Equal or within the slack counts as visible.
            // (kDepthSlack is a power of two, so t - kDepthSlack * t rounds monotonically in
            // t: behind every texel is behind their farthest.)
            const float t = row[tx];
            if (!(nearestDepth < t - kDepthSlack * t)) return false;
        }
    }
    return true;
}

float farthestInBruteForce(std::span<const float> depth, int width, int height, const ScreenRect& rect) {
    int x0, y0, x1, y1;
    if (!clampRect(rect, width, height, x0, y0, x1, y1)) return 1.0f;
    float farthest = 1.0f;
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
            farthest = std::min(farthest, depth[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                                                static_cast<std::size_t>(x)]);
    return farthest;
}

}  // namespace dyncull
