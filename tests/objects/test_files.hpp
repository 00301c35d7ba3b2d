// Test helpers: a per-test temporary directory and small file writers.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "dyncull/objects/error.hpp"
#include "dyncull/objects/file_extension.hpp"
#include "dyncull/objects/scene.hpp"

namespace dyncull::test {

/// Unique directory under the system temp dir, removed with its files on destruction.
class TempDir {
public:
    TempDir() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::random_device rd;
        path_ = std::filesystem::temp_directory_path() /
                ("dyncull_" + std::string(info ? info->name() : "test") + "_" + std::to_string(rd()));
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    std::filesystem::path file(const std::string& name) const { return path_ / name; }
    std::filesystem::path write(const std::string& name, const std::string& bytes) const {
        const auto p = file(name);
        std::ofstream(p, std::ios::binary) << bytes;
        exportFuzzSeed(name, bytes);
        return p;
    }

    /// With $DYNCULL_FUZZ_SEEDS set (scripts/fuzz.sh), every file a test writes is also
    /// copied to <seeds>/<extension>/<test>_<name>: the loader tests' good and broken
    /// files are the fuzzers' seed corpora, so no binary seeds are committed.
    static void exportFuzzSeed(const std::string& name, const std::string& bytes) {
        const char* seeds = std::getenv("DYNCULL_FUZZ_SEEDS");
        if (!seeds || !*seeds) return;
        const std::string ext = lowercaseExtension(name);
        if (ext.size() < 2) return;
        const auto dir = std::filesystem::path(seeds) / ext.substr(1);
        std::filesystem::create_directories(dir);
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        const std::string test = info ? std::string(info->test_suite_name()) + "." + info->name() : "test";
        std::ofstream(dir / (test + "_" + name), std::ios::binary) << bytes;
    }

private:
    std::filesystem::path path_;
};

/// Appends the bytes of `v` in little- or big-endian order.
template <class T>
void put(std::string& out, T v, bool bigEndian) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (bigEndian)
        for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

/// A loader's error: one line that starts with the file's path and mentions `what`.
inline void expectError(const Expected<Scene>& r, const std::filesystem::path& path, const std::string& what) {
    ASSERT_FALSE(r.ok()) << "expected an error containing '" << what << "'";
    const std::string& msg = r.error().message;
    EXPECT_EQ(msg.rfind(path.string(), 0), 0u) << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << "expected '" << what << "' in: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}

/// Standard base64 with padding (glTF data URIs).
inline std::string base64(const std::string& in) {
    static const char* tbl = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    std::size_t i = 0;
    for (; i + 2 < in.size(); i += 3) {
        const std::uint32_t v = (std::uint8_t(in[i]) << 16) | (std::uint8_t(in[i + 1]) << 8) | std::uint8_t(in[i + 2]);
        for (int k = 3; k >= 0; --k) out += tbl[(v >> (6 * k)) & 63];
    }
    if (i + 1 == in.size()) {
        const std::uint32_t v = std::uint8_t(in[i]) << 16;
        out += tbl[(v >> 18) & 63];
        out += tbl[(v >> 12) & 63];
        out += "==";
    } else if (i + 2 == in.size()) {
        const std::uint32_t v = (std::uint8_t(in[i]) << 16) | (std::uint8_t(in[i + 1]) << 8);
        out += tbl[(v >> 18) & 63];
        out += tbl[(v >> 12) & 63];
        out += tbl[(v >> 6) & 63];
        out += '=';
    }
    return out;
}

}  // namespace dyncull::test
