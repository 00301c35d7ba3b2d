#include <gtest/gtest.h>

#include "dyncull/scheduler/occupancy_map.hpp"

using namespace dyncull;

TEST(OccupancyMap, MarkAndTestRectangles) {
    OccupancyMap m;
    m.reset(200, 100, 16);  // 13 x 7 tiles
    EXPECT_EQ(m.tilesX(), 13);
    EXPECT_EQ(m.tilesY(), 7);
    const ScreenRect r{20, 20, 40, 40};  // tiles 1..2 in x and y
    EXPECT_FALSE(m.anySet(r));
    EXPECT_FALSE(m.allSet(r));
    m.mark(r);
    EXPECT_TRUE(m.anySet(r));
    EXPECT_TRUE(m.allSet(r));
    EXPECT_TRUE(m.tile(1, 1));
    EXPECT_TRUE(m.tile(2, 2));
    EXPECT_FALSE(m.tile(3, 2));
    EXPECT_FALSE(m.tile(0, 0));
    // A rectangle reaching one more tile is not fully covered but overlaps.
    EXPECT_FALSE(m.allSet({20, 20, 60, 40}));
    EXPECT_TRUE(m.anySet({20, 20, 60, 40}));
    m.unmark(r);
    EXPECT_FALSE(m.anySet(r));
}

TEST(OccupancyMap, WideMapsCrossWordBoundaries) {
    OccupancyMap m;
    m.reset(4000, 8, 4);  // 1000 tiles per row: 16 words
    const ScreenRect r{250, 0, 3000, 4};
    m.mark(r);
    EXPECT_TRUE(m.allSet(r));
    EXPECT_FALSE(m.anySet({0, 0, 248, 8}));
    EXPECT_FALSE(m.anySet({3004, 0, 4000, 8}));
    EXPECT_TRUE(m.tile(62, 0));
    EXPECT_TRUE(m.tile(64, 0));
    EXPECT_TRUE(m.tile(749, 0));
    EXPECT_FALSE(m.tile(750, 0));
}

TEST(OccupancyMap, EmptyAndOutOfRangeRectangles) {
    OccupancyMap m;
    m.reset(64, 64, 16);
    m.mark({});  // empty: no effect
    EXPECT_FALSE(m.anySet({0, 0, 64, 64}));
    m.mark({-50, -50, 1000, 1000});  // clamped to the viewport
    EXPECT_TRUE(m.allSet({0, 0, 64, 64}));
    // An empty rectangle touches no tile: "all set" is vacuously true, "any" false.
    EXPECT_TRUE(m.allSet({}));
    EXPECT_FALSE(m.anySet({}));
}
