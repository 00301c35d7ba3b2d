#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "dyncull/loaders/loaders.hpp"
#include "dyncull/loaders/ply_stream.hpp"
#include "objects/test_files.hpp"

namespace dyncull {
namespace {

using test::put;
using test::TempDir;
using test::expectError;

// Unit square in z = 0 as one quad plus a triangle above it, with Stanford-style extras.
const char* kAsciiQuad =
    "ply\n"
    "format ascii 1.0\n"
    "comment made by hand\n"
    "element vertex 5\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "property float confidence\n"
    "property float intensity\n"
    "element face 2\n"
    "property uchar flags\n"
    "property list uchar int vertex_indices\n"
    "end_header\n"
    "0 0 0 0.5 1\n"
    "1 0 0 0.5 1\n"
    "1 1 0 0.5 1 \n"
    "0 1 0 0.5 1\r\n"
    "+0.5 0.5 1e0 0.5 1\n"
    "7 4 0 1 2 3\n"
    "0 3 0 1 4\n";

TEST(PlyLoader, AsciiQuadIsFanTriangulatedAndExtrasSkipped) {
    TempDir dir;
    const auto path = dir.write("quad.ply", kAsciiQuad);
    auto r = loadPly(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->meshes.size(), 1u);
    ASSERT_EQ(r->instances.size(), 1u);
    const Mesh& m = r->meshes[0];
    EXPECT_EQ(m.vertexCount(), 5u);
    EXPECT_EQ(m.triangleCount(), 3u);  // quad -> 2, triangle -> 1
    EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 0, 1, 4}));
    EXPECT_EQ(m.positions[4], glm::vec3(0.5f, 0.5f, 1.0f));
    ASSERT_EQ(m.normals.size(), 5u);
    EXPECT_NEAR(m.normals[2].z, 1.0f, 1e-6f);  // only touched by the flat quad
    EXPECT_NEAR(surfaceArea(m), 1.0 + 0.5 * std::sqrt(1.0 + 0.25), 1e-6);
}

