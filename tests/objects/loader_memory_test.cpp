// Issue 19: a loader's memory must follow the data it has read and checked, not counts
// claimed by a header. Measured as peak operator-new bytes (alloc_peak.hpp), which is
// deterministic; the file's own bytes (read whole) are the baseline.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "dyncull/loaders/loaders.hpp"
#include "objects/alloc_peak.hpp"
#include "objects/test_files.hpp"

namespace dyncull {
namespace {

using test::PeakAllocation;
using test::TempDir;

struct Measured {
    bool ok = false;
    std::string message;
    std::size_t peak = 0;
};

template <class Load>
Measured measure(const Load& load, const std::filesystem::path& path) {
    Measured m;
    PeakAllocation scope;
    {
        auto r = load(path);
        m.ok = r.ok();
        if (!m.ok) m.message = r.error().message;
    }
    m.peak = scope.peakBytes();
    return m;
}

constexpr std::size_t kSlack = 256 * 1024;  // messages, small vectors, the path

TEST(LoaderMemory, CounterSeesAllocations) {
    PeakAllocation scope;
    { std::vector<char> v(10 << 20); v[5] = 1; }
    EXPECT_GE(scope.peakBytes(), std::size_t(10 << 20));
}

TEST(LoaderMemory, AsciiPlyOfBlankLines) {
    // Header counts the file could hold (2 bytes per value), body only blank lines:
    // sizing the arrays from the header would allocate about 4.5x the file before any check.
    const std::string body(4 << 20, '\n');
    const std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 300000\nproperty float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        "element face 1000000\nproperty list uchar int vertex_indices\nend_header\n" + body;
    TempDir dir;
    const auto path = dir.write("blank.ply", ply);
    const Measured m = measure(loadPly, path);
    EXPECT_FALSE(m.ok);
    EXPECT_NE(m.message.find("unexpected end of file: 0 of 300000 vertex lines present"), std::string::npos) << m.message;
    EXPECT_LE(m.peak, ply.size() + kSlack) << "peak " << m.peak << " bytes for a " << ply.size() << "-byte file";
}

TEST(LoaderMemory, AsciiPlyCountBeyondWhatTheFileCanHold) {
    // 3 values need at least 6 bytes: one more vertex than (bytes + 1) / 6 is a wrong header.
    const std::string body(600000, '\n');
    auto header = [](std::uint64_t n) {
        return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(n) +
               "\nproperty float x\nproperty float y\nproperty float z\n"
               "element face 0\nproperty list uchar int vertex_indices\nend_header\n";
    };
    TempDir dir;
    const auto over = dir.write("over.ply", header(100001) + body);
    const Measured m = measure(loadPly, over);
    EXPECT_NE(m.message.find("header declares 100001 vertex entries but the file is too short"), std::string::npos)
        << m.message;
    EXPECT_LE(m.peak, body.size() + kSlack);
    const auto at = dir.write("at.ply", header(100000) + body);  // passes the bound, fails on the data
    EXPECT_NE(measure(loadPly, at).message.find("unexpected end of file"), std::string::npos);
}

TEST(LoaderMemory, BinaryPlyTruncatedInTheFaces) {
    // 80000 real (zero) vertices, then 1000000 faces claimed but 88576 bytes present:
    // reserving 3 indices per claimed face would take about 11x the file before reading one.
    std::string ply =
        "ply\nformat binary_little_endian 1.0\nelement vertex 80000\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1000000\nproperty list uchar int vertex_indices\nend_header\n";
    ply += std::string(80000 * 12 + 88576, '\0');
    TempDir dir;
    const auto path = dir.write("trunc.ply", ply);
    const Measured m = measure(loadPly, path);
    EXPECT_NE(m.message.find("file truncated in face 88576 of 1000000"), std::string::npos) << m.message;
    // The file, the vertices actually read (12 bytes each) and vector growth (up to 2x, old+new).
    EXPECT_LE(m.peak, ply.size() + 3 * 80000 * 12 + kSlack) << m.peak;
}

TEST(LoaderMemory, ObjOfBlankLines) {
    const std::string obj(4 << 20, '\n');
    TempDir dir;
    const auto path = dir.write("blank.obj", obj);
    const Measured m = measure(loadObj, path);
    EXPECT_NE(m.message.find("no faces"), std::string::npos) << m.message;
    EXPECT_LE(m.peak, obj.size() + kSlack) << m.peak;
}

TEST(LoaderMemory, ObjVerticesThenGarbage) {
    std::string obj;
    for (int i = 0; i < 200000; ++i) obj += "v 0 0 0\n";
    obj += "f 1 2 x\n";
    TempDir dir;
    const auto path = dir.write("garbage.obj", obj);
    const Measured m = measure(loadObj, path);
    EXPECT_NE(m.message.find("line 200001: vertex index 'x' is not an integer"), std::string::npos) << m.message;
    EXPECT_LE(m.peak, obj.size() + 3 * 200000 * 12 + kSlack) << m.peak;
}

}  // namespace
}  // namespace dyncull
