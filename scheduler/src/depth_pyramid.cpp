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
    base_.assign(depth.begin(), depth.end());
    buildLevels();
}

void DepthPyramid::adopt(std::vector<float>& depth, int width, int height) {
    assert(width >= 1 && height >= 1);
    assert(depth.size() == static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
    width_ = width;
    height_ = height;
    base_.swap(depth);
    buildLevels();
}

void DepthPyramid::buildLevels() {
    levels_.clear();
    levels_.push_back({0, width_, height_});
    std::size_t total = 0;
    for (int w = width_, h = height_; w > 1 || h > 1;) {
        w = (w + 1) / 2;
        h = (h + 1) / 2;
        levels_.push_back({total, w, h});
        total += static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    }
    texels_.resize(total);
    for (std::size_t k = 1; k < levels_.size(); ++k) {
        const Level& src = levels_[k - 1];
        const Level& dst = levels_[k];
        const float* in = levelData(k - 1);
        float* out = texels_.data() + dst.offset;
        const std::size_t sw = static_cast<std::size_t>(src.width), dw = static_cast<std::size_t>(dst.width);
        const std::size_t pairs = sw / 2;  // texels with both source columns; an odd last one follows
        for (int y = 0; y < dst.height; ++y) {
            // An odd last row or column has no partner: it is its own farthest.
            const float* a = in + static_cast<std::size_t>(2 * y) * sw;
            const float* b = in + static_cast<std::size_t>(std::min(2 * y + 1, src.height - 1)) * sw;
            float* o = out + static_cast<std::size_t>(y) * dw;
            for (std::size_t x = 0; x < pairs; ++x) o[x] = std::min(std::min(a[2 * x], a[2 * x + 1]), std::min(b[2 * x], b[2 * x + 1]));
            if (pairs < dw) o[pairs] = std::min(a[2 * pairs], b[2 * pairs]);
        }
    }
}

float DepthPyramid::texel(int level, int x, int y) const {
    assert(level >= 0 && level < levels());
    const Level& l = levels_[static_cast<std::size_t>(level)];
    assert(x >= 0 && x < l.width && y >= 0 && y < l.height);
    return levelData(static_cast<std::size_t>(level))[static_cast<std::size_t>(y) * static_cast<std::size_t>(l.width) + static_cast<std::size_t>(x)];
}

float DepthPyramid::farthestIn(const ScreenRect& rect) const {
    int x0, y0, x1, y1;
    if (levels_.empty() || !clampRect(rect, width_, height_, x0, y0, x1, y1)) return 1.0f;
    return farthestInPixels(x0, y0, x1, y1);
}

float DepthPyramid::farthestInPixels(int x0, int y0, int x1, int y1, int maxSpan) const {
    // Every texel the rectangle touches at that level is read.
    assert(maxSpan >= 2);
    const int k = levelSpanning(x0, y0, x1, y1, maxSpan);
    assert(k < levels());
    const Level& l = levels_[static_cast<std::size_t>(k)];
    float farthest = 1.0f;
    for (int ty = y0 >> k; ty <= (y1 >> k); ++ty) {
        const float* row = levelData(static_cast<std::size_t>(k)) + static_cast<std::size_t>(ty) * static_cast<std::size_t>(l.width);
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
    const int fine = levelSpanning(x0, y0, x1, y1, maxSpan);
    const int coarse = levelSpanning(x0, y0, x1, y1, 2, fine);
    if (coarse > fine && hiddenAt(coarse, x0, y0, x1, y1, nearestDepth)) return true;
    return hiddenAt(fine, x0, y0, x1, y1, nearestDepth);
}

bool DepthPyramid::hiddenAt(int level, int x0, int y0, int x1, int y1, float nearestDepth) const {
    assert(level < levels());
    const Level& l = levels_[static_cast<std::size_t>(level)];
    const float* data = levelData(static_cast<std::size_t>(level));
    for (int ty = y0 >> level; ty <= (y1 >> level); ++ty) {
        const float* row = data + static_cast<std::size_t>(ty) * static_cast<std::size_t>(l.width);
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
