// The budget oracle's choice (chooseBudgetDrops) against every subset of small item sets.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "dyncull/measure/budget_oracle.hpp"

namespace dyncull {
namespace {

TEST(BudgetOracle, LeavesOutTheMostTrianglesPerPixelFirst) {
    // Ratios 10, 2, 5 triangles per pixel; a budget of 12 pixels fits items 0 and 2 (10 + 2 pixels).
    const std::vector<std::uint32_t> triangles{100, 20, 10}, pixels{10, 10, 2};
    const BudgetDrops d = chooseBudgetDrops(triangles, pixels, 12);
    EXPECT_EQ(d.dropped, (std::vector<std::uint8_t>{1, 0, 1}));
    EXPECT_EQ(d.pixels, 12u);
    EXPECT_EQ(d.triangles, 110u);
    EXPECT_DOUBLE_EQ(d.triangleBound, 110.0);
}

TEST(BudgetOracle, GoesOnWithSmallerItemsWhenOneDoesNotFit) {
    const std::vector<std::uint32_t> triangles{90, 40, 3}, pixels{9, 10, 1};  // ratios 10, 4, 3
    const BudgetDrops d = chooseBudgetDrops(triangles, pixels, 12);
    EXPECT_EQ(d.dropped, (std::vector<std::uint8_t>{1, 0, 1}));
    EXPECT_EQ(d.pixels, 10u);
    // The fractional optimum: item 0 whole, then 3 of item 1's 10 pixels.
    EXPECT_DOUBLE_EQ(d.triangleBound, 90.0 + 40.0 * 3.0 / 10.0);
}

TEST(BudgetOracle, NoBudgetLeavesNothingOut) {
    const std::vector<std::uint32_t> triangles{5, 7}, pixels{1, 1};
    const BudgetDrops d = chooseBudgetDrops(triangles, pixels, 0);
    EXPECT_EQ(d.dropped, (std::vector<std::uint8_t>{0, 0}));
    EXPECT_EQ(d.triangles, 0u);
    EXPECT_DOUBLE_EQ(d.triangleBound, 0.0);
    EXPECT_TRUE(chooseBudgetDrops({}, {}, 100).dropped.empty());
}

TEST(BudgetOracle, WithinTheBudgetAndTheBoundOfEverySubset) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 300; ++trial) {
        const int n = 1 + static_cast<int>(rng() % 10);
        std::vector<std::uint32_t> triangles(n), pixels(n);
        for (int i = 0; i < n; ++i) {
            triangles[i] = 1 + rng() % 64;
            pixels[i] = 1 + rng() % 40;
        }
        const std::uint64_t budget = rng() % 120;
        const BudgetDrops d = chooseBudgetDrops(triangles, pixels, budget);
        std::uint64_t best = 0, pixelSum = 0, triangleSum = 0;
        for (int i = 0; i < n; ++i)
            if (d.dropped[i]) pixelSum += pixels[i], triangleSum += triangles[i];
        for (std::uint32_t mask = 0; mask < (1u << n); ++mask) {  // the reference: every subset
            std::uint64_t p = 0, t = 0;
            for (int i = 0; i < n; ++i)
                if (mask >> i & 1u) p += pixels[i], t += triangles[i];
            if (p <= budget) best = std::max(best, t);
        }
        EXPECT_EQ(d.pixels, pixelSum);
        EXPECT_EQ(d.triangles, triangleSum);
        EXPECT_LE(d.pixels, budget);
        EXPECT_LE(d.triangles, best);
        EXPECT_GE(d.triangleBound + 1e-9, static_cast<double>(best)) << "trial " << trial;
        EXPECT_LE(d.triangleBound, static_cast<double>(d.triangles) + 64.0 + 1e-9);
    }
}

}  // namespace
}  // namespace dyncull