TEST(PlyLoader, FileNormalsAreUsedAndNormalised) {
    TempDir dir;
    const auto path = dir.write("n.ply",
                                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
                                "element face 1\nproperty list uchar uint vertex_index\nend_header\n"
                                "0 0 0 2 0 0\n1 0 0 2 0 0\n0 1 0 2 0 0\n3 0 1 2\n");
    auto r = loadPly(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    // The file says +X (length 2); the geometric normal would be +Z.
    EXPECT_EQ(r->meshes[0].normals[1], glm::vec3(1.0f, 0.0f, 0.0f));
}

TEST(PlyLoader, ZeroFileNormalsFallBackToComputed) {
    TempDir dir;
    const auto path = dir.write("n0.ply",
                                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
                                "element face 1\nproperty list uchar uint vertex_indices\nend_header\n"
                                "0 0 0 0 0 0\n1 0 0 0 0 0\n0 1 0 0 0 0\n3 0 1 2\n");
    auto r = loadPly(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->meshes[0].normals[0], glm::vec3(0.0f, 0.0f, 1.0f));
}

// Binary file with mixed scalar types, type aliases, extra scalar/list properties on
// both elements and an extra trailing element.
std::string binaryPly(bool big) {
    std::string s = "ply\nformat ";
    s += big ? "binary_big_endian" : "binary_little_endian";
    s += " 1.0\ncomment extra properties everywhere\n"
         "element vertex 4\n"
         "property float32 x\nproperty double y\nproperty float z\n"
         "property uchar red\nproperty int16 q\nproperty list uint8 float junk\nproperty float confidence\n"
         "element face 2\n"
         "property int flags\nproperty list uint8 int32 vertex_indices\nproperty list ushort double texcoord\n"
         "element edge 1\nproperty int vertex1\nproperty uint vertex2\n"
         "end_header\n";
    const float xs[4] = {0, 2, 2, 0};
    const double ys[4] = {0, 0, 3, 3};
    for (int i = 0; i < 4; ++i) {
        put<float>(s, xs[i], big);
        put<double>(s, ys[i], big);
        put<float>(s, -1.0f, big);
        put<std::uint8_t>(s, 255, big);
        put<std::int16_t>(s, -7, big);
        put<std::uint8_t>(s, 2, big);  // junk list of 2 floats
        put<float>(s, 9.0f, big);
        put<float>(s, 9.0f, big);
        put<float>(s, 0.25f, big);
    }
    // face 0: triangle 0 1 2; face 1: triangle 0 2 3. Each with a 1-entry texcoord list.
    const std::int32_t faces[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (const auto& f : faces) {
        put<std::int32_t>(s, 42, big);
        put<std::uint8_t>(s, 3, big);
        for (std::int32_t v : f) put<std::int32_t>(s, v, big);
        put<std::uint16_t>(s, 1, big);
        put<double>(s, 0.5, big);
    }
    put<std::int32_t>(s, 0, big);
    put<std::uint32_t>(s, 1, big);
    return s;
}

class PlyBinary : public ::testing::TestWithParam<bool> {};

TEST_P(PlyBinary, LoadsWithExtraPropertiesAndListTypes) {
    TempDir dir;
    const auto path = dir.write("bin.ply", binaryPly(GetParam()));
    auto r = loadPly(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    const Mesh& m = r->meshes[0];
    ASSERT_EQ(m.vertexCount(), 4u);
    EXPECT_EQ(m.positions[2], glm::vec3(2.0f, 3.0f, -1.0f));
    EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
    EXPECT_NEAR(surfaceArea(m), 6.0, 1e-9);
}

TEST_P(PlyBinary, TruncatedInTheMiddleIsAnError) {
    TempDir dir;
    const std::string full = binaryPly(GetParam());
    const auto path = dir.write("cut.ply", full.substr(0, full.size() - 30));
    expectError(loadPly(path), path, "truncated");
}

TEST_P(PlyBinary, EveryTruncationIsAnErrorNotACrash) {
    TempDir dir;
    const std::string full = binaryPly(GetParam());
    // Step 3 (co-prime to the 2/4/8-byte fields) still cuts inside every kind of field.
    for (std::size_t n = 1; n < full.size(); n += 3) {
        const auto path = dir.write("cut.ply", full.substr(0, n));
        auto r = loadPly(path);
        ASSERT_FALSE(r.ok()) << "prefix of " << n << " bytes loaded";
        ASSERT_EQ(r.error().message.rfind(path.string(), 0), 0u) << r.error().message;
    }
}

INSTANTIATE_TEST_SUITE_P(Endianness, PlyBinary, ::testing::Values(false, true),
                         [](const auto& p) { return p.param ? "BigEndian" : "LittleEndian"; });

TEST(PlyLoader, EveryAsciiTruncationIsHandled) {
    TempDir dir;
    const std::string full = kAsciiQuad;
    for (std::size_t n = 1; n < full.size(); n += 2) {
        const auto path = dir.write("cut.ply", full.substr(0, n));
        auto r = loadPly(path);
        // Cutting only the final newline (or a digit-free tail) may still be a valid file.
        if (r.ok()) EXPECT_GE(n, full.size() - 2) << "prefix of " << n << " bytes loaded";
        else ASSERT_EQ(r.error().message.rfind(path.string(), 0), 0u) << r.error().message;
    }
}

TEST(PlyLoader, AllScalarTypesInAscii) {
    TempDir dir;
    const auto path = dir.write("types.ply",
                                "ply\nformat ascii 1.0\nelement vertex 3\nproperty char x\nproperty ushort y\n"
                                "property int32 z\nproperty uint a\nproperty int8 b\nproperty uint16 c\n"
                                "property short d\nproperty double e\nproperty float64 f\n"
                                "element face 1\nproperty list int uint32 vertex_indices\nend_header\n"
                                "-1 0 0 4000000000 -5 65535 -300 1.5 2.5\n1 0 0 0 0 0 0 0 0\n0 1 0 0 0 0 0 0 0\n"
                                "3 0 1 2\n");
    auto r = loadPly(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->meshes[0].positions[0], glm::vec3(-1.0f, 0.0f, 0.0f));
}

TEST(PlyLoader, MissingFile) {
    TempDir dir;
    const auto path = dir.file("nothere.ply");
    expectError(loadPly(path), path, "not found");
}

TEST(PlyLoader, EmptyFile) {
    TempDir dir;
    const auto path = dir.write("empty.ply", "");
    expectError(loadPly(path), path, "empty");
}

TEST(PlyLoader, NotAPlyFile) {
    TempDir dir;
    const auto path = dir.write("text.ply", "hello\nworld\n");
    expectError(loadPly(path), path, "not a PLY file");
}

TEST(PlyLoader, UnknownFormat) {
    TempDir dir;
    const auto path = dir.write("fmt.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n");
    expectError(loadPly(path), path, "unknown format");
}

TEST(PlyLoader, HeaderWithoutEnd) {
    TempDir dir;
    const auto path = dir.write("noend.ply", "ply\nformat ascii 1.0\nelement vertex 3\n");
    expectError(loadPly(path), path, "end_header");
}

TEST(PlyLoader, AsciiMissingFaceLine) {
    TempDir dir;
    std::string text = kAsciiQuad;
    text.erase(text.rfind("0 3 0 1 4\n"));
    const auto path = dir.write("short.ply", text);
    expectError(loadPly(path), path, "unexpected end of file: 1 of 2 face lines");
}

TEST(PlyLoader, AsciiMissingVertexLine) {
    TempDir dir;
    std::string text = kAsciiQuad;
    text.erase(text.find("1 0 0 0.5 1\n"), 12);
    const auto path = dir.write("short.ply", text);
    // The first face line is now read as vertex 4.
    expectError(loadPly(path), path, "vertex 4");
}

TEST(PlyLoader, AsciiShortLine) {
    TempDir dir;
    std::string text = kAsciiQuad;
    text.replace(text.find("1 0 0 0.5 1\n"), 12, "1 0 0\n");
    const auto path = dir.write("shortline.ply", text);
    expectError(loadPly(path), path, "line 15: vertex 1: missing value for 'confidence'");
}

TEST(PlyLoader, HeaderCountTooSmall) {
    TempDir dir;
    std::string text = kAsciiQuad;
    text.replace(text.find("element face 2"), 14, "element face 1");
    const auto path = dir.write("count.ply", text);
    expectError(loadPly(path), path, "data after the last element");
}

TEST(PlyLoader, HeaderCountHuge) {
    TempDir dir;
    std::string text = kAsciiQuad;
    text.replace(text.find("element vertex 5"), 16, "element vertex 999999999");
    const auto path = dir.write("huge.ply", text);
    expectError(loadPly(path), path, "too short");
}

TEST(PlyLoader, IndexOutOfRange) {
    TempDir dir;
    std::string text = kAsciiQuad;
    text.replace(text.find("0 3 0 1 4"), 9, "0 3 0 1 7");
    const auto path = dir.write("range.ply", text);
    expectError(loadPly(path), path, "face 1: vertex index 7 out of range (5 vertices)");
}

TEST(PlyLoader, NegativeIndexInBinary) {
    TempDir dir;
    std::string s = binaryPly(false);
    // Patch the first index of face 0 (after the 4 vertices and the int flags + uchar count).
    const std::size_t headerEnd = s.find("end_header\n") + 11;
    const std::size_t vertexBytes = 4 + 8 + 4 + 1 + 2 + 1 + 8 + 4;
    std::string neg;
    put<std::int32_t>(neg, -3, false);
    s.replace(headerEnd + 4 * vertexBytes + 5, 4, neg);
    const auto path = dir.write("neg.ply", s);
    expectError(loadPly(path), path, "face 0: vertex index -3 out of range");
}

TEST(PlyLoader, NanAndInfCoordinates) {
    TempDir dir;
    for (const char* bad : {"nan", "inf", "-inf", "1e99"}) {
        std::string text = kAsciiQuad;
        text.replace(text.find("1 1 0 0.5 1"), 5, std::string("1 ") + bad + " 0");
        const auto path = dir.write("nan.ply", text);
        expectError(loadPly(path), path, "vertex 2 has a non-finite coordinate");
    }
}

TEST(PlyLoader, BadNumber) {
    TempDir dir;
    std::string text = kAsciiQuad;
    text.replace(text.find("1 1 0 0.5 1"), 5, "1 x1 0");
    const auto path = dir.write("bad.ply", text);
    expectError(loadPly(path), path, "bad value for 'y'");
}

TEST(PlyLoader, NoVertexElement) {
    TempDir dir;
    const auto path = dir.write("nov.ply", "ply\nformat ascii 1.0\nelement face 0\n"
                                           "property list uchar int vertex_indices\nend_header\n");
    expectError(loadPly(path), path, "no 'vertex' element");
}

TEST(PlyLoader, PointCloudWithoutFaces) {
    TempDir dir;
    const auto path = dir.write("pts.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                           "property float y\nproperty float z\nend_header\n0 0 0\n");
    expectError(loadPly(path), path, "no 'face' element");
}

TEST(PlyLoader, MissingCoordinateProperty) {
    TempDir dir;
    const auto path = dir.write("noz.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                           "property float y\nelement face 0\n"
                                           "property list uchar int vertex_indices\nend_header\n0 0\n");
    expectError(loadPly(path), path, "x, y or z");
}

TEST(PlyLoader, OnlyDegenerateFaces) {
    TempDir dir;
    const auto path = dir.write("deg.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                           "property float y\nproperty float z\nelement face 1\n"
                                           "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n2 0 1\n");
    expectError(loadPly(path), path, "no triangles");
}

// Issue 19: every count read from the file is checked before it sizes anything, with
// values at and around 2^32 and 2^64.
std::string triangleHeader(const std::string& format, const std::string& vertexCount, const std::string& faceCount,
                           const std::string& countType = "uchar", const std::string& extra = "") {
    return "ply\nformat " + format + " 1.0\n" + extra + "element vertex " + vertexCount +
           "\nproperty float x\nproperty float y\nproperty float z\nelement face " + faceCount + "\nproperty list " +
           countType + " int vertex_indices\nend_header\n";
}
const char* kTriangleBody = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

TEST(PlyLoader, HeaderCountsNear2To32And2To64) {
    struct Case {
        const char* vertices;
        const char* faces;
        const char* what;
    };
    const Case cases[] = {
        {"4294967295", "1", "header declares 4294967295 vertex entries but the file is too short"},
        {"4294967296", "1", "too many vertices for 32-bit indices"},
        {"4294967297", "1", "too many vertices for 32-bit indices"},
        {"18446744073709551615", "1", "too many vertices for 32-bit indices"},
        {"18446744073709551616", "1", "bad element count '18446744073709551616'"},
        {"-1", "1", "bad element count '-1'"},
        {"3", "4294967295", "header declares 4294967295 face entries"},
        {"3", "4294967296", "header declares 4294967296 face entries"},
        {"3", "18446744073709551615", "header declares 18446744073709551615 face entries"},
        {"3", "99999999999999999999999", "bad element count"},
    };
    for (const std::string format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
        for (const Case& c : cases) {
            SCOPED_TRACE(format + " " + c.vertices + " " + c.faces);
            TempDir dir;
            // Padded so every case fails on its own count, not on the vertices' bytes.
            const auto path = dir.write("count.ply", triangleHeader(format, c.vertices, c.faces) + kTriangleBody +
                                                         std::string(64, '\n'));
            expectError(loadPly(path), path, c.what);
        }
    }
}

TEST(PlyLoader, ElementWithoutPropertiesAndHugeCountIsNoEndlessLoop) {
    // Binary: nothing to read per instance, so the count is harmless and the file loads.
    std::string bin = triangleHeader("binary_little_endian", "3", "1", "uchar", "element nothing 18446744073709551615\n");
    for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put(bin, f, false);
    put<std::uint8_t>(bin, 3, false);
    for (std::int32_t i : {0, 1, 2}) put(bin, i, false);
    TempDir dir;
    const auto binPath = dir.write("empty_element.ply", bin);
    auto r = loadPly(binPath);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->meshes[0].triangleCount(), 1u);
    // ASCII: each instance would need a line of its own.
    const auto asciiPath =
        dir.write("empty_element_ascii.ply",
                  triangleHeader("ascii", "3", "1", "uchar", "element nothing 18446744073709551615\n") + kTriangleBody);
    expectError(loadPly(asciiPath), asciiPath, "line 11: nothing 0: more values than the header declares");
}

TEST(PlyLoader, ListCountsNear2To32) {
    TempDir dir;
    for (bool big : {false, true}) {
        const std::string format = big ? "binary_big_endian" : "binary_little_endian";
        auto file = [&](const std::string& countType, auto count) {
            std::string s = triangleHeader(format, "3", "1", countType);
            for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put(s, f, big);
            put(s, count, big);
            for (std::int32_t i : {0, 1, 2}) put(s, i, big);
            return s;
        };
        const auto u32 = dir.write("u32.ply", file("uint", std::uint32_t{0xFFFFFFFFu}));
        expectError(loadPly(u32), u32, "file truncated in face 0 of 1");
        const auto u32b = dir.write("u32b.ply", file("uint", std::uint32_t{0x80000000u}));
        expectError(loadPly(u32b), u32b, "file truncated in face 0 of 1");
        const auto i32 = dir.write("i32.ply", file("int", std::int32_t{-1}));
        expectError(loadPly(i32), i32, "face 0: negative list count");
        const auto i32min = dir.write("i32min.ply", file("int", std::int32_t{INT32_MIN}));
        expectError(loadPly(i32min), i32min, "face 0: negative list count");
    }
    // ASCII list counts are read as 64-bit: the line runs out first.
    for (const char* count : {"4294967296", "9223372036854775807"}) {
        const auto path = dir.write("ascii_list.ply", triangleHeader("ascii", "3", "1") + "0 0 0\n1 0 0\n0 1 0\n" +
                                                          count + " 0 1 2\n");
        expectError(loadPly(path), path, std::string("list 'vertex_indices' has fewer than ") + count + " entries");
    }
    const auto neg = dir.write("ascii_neg.ply", triangleHeader("ascii", "3", "1") + "0 0 0\n1 0 0\n0 1 0\n-3 0 1 2\n");
    expectError(loadPly(neg), neg, "bad list count");
}

TEST(PlyLoader, AsciiIndicesNear2To32And2To63) {
    TempDir dir;
    const std::pair<const char*, const char*> cases[] = {
        {"4294967295", "vertex index 4294967295 out of range (3 vertices)"},
        {"4294967296", "vertex index 4294967296 out of range (3 vertices)"},
        {"9223372036854775807", "vertex index 9223372036854775807 out of range (3 vertices)"},
        {"-9223372036854775808", "vertex index -9223372036854775808 out of range (3 vertices)"},
        {"9223372036854775808", "bad vertex index in 'vertex_indices'"},
        {"18446744073709551616", "bad vertex index in 'vertex_indices'"},
        {"1.5", "bad vertex index"},
        {"nan", "bad vertex index"},
    };
    for (const auto& [index, what] : cases) {
        SCOPED_TRACE(index);
        const auto path = dir.write("index.ply", triangleHeader("ascii", "3", "1") + "0 0 0\n1 0 0\n0 1 0\n3 0 1 " +
                                                      index + "\n");
        expectError(loadPly(path), path, std::string("line 13: face 0: ") + what);
    }
}

TEST(PlyLoader, ConcaveFaceIsEarClipped) {
    // An L-shaped hexagon: the fan from corner 0 would leave the L (triangle 0 3 4 crosses
    // the notch); ear clipping covers exactly its area of 5.
    TempDir dir;
    const auto path = dir.write("l.ply", triangleHeader("ascii", "6", "1") +
                                             "1 3 0\n0 3 0\n0 0 0\n3 0 0\n3 1 0\n1 1 0\n6 0 1 2 3 4 5\n");
    auto r = loadPly(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->meshes[0].triangleCount(), 4u);
    EXPECT_NEAR(surfaceArea(r->meshes[0]), 5.0, 1e-6);
    for (const glm::vec3& n : r->meshes[0].normals) EXPECT_NEAR(n.z, 1.0f, 1e-6f);
}

TEST(PlyLoader, FacesBeforeVerticesAreTriangulatedOnceTheVerticesAreRead) {
    TempDir dir;
    const auto path = dir.write("faces_first.ply",
                                "ply\nformat ascii 1.0\nelement face 2\nproperty list uchar int vertex_indices\n"
                                "element vertex 6\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
                                "6 0 1 2 3 4 5\n3 0 1 2\n1 1 0\n1 3 0\n0 3 0\n0 0 0\n3 0 0\n3 1 0\n");
    auto r = loadPly(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->meshes[0].triangleCount(), 5u);
    EXPECT_NEAR(surfaceArea(r->meshes[0]), 5.0 + 1.0, 1e-6);
}

TEST(PlyLoader, ZeroAreaPolygonsAreDropped) {
    TempDir dir;
    const auto path = dir.write("flat.ply", triangleHeader("ascii", "4", "2") +
                                                "0 0 0\n1 0 0\n2 0 0\n0 1 0\n4 0 1 2 0\n3 0 1 3\n");
    auto r = loadPly(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->meshes[0].triangleCount(), 1u);
}

}  // namespace
}  // namespace dyncull

namespace dyncull {
namespace {

TEST(PlyWriter, WritesWhatTheLoaderReadsBack) {
    test::TempDir dir;
    const std::vector<glm::vec3> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1.5f}};
    for (const bool normals : {false, true}) {
        const auto path = dir.file(normals ? "n.ply" : "p.ply");
        PlyWriter w;
        ASSERT_TRUE(w.open(path, 4, 2, normals, "test").ok());
        for (const glm::vec3& v : p) ASSERT_TRUE(w.vertex(v, glm::vec3(0, 0, 2)).ok());
        ASSERT_TRUE(w.triangle(0, 1, 2).ok());
        ASSERT_TRUE(w.triangle(0, 2, 3).ok());
        ASSERT_TRUE(w.close().ok());
        auto scene = loadPly(path);
        ASSERT_TRUE(scene.ok()) << scene.error().message;
        const Mesh& m = scene->meshes[0];
        EXPECT_EQ(m.positions, p);
        EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
        if (normals) {
            EXPECT_EQ(m.normals[3], glm::vec3(0, 0, 1));  // the file's, normalised
        }
    }
}

TEST(PlyWriter, CountsOtherThanDeclaredAreAnErrorAndLeaveNoFile) {
    test::TempDir dir;
    const auto path = dir.file("bad.ply");
    {
        PlyWriter w;
        ASSERT_TRUE(w.open(path, 3, 1, false).ok());
        ASSERT_TRUE(w.vertex({0, 0, 0}).ok());
        EXPECT_FALSE(w.triangle(0, 0, 0).ok());  // before every vertex
        ASSERT_TRUE(w.vertex({1, 0, 0}).ok());
        ASSERT_TRUE(w.vertex({0, 1, 0}).ok());
        EXPECT_FALSE(w.vertex({0, 1, 0}).ok());  // one too many
        EXPECT_FALSE(w.triangle(0, 1, 3).ok());  // out of range
        const Status s = w.close();              // no triangle written
        ASSERT_FALSE(s.ok());
        EXPECT_NE(s.message().find("declares"), std::string::npos) << s.message();
    }
    EXPECT_TRUE(std::filesystem::is_empty(dir.file("")));
    PlyWriter w;
    const Status s = w.open(dir.file("no/such/dir/x.ply"), 3, 1, false);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("x.ply"), std::string::npos);
}

}  // namespace
}  // namespace dyncull
