// Depth pyramid against its brute-force oracle: on random and structured depth buffers of
// awkward sizes, the pyramid's farthest depth over a rectangle is never nearer than the
// exact farthest over its pixels (so it never calls a visible surface occluded), is exact
// for rectangles of at most kMaxSpan pixels a side, and every texel covers exactly its pixel block.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

#include "dyncull/scheduler/depth_pyramid.hpp"

namespace dyncull {
namespace {

struct Buffer {
    int width, height;
    std::vector<float> depth;
};

// Random depths in blocks of `block` pixels plus per-pixel noise, some pixels cleared to the
// far plane (0) and some near (1), so minima come from single pixels anywhere.
Buffer makeBuffer(int width, int height, int block, std::mt19937& rng) {
    Buffer b{width, height, std::vector<float>(static_cast<std::size_t>(width) * static_cast<std::size_t>(height))};
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const int bw = (width + block - 1) / block, bh = (height + block - 1) / block;
    std::vector<float> blocks(static_cast<std::size_t>(bw) * static_cast<std::size_t>(bh));
    for (float& v : blocks) v = u(rng);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            float v = blocks[static_cast<std::size_t>(y / block) * static_cast<std::size_t>(bw) + static_cast<std::size_t>(x / block)];
            v = std::clamp(v + 0.05f * (u(rng) - 0.5f), 0.0f, 1.0f);
            const float r = u(rng);
            if (r < 0.002f) v = 0.0f;        // background showing through
            else if (r < 0.004f) v = 1.0f;   // at the near plane
            b.depth[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)] = v;
        }
    return b;
}

ScreenRect randomRect(int width, int height, std::mt19937& rng) {
    // Sizes from one pixel to more than the screen, positions partly off screen.
    std::uniform_int_distribution<int> size(1, std::max(width, height) + 4);
    std::uniform_int_distribution<int> small(1, 3);
    const bool tiny = std::uniform_int_distribution<int>(0, 3)(rng) == 0;
    const int w = tiny ? small(rng) : size(rng), h = tiny ? small(rng) : size(rng);
    const int x0 = std::uniform_int_distribution<int>(-w + 1, width - 1)(rng);
    const int y0 = std::uniform_int_distribution<int>(-h + 1, height - 1)(rng);
    return {x0, y0, x0 + w, y0 + h};
}

TEST(DepthPyramid, NeverNearerThanTheExactFarthestAndExactForSmallRects) {
    std::mt19937 rng(7);
    const int sizes[][2] = {{1, 1}, {1, 7}, {7, 1}, {3, 5}, {64, 64}, {65, 33}, {257, 129}, {640, 360}};
    std::uint64_t tests = 0, exact = 0;
    for (const auto& s : sizes) {
        for (const int block : {1, 4, 16}) {
            const Buffer b = makeBuffer(s[0], s[1], block, rng);
            DepthPyramid p;
            p.build(b.depth, b.width, b.height);
            for (int i = 0; i < 400; ++i) {
                const ScreenRect r = randomRect(b.width, b.height, rng);
                const float truth = farthestInBruteForce(b.depth, b.width, b.height, r);
                const float fast = p.farthestIn(r);
                ASSERT_LE(fast, truth) << s[0] << "x" << s[1] << " rect [" << r.x0 << "," << r.x1 << ")x[" << r.y0
                                       << "," << r.y1 << ")";
                if (r.x1 - r.x0 <= DepthPyramid::kMaxSpan && r.y1 - r.y0 <= DepthPyramid::kMaxSpan) {
                    EXPECT_EQ(fast, truth) << "a rectangle of at most kMaxSpan pixels a side is answered at level 0";
                }
                // A surface just in front of the exact farthest depth is visible somewhere in
                // the rectangle; the pyramid must not call it occluded.
                EXPECT_FALSE(p.occluded(r, truth)) << "at the farthest depth itself";
                EXPECT_FALSE(p.occluded(r, std::nextafter(truth, 2.0f)));
                // A wider span reads a finer level: never nearer than the exact answer either,
                // and exact for rectangles up to that span.
                for (const int span : {2, 16, 64}) {
                    EXPECT_FALSE(p.occluded(r, truth, span)) << "span " << span;
                    if (r.x1 - r.x0 <= span && r.y1 - r.y0 <= span && truth > 0.0f) {
                        EXPECT_TRUE(p.occluded(r, truth * (1.0f - 2.0f * DepthPyramid::kDepthSlack), span))
                            << "exact at level 0 for span " << span;
                    }
                }
                ++tests;
                exact += fast == truth;
            }
        }
    }
    // How often the 2x2-texel answer equals the exact one (not asserted: it depends on the data).
    std::printf("depth pyramid: %llu rectangles, %.1f%% answered exactly\n", static_cast<unsigned long long>(tests),
                100.0 * static_cast<double>(exact) / static_cast<double>(tests));
}

