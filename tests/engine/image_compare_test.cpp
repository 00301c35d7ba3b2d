// Exact image comparison: percentages and the largest 4-connected wrong region.
#include <gtest/gtest.h>

#include "dyncull/measure/image_compare.hpp"

namespace dyncull {
namespace {

Image solid(int w, int h, std::uint8_t v) {
    Image img;
    img.width = w;
    img.height = h;
    img.rgba.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4, v);
    return img;
}

void setPixel(Image& img, int x, int y, glm::u8vec4 c) {
    const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x)) * 4;
    img.rgba[i] = c.r;
    img.rgba[i + 1] = c.g;
    img.rgba[i + 2] = c.b;
    img.rgba[i + 3] = c.a;
}

TEST(ImageCompare, IdenticalImagesDifferNowhere) {
    const Image a = solid(40, 30, 77);
    auto d = compareImages(a, a);
    ASSERT_TRUE(d.ok());
    EXPECT_EQ(d->totalPixels, 1200u);
    EXPECT_EQ(d->differingPixels, 0u);
    EXPECT_EQ(d->percentDiffering, 0.0);
    EXPECT_EQ(d->largestRegion, 0u);
}

TEST(ImageCompare, KnownBlobGivesPercentAndRegion) {
    const Image a = solid(100, 50, 10);
    Image b = a;
    for (int y = 5; y < 15; ++y)  // a 10 x 10 blob
        for (int x = 20; x < 30; ++x) setPixel(b, x, y, {200, 10, 10, 10});
    // Three single pixels touching only diagonally: three regions of one pixel each.
    setPixel(b, 60, 40, {10, 10, 10, 11});  // alpha alone differs: still wrong
    setPixel(b, 61, 41, {11, 10, 10, 10});
    setPixel(b, 62, 42, {10, 10, 11, 10});
    std::vector<std::uint8_t> mask;
    auto d = compareImages(a, b, &mask);
    ASSERT_TRUE(d.ok());
    EXPECT_EQ(d->differingPixels, 103u);
    EXPECT_DOUBLE_EQ(d->percentDiffering, 100.0 * 103.0 / 5000.0);
    EXPECT_EQ(d->largestRegion, 100u);
    ASSERT_EQ(mask.size(), 5000u);
    EXPECT_EQ(mask[5 * 100 + 20], 1);
    EXPECT_EQ(mask[4 * 100 + 20], 0);
}

TEST(ImageCompare, RegionsJoinThroughEdgesOnly) {
    // An L of 5 pixels and a separate bar of 3: 4-connected sizes 5 and 3.
    std::vector<std::uint8_t> m(8 * 4, 0);
    for (int i : {0, 8, 16, 17, 18}) m[static_cast<std::size_t>(i)] = 1;
    for (int i : {5, 6, 7}) m[static_cast<std::size_t>(i)] = 1;
    EXPECT_EQ(largestConnectedRegion(m, 8, 4), 5u);
    // A region wrapping the right edge must not join the next row's left pixel.
    std::vector<std::uint8_t> wrap(4 * 2, 0);
    wrap[3] = 1;
    wrap[4] = 1;
    EXPECT_EQ(largestConnectedRegion(wrap, 4, 2), 1u);
    // A whole wrong frame is one region (iterative fill: no deep recursion).
    EXPECT_EQ(largestConnectedRegion(std::vector<std::uint8_t>(640 * 360, 1), 640, 360), 640u * 360u);
}

TEST(ImageCompare, SizeMismatchIsAnError) {
    auto d = compareImages(solid(4, 4, 0), solid(4, 5, 0));
    ASSERT_FALSE(d.ok());
    EXPECT_NE(d.error().message.find("4x4 vs 4x5"), std::string::npos);
    Image broken = solid(4, 4, 0);
    broken.rgba.pop_back();
    EXPECT_FALSE(compareImages(broken, solid(4, 4, 0)).ok());
    auto empty = compareImages(Image{}, Image{});
    ASSERT_TRUE(empty.ok());
    EXPECT_EQ(empty->percentDiffering, 0.0);
}

}  // namespace
}  // namespace dyncull
