#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "dyncull/measure/png_writer.hpp"
#include "dyncull/engine/image.hpp"

namespace dyncull {
namespace {

std::uint32_t bigEndian(const unsigned char* p) {
    return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

TEST(PngWriter, WritesHeaderWithSize) {
    const auto dir = std::filesystem::temp_directory_path() / ("dyncull_png_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    Image img;
    img.width = 7;
    img.height = 5;
    img.rgba.assign(7 * 5 * 4, 200);
    const auto path = dir / "t.png";
    ASSERT_TRUE(writePng(img, path).ok());
    std::ifstream in(path, std::ios::binary);
    unsigned char head[24] = {};
    in.read(reinterpret_cast<char*>(head), sizeof head);
    ASSERT_EQ(in.gcount(), 24);
    const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    EXPECT_EQ(std::memcmp(head, sig, 8), 0);
    EXPECT_EQ(std::memcmp(head + 12, "IHDR", 4), 0);
    EXPECT_EQ(bigEndian(head + 16), 7u);
    EXPECT_EQ(bigEndian(head + 20), 5u);
    std::filesystem::remove_all(dir);
}

TEST(PngWriter, MissingDirectoryIsAnError) {
    Image img;
    img.width = img.height = 1;
    img.rgba.assign(4, 0);
    const auto path = std::filesystem::temp_directory_path() / "dyncull_no_such_dir_xyz" / "a.png";
    const Status s = writePng(img, path);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("a.png"), std::string::npos);
}

TEST(PngWriter, MismatchedBufferIsAnError) {
    Image img;
    img.width = 4;
    img.height = 4;
    img.rgba.assign(10, 0);
    EXPECT_FALSE(writePng(img, std::filesystem::temp_directory_path() / "dyncull_bad.png").ok());
}

}  // namespace
}  // namespace dyncull