// occluded reads a coarse level first and stops at the first texel in front: its answer
// is still that of every texel at the finest level where the rectangle spans at most
// `span` texels, read in full (the reference below, from the public texels).
// The per-texel test against its pixel-by-pixel oracle, with random planes (up to three,
// steep and shallow, some pointing the bound nearer than the buffer, some behind it):
// never "occluded" where the oracle shows a pixel, whatever the texel budget, and, with a
// budget large enough to reach every pixel, exactly the oracle's answer.
TEST(DepthPyramid, PerTexelTestNeverHidesWhatThePixelOracleShows) {
    std::mt19937 rng(29);
    std::uniform_real_distribution<double> u(0.0, 1.0), slope(-0.01, 0.01);
    const int sizes[][2] = {{1, 1}, {7, 3}, {65, 33}, {640, 360}};
    std::uint64_t hidden = 0, shown = 0, gaveUp = 0;
    for (const auto& s : sizes) {
        const Buffer b = makeBuffer(s[0], s[1], 8, rng);
        DepthPyramid p;
        p.build(b.depth, b.width, b.height);
        for (int i = 0; i < 1500; ++i) {
            const ScreenRect r = randomRect(b.width, b.height, rng);
            DepthPlanes planes;
            planes.count = static_cast<std::uint32_t>(std::uniform_int_distribution<int>(0, 3)(rng));
            const double base = u(rng);
            for (std::uint32_t k = 0; k < planes.count; ++k) {
                const double scale = (i % 3 == 0) ? 10.0 : 1.0;  // some planes steep
                planes.planes[k] = {slope(rng) * scale, slope(rng) * scale, base + 0.3 * (u(rng) - 0.5)};
            }
            // Half the cases with an outline: random half-planes through points near the
            // rectangle (at times empty, at times cutting it to a sliver).
            if (i % 2 == 1) {
                planes.edgeCount = static_cast<std::uint32_t>(std::uniform_int_distribution<int>(1, 8)(rng));
                for (std::uint32_t k = 0; k < planes.edgeCount; ++k) {
                    const double angle = 6.283185307179586 * u(rng);
                    const double px = r.x0 + (r.x1 - r.x0) * (1.4 * u(rng) - 0.2), py = r.y0 + (r.y1 - r.y0) * (1.4 * u(rng) - 0.2);
                    planes.edges[k] = {std::cos(angle), std::sin(angle), std::cos(angle) * px + std::sin(angle) * py};
                }
            }
            const float nearest = static_cast<float>(u(rng));
            const bool truth = occludedPerPixelBruteForce(b.depth, b.width, b.height, r, nearest, planes);
            for (const int budget : {1, 16, 256}) {
                const bool fast = p.occludedPerTexel(r, nearest, planes, budget);
                if (fast) {
                    ASSERT_TRUE(truth) << "budget " << budget << ", case " << i << " of " << s[0] << "x" << s[1];
                }
                gaveUp += truth && !fast;
            }
            ASSERT_EQ(p.occludedPerTexel(r, nearest, planes, 1 << 20), truth) << "case " << i << " of " << s[0] << "x" << s[1];
            (truth ? hidden : shown) += 1;
        }
    }
    // Both answers must have been exercised.
    EXPECT_GT(hidden, 500u);
    EXPECT_GT(shown, 500u);
    std::printf("per-texel test: %llu hidden, %llu shown; a small budget answered visible for a hidden one %llu times\n",
                static_cast<unsigned long long>(hidden), static_cast<unsigned long long>(shown), static_cast<unsigned long long>(gaveUp));
}

// A wall seen at a slant, just behind another parallel to it: its nearest depth over the
// whole rectangle is in front of most of the buffer, so the pyramid test shows it; bounded
// by its plane, it is behind at every pixel.
TEST(DepthPyramid, APlaneHidesASlantedSurfaceTheNearestDepthCannot) {
    const int w = 64, h = 16;
    std::vector<float> depth(static_cast<std::size_t>(w * h));
    DepthPlanes planes;
    planes.count = 1;
    planes.planes[0] = {0.01, 0.0, 0.1};  // 0.1 at the left edge, 0.74 at the right
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) depth[static_cast<std::size_t>(y * w + x)] = float(0.1 + 0.01 * (x + 1.5) + 0.02);
    DepthPyramid p;
    p.build(depth, w, h);
    const ScreenRect all{0, 0, w, h};
    const float nearest = 0.75f;
    EXPECT_FALSE(p.occluded(all, nearest, 64));
    EXPECT_TRUE(p.occludedPerTexel(all, nearest, planes, 1 << 20));
    EXPECT_TRUE(occludedPerPixelBruteForce(depth, w, h, all, nearest, planes));
    // One pixel in front of the plane makes it visible.
    depth[static_cast<std::size_t>(5 * w + 40)] = 0.0f;
    p.build(depth, w, h);
    EXPECT_FALSE(p.occludedPerTexel(all, nearest, planes, 1 << 20));
}

