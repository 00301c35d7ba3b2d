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

// The centres of pixels [x0, x1] x [y0, y1] grown by kSnapPixels, where a rasteriser's
// snapping may move a surface point: the rectangle the planes and the outline are judged over.
struct GrownCentres {
    double lx, ly, hx, hy;
};
GrownCentres grownCentres(int x0, int y0, int x1, int y1) {
    constexpr double s = DepthPyramid::kSnapPixels;
    return {x0 + 0.5 - s, y0 + 0.5 - s, x1 + 0.5 + s, y1 + 0.5 + s};
}

// The greatest depth the least of `p`'s planes takes over `g` (an affine function peaks at
// a corner), and at most `nearest`.
double boundOver(const DepthPlanes& p, float nearest, const GrownCentres& g) {
    double bound = nearest;
    for (std::uint32_t i = 0; i < p.count; ++i) {
        const auto& [a, b, c] = p.planes[i];
        bound = std::min(bound, c + a * (a > 0.0 ? g.hx : g.lx) + b * (b > 0.0 ? g.hy : g.ly));
    }
    return bound;
}

// Whether all of `g` lies outside one of `p`'s outline edges (an affine function is least
// at a corner); the margin, 2^-30 of the terms, is far above the rounding of a sum of three
// doubles.
bool outsideOutline(const DepthPlanes& p, const GrownCentres& g) {
    for (std::uint32_t i = 0; i < p.edgeCount; ++i) {
        const auto& [a, b, c] = p.edges[i];
        const double ax = a * (a > 0.0 ? g.lx : g.hx), by = b * (b > 0.0 ? g.ly : g.hy);
        if (ax + by > c + 0x1p-30 * (std::abs(ax) + std::abs(by) + std::abs(c))) return true;
    }
    return false;
}

// Reversed Z: behind means smaller, by more than the slack (as hiddenAt compares).
bool behind(double bound, float t) { return bound < double(t - DepthPyramid::kDepthSlack * t); }

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

bool DepthPyramid::occludedPerTexel(const ScreenRect& rect, float nearestDepth, const DepthPlanes& planes, int maxTexels) const {
    int x0, y0, x1, y1;
    if (levels_.empty() || !clampRect(rect, width_, height_, x0, y0, x1, y1)) return false;  // no evidence
    assert(maxTexels >= 1);
    // Depth first from the level where the rectangle spans at most 2 texels a side: each
    // texel popped pushes at most four, so the stack holds at most 4 + 3 per level.
    struct Texel {
        int level, x, y;
    };
    std::array<Texel, 4 + 3 * 32> stack;
    std::size_t top = 0;
    const int start = levelSpanning(x0, y0, x1, y1, 2);
    for (int ty = y0 >> start; ty <= (y1 >> start); ++ty)
        for (int tx = x0 >> start; tx <= (x1 >> start); ++tx) stack[top++] = {start, tx, ty};
    int visited = 0;
    while (top > 0) {
        const Texel t = stack[--top];
        // The texel's pixels within the rectangle.
        const int px0 = std::max(x0, t.x << t.level), px1 = std::min(x1, ((t.x + 1) << t.level) - 1);
        const int py0 = std::max(y0, t.y << t.level), py1 = std::min(y1, ((t.y + 1) << t.level) - 1);
        const Level& l = levels_[static_cast<std::size_t>(t.level)];
        const float farthest =
            levelData(static_cast<std::size_t>(t.level))[static_cast<std::size_t>(t.y) * static_cast<std::size_t>(l.width) + static_cast<std::size_t>(t.x)];
        const GrownCentres g = grownCentres(px0, py0, px1, py1);
        if (behind(boundOver(planes, nearestDepth, g), farthest) || outsideOutline(planes, g)) continue;
        if (t.level == 0 || ++visited >= maxTexels) return false;
        const int k = t.level - 1;
        for (int cy = py0 >> k; cy <= (py1 >> k); ++cy)
            for (int cx = px0 >> k; cx <= (px1 >> k); ++cx) {
                assert(top < stack.size());
                stack[top++] = {k, cx, cy};
            }
    }
    return true;
}

bool occludedPerPixelBruteForce(std::span<const float> depth, int width, int height, const ScreenRect& rect, float nearestDepth,
                                const DepthPlanes& planes) {
    int x0, y0, x1, y1;
    if (!clampRect(rect, width, height, x0, y0, x1, y1)) return false;
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            const float d = depth[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)];
            const GrownCentres g = grownCentres(x, y, x, y);
            if (!behind(boundOver(planes, nearestDepth, g), d) && !outsideOutline(planes, g)) return false;
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