// A box seen corner-on covers a diamond of its rectangle: the rectangle's corners show the
// far background, which hides nothing, and the diamond a near wall. Its outline leaves the
// corners out, and the wall hides it; without the outline it shows.
TEST(DepthPyramid, AnOutlineLeavesOutThePixelsTheVolumeCannotCover) {
    const int w = 32, h = 32;
    std::vector<float> depth(static_cast<std::size_t>(w * h), 0.0f);  // cleared: the far plane
    auto inDiamond = [](double x, double y, double slack) { return std::abs(x - 16.0) + std::abs(y - 16.0) <= 12.0 + slack; };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (inDiamond(x + 0.5, y + 0.5, 1.0)) depth[static_cast<std::size_t>(y * w + x)] = 0.8f;
    DepthPyramid p;
    p.build(depth, w, h);
    DepthPlanes planes;
    // |x - 16| + |y - 16| <= 12 as four half-planes.
    planes.edgeCount = 4;
    planes.edges[0] = {1.0, 1.0, 44.0};
    planes.edges[1] = {-1.0, 1.0, 12.0};
    planes.edges[2] = {-1.0, -1.0, -20.0};
    planes.edges[3] = {1.0, -1.0, 12.0};
    const ScreenRect r{4, 4, 28, 28};
    const float nearest = 0.5f;
    EXPECT_TRUE(p.occludedPerTexel(r, nearest, planes, 1 << 20));
    EXPECT_TRUE(occludedPerPixelBruteForce(depth, w, h, r, nearest, planes));
    DepthPlanes none;
    EXPECT_FALSE(p.occludedPerTexel(r, nearest, none, 1 << 20));
    EXPECT_FALSE(occludedPerPixelBruteForce(depth, w, h, r, nearest, none));
    // A background pixel inside the outline shows the volume.
    depth[static_cast<std::size_t>(16 * w + 16)] = 0.0f;
    p.build(depth, w, h);
    EXPECT_FALSE(p.occludedPerTexel(r, nearest, planes, 1 << 20));
}

TEST(DepthPyramid, ShortCutAnswersAsReadingEveryTexelOfTheSpanLevel) {
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::uint64_t hidden = 0, shown = 0;
    for (const auto& s : {std::pair{640, 360}, std::pair{257, 129}, std::pair{33, 65}}) {
        for (const int block : {2, 8, 32}) {
            const Buffer b = makeBuffer(s.first, s.second, block, rng);
            DepthPyramid p;
            p.build(b.depth, b.width, b.height);
            for (int i = 0; i < 600; ++i) {
                const ScreenRect r = randomRect(b.width, b.height, rng);
                const int x0 = std::max(r.x0, 0), y0 = std::max(r.y0, 0);
                const int x1 = std::min(r.x1, b.width) - 1, y1 = std::min(r.y1, b.height) - 1;
                if (x0 > x1 || y0 > y1) continue;
                const float truth = farthestInBruteForce(b.depth, b.width, b.height, r);
                for (const int span : {2, 4, 16, 32, 64}) {
                    int k = 0;
                    while ((x1 >> k) - (x0 >> k) >= span || (y1 >> k) - (y0 >> k) >= span) ++k;
                    float farthest = 1.0f;
                    for (int ty = y0 >> k; ty <= (y1 >> k); ++ty)
                        for (int tx = x0 >> k; tx <= (x1 >> k); ++tx) farthest = std::min(farthest, p.texel(k, tx, ty));
                    // Depths around the answer's edge, and anywhere.
                    for (const float z : {u(rng), truth, farthest, farthest * (1.0f - 2.0f * DepthPyramid::kDepthSlack),
                                          std::nextafter(farthest - DepthPyramid::kDepthSlack * farthest, 0.0f)}) {
                        const bool expected = z < farthest - DepthPyramid::kDepthSlack * farthest;
                        ASSERT_EQ(p.occluded(r, z, span), expected) << "span " << span << ", depth " << z;
                        ++(expected ? hidden : shown);
                    }
                }
            }
        }
    }
    EXPECT_GT(hidden, 1000u);
    EXPECT_GT(shown, 1000u);
}

// adopt builds the pyramid build does, from the caller's buffer without a copy, and hands
// back a buffer of its own; a pyramid rebuilt at another size is that size's throughout.
TEST(DepthPyramid, AdoptingTheBufferBuildsTheSamePyramid) {
    std::mt19937 rng(19);
    DepthPyramid adopted;
    for (const auto& s : {std::pair{640, 360}, std::pair{1, 1}, std::pair{7, 1}, std::pair{33, 65}, std::pair{640, 360}}) {
        const Buffer b = makeBuffer(s.first, s.second, 4, rng);
        DepthPyramid copied;
        copied.build(b.depth, b.width, b.height);
        std::vector<float> buffer = b.depth;
        adopted.adopt(buffer, b.width, b.height);
        ASSERT_EQ(adopted.levels(), copied.levels());
        for (int k = 0; k < copied.levels(); ++k) {
            const int w = std::max(1, (b.width + (1 << k) - 1) >> k), h = std::max(1, (b.height + (1 << k) - 1) >> k);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) ASSERT_EQ(adopted.texel(k, x, y), copied.texel(k, x, y)) << "level " << k;
        }
    }
}

TEST(DepthPyramid, EveryTexelIsTheFarthestOfExactlyItsPixelBlock) {
    std::mt19937 rng(11);
    for (const auto& s : {std::pair{13, 9}, std::pair{640, 360}, std::pair{1, 33}}) {
        const Buffer b = makeBuffer(s.first, s.second, 3, rng);
        DepthPyramid p;
        p.build(b.depth, b.width, b.height);
        ASSERT_EQ(p.texel(0, 0, 0), b.depth[0]);
        for (int k = 0; k < p.levels(); ++k) {
            const int span = 1 << k;
            for (int y = 0; y * span < b.height; ++y)
                for (int x = 0; x * span < b.width; ++x) {
                    const ScreenRect block{x * span, y * span, (x + 1) * span, (y + 1) * span};
                    ASSERT_EQ(p.texel(k, x, y), farthestInBruteForce(b.depth, b.width, b.height, block))
                        << "level " << k << " texel " << x << "," << y;
                }
        }
        // The top level is one texel: the farthest depth of the whole buffer.
        EXPECT_EQ(p.texel(p.levels() - 1, 0, 0), *std::min_element(b.depth.begin(), b.depth.end()));
    }
}

TEST(DepthPyramid, OccludedOnlyBehindTheSlack) {
    const int w = 40, h = 30;
    std::vector<float> depth(static_cast<std::size_t>(w * h), 0.5f);
    DepthPyramid p;
    p.build(depth, w, h);
    const ScreenRect r{5, 5, 20, 12};
    EXPECT_FALSE(p.occluded(r, 0.5f)) << "a tie is visible";
    EXPECT_FALSE(p.occluded(r, 0.5f * (1.0f - 0.5f * DepthPyramid::kDepthSlack))) << "within the rounding margin";
    EXPECT_TRUE(p.occluded(r, 0.5f * (1.0f - 2.0f * DepthPyramid::kDepthSlack)));
    EXPECT_TRUE(p.occluded(r, 0.1f));
    // One pixel of background (cleared to the far plane) in the rectangle: nothing is hidden.
    depth[static_cast<std::size_t>(8 * w + 17)] = 0.0f;
    p.build(depth, w, h);
    EXPECT_FALSE(p.occluded(r, 0.1f));
    EXPECT_TRUE(p.occluded({0, 0, 3, 3}, 0.1f)) << "away from that pixel the rest still hides";
}

TEST(DepthPyramid, EmptyOrOffscreenRectanglesClaimNothing) {
    std::vector<float> depth(64, 0.9f);
    DepthPyramid p;
    EXPECT_FALSE(p.occluded({0, 0, 4, 4}, 0.1f)) << "before the first build";
    p.build(depth, 8, 8);
    EXPECT_FALSE(p.occluded({3, 3, 3, 5}, 0.1f));    // empty
    EXPECT_FALSE(p.occluded({9, 0, 12, 4}, 0.1f));   // right of the screen
    EXPECT_FALSE(p.occluded({-5, -5, 0, 0}, 0.1f));  // below and left
    EXPECT_TRUE(p.occluded({-5, -5, 1, 1}, 0.1f));   // reaches pixel (0, 0)
    EXPECT_EQ(p.farthestIn({9, 9, 10, 10}), 1.0f);
}

}  // namespace
}  // namespace dyncull
