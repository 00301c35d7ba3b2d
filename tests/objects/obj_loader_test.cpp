#include <cmath>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "dyncull/loaders/loaders.hpp"
#include "objects/test_files.hpp"

namespace dyncull {
namespace {

using test::TempDir;
using test::expectError;

// Two shapes: a quad (shared corners referenced twice) and a pentagon with normals.
const char* kObj =
    "# test\n"
    "mtllib missing.mtl\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    "v 0 0 2\nv 1 0 2\nv 2 1 2\nv 1 2 2\nv 0 1 2\n"
    "vn 0 0 3\n"
    "o quad\n"
    "f 1 2 3 4\n"
    "o penta\n"
    "f 5//1 6//1 7//1 8//1 9//1\n"
    "f -5//1 -4//1 -1//1\n";

TEST(ObjLoader, QuadsAndPolygonsAreTriangulatedPerShape) {
    TempDir dir;
    const auto path = dir.write("shapes.obj", kObj);
    auto r = loadObj(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->meshes.size(), 2u);
    ASSERT_EQ(r->instances.size(), 2u);
    const Mesh& quad = r->meshes[0];
    EXPECT_EQ(quad.name, "quad");
    EXPECT_EQ(quad.vertexCount(), 4u);
    EXPECT_EQ(quad.triangleCount(), 2u);
    EXPECT_NEAR(surfaceArea(quad), 1.0, 1e-6);
    EXPECT_NEAR(quad.normals[0].z, 1.0f, 1e-6f);  // computed: no vn on this shape

    const Mesh& penta = r->meshes[1];
    EXPECT_EQ(penta.triangleCount(), 4u);  // pentagon -> 3, plus one triangle
    // Relative indices reuse vertices 5, 6 and 9: deduplicated to 5 vertices.
    EXPECT_EQ(penta.vertexCount(), 5u);
    EXPECT_EQ(penta.normals[0], glm::vec3(0.0f, 0.0f, 1.0f));  // from the file, normalised
    EXPECT_EQ(r->instances[1].mesh, 1u);
    EXPECT_EQ(r->instances[1].transform, glm::mat4(1.0f));
}

TEST(ObjLoader, MissingFile) {
    TempDir dir;
    const auto path = dir.file("none.obj");
    expectError(loadObj(path), path, "not found");
}

TEST(ObjLoader, EmptyFile) {
    TempDir dir;
    const auto path = dir.write("e.obj", "");
    expectError(loadObj(path), path, "empty");
}

TEST(ObjLoader, NoFaces) {
    TempDir dir;
    const auto path = dir.write("nof.obj", "v 0 0 0\nv 1 0 0\n");
    expectError(loadObj(path), path, "no faces");
}

TEST(ObjLoader, IndexOutOfRange) {
    TempDir dir;
    const auto path = dir.write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    expectError(loadObj(path), path, "line 4: vertex index 9 out of range (3 vertices)");
}

// Issue 19: unparsable or non-finite numbers and out-of-range indices are errors with a line number.
struct BadObj {
    const char* name;
    std::string text;
    const char* what;  // expected in the message, after the path
};

const char* const kTri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

TEST(ObjLoader, HostileInputIsRejectedWithFileAndLine) {
    const std::string tri = kTri;
    const BadObj cases[] = {
        {"nan", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "line 1: vertex: 'nan' is not a finite number"},
        {"inf", "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n", "line 2: vertex: 'inf' is not a finite number"},
        {"neginf", "v 0 0 0\nv 1 0 -inf\nv 0 1 0\nf 1 2 3\n", "line 2: vertex: '-inf' is not a finite number"},
        {"letters", "v 0 0 0\nv 1 0 0\nv a b c\nf 1 2 3\n", "line 3: vertex: 'a' is not a finite number"},
        {"float_overflow", "v 0 0 1e39\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "line 1: vertex: '1e39' is not a finite number"},
        {"number_prefix", "v 0 0 1x\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "line 1: vertex: '1x' is not a finite number"},
        {"two_coords", "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "line 1: vertex has 2 numbers"},
        {"five_coords", "v 0 0 0 1 1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "line 1: vertex has 5 numbers"},
        {"trailing_garbage", "v 0 0 0 1 1 1 1 junk\n", "line 1: vertex has more than 7 numbers (trailing 'junk')"},
        {"vn_garbage", tri + "vn 0 0 x\nf 1//1 2//1 3//1\n", "line 4: normal: 'x' is not a finite number"},
        {"vn_nan", tri + "vn 0 nan 1\n", "line 4: normal: 'nan' is not a finite number"},
        {"vn_short", tri + "vn 0 1\n", "line 4: normal has 2 numbers, expected 3"},
        {"vn_long", tri + "vn 0 1 0 0\n", "line 4: normal has more than 3 numbers"},
        {"vt_garbage", tri + "vt 0.5 q\n", "line 4: texture coordinate: 'q' is not a finite number"},
        {"huge_index", tri + "f 1 2 99999999999999999999\n", "line 4: vertex index '99999999999999999999' is not an integer"},
        {"big_index", tri + "f 1 2 4294967297\n", "line 4: vertex index 4294967297 out of range (3 vertices)"},
        {"index_zero", tri + "f 0 1 2\n", "line 4: vertex index 0 (OBJ indices start at 1)"},
        {"relative_before_start", tri + "f -1 -2 -4\n", "line 4: vertex index -4 out of range (3 vertices)"},
        {"relative_huge", tri + "f -1 -2 -9223372036854775808\n", "out of range (3 vertices)"},
        {"index_garbage", tri + "f 1 2 3x\n", "line 4: vertex index '3x' is not an integer"},
        {"index_float", tri + "f 1 2 3.0\n", "line 4: vertex index '3.0' is not an integer"},
        {"normal_index_range", tri + "vn 0 0 1\nf 1//1 2//1 3//2\n", "line 5: normal index 2 out of range (1 normals)"},
        {"texcoord_index_range", tri + "f 1/1 2/1 3/1\n", "line 4: texture coordinate index 1 out of range (0 texture coordinates)"},
        {"corner_four_parts", tri + "f 1/1/1/1 2 3\n", "line 4: face corner '1/1/1/1' has more than three parts"},
        {"corner_empty_texcoord", tri + "f 1/ 2 3\n", "line 4: face corner '1/' is malformed"},
        {"corner_empty_vertex", tri + "f /1 2 3\n", "line 4: vertex index '' is not an integer"},
        {"face_two_corners", tri + "f 1 2\n", "line 4: face has 2 corners (a face needs at least 3)"},
        {"face_no_corners", tri + "f\n", "line 4: face has 0 corners"},
        {"unknown_keyword", tri + "vx 1 2 3\nf 1 2 3\n", "line 4: unknown keyword 'vx'"},
        {"binary_junk", tri + std::string("\x01\x02\x03 1\n"), "line 4: unknown keyword"},
    };
    for (const BadObj& c : cases) {
        SCOPED_TRACE(c.name);
        TempDir dir;
        const auto path = dir.write(std::string(c.name) + ".obj", c.text);
        expectError(loadObj(path), path, c.what);
        ASSERT_FALSE(loadObj(path).ok());
        EXPECT_EQ(loadObj(path).error().message.find('\n'), std::string::npos);
    }
}

TEST(ObjLoader, ForwardReferenceIsOutOfRange) {
    // Indices name vertices defined earlier in the file (the OBJ rule), so errors can name the line.
    TempDir dir;
    const auto path = dir.write("fwd.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n");
    expectError(loadObj(path), path, "line 3: vertex index 3 out of range (2 vertices)");
}

TEST(ObjLoader, HugeLineIsRejectedWithAShortMessage) {
    TempDir dir;
    const std::string text = std::string(kTri) + "v 0 0 " + std::string(1 << 20, '7') + "x\n";
    const auto path = dir.write("long.obj", text);
    auto r = loadObj(path);
    expectError(r, path, "line 4: vertex: '7777");
    EXPECT_LT(r.error().message.size(), 200u + path.string().size());
}

TEST(ObjLoader, HugeFaceLoads) {
    // One face with 100000 corners on a circle (convex): fine, and no quadratic blow-up.
    std::string text;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
        const double a = 2.0 * std::numbers::pi * i / n;
        text += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
    }
    text += "f";
    for (int i = 1; i <= n; ++i) text += " " + std::to_string(i);
    text += "\n";
    TempDir dir;
    const auto path = dir.write("circle.obj", text);
    auto r = loadObj(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->meshes[0].triangleCount(), std::size_t(n - 2));
    EXPECT_NEAR(surfaceArea(r->meshes[0]), std::numbers::pi, 1e-3);
}

TEST(ObjLoader, AcceptedVariants) {
    // w weight, vertex colours, texture coordinates, comments, CRLF, tabs, '+' signs, groups
    // without faces, lines and points (ignored), relative indices.
    const char* text =
        "\xEF\xBB\xBF# comment after a byte order mark\r\n"
        "v 0 0 0 1\r\n"
        "v\t+1 0 0 0.5 0.5 0.5\n"
        "v 0 1 0 1 0 0 0 # colour and weight\n"
        "vt 0 0\nvt 1\nvt 0 1 0\n"
        "vn 0 0 1\n"
        "g empty\n"
        "o tri\n"
        "s off\nusemtl m\nl 1 2\np 1\n"
        "f 1/1/1 2/2/1 3/3/1\n"
        "f -3/-3 -2/-2 -1/-1\n";
    TempDir dir;
    const auto path = dir.write("variants.obj", text);
    auto r = loadObj(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->meshes.size(), 1u);
    EXPECT_EQ(r->meshes[0].name, "tri");
    EXPECT_EQ(r->meshes[0].triangleCount(), 2u);
    EXPECT_EQ(r->meshes[0].positions[1], glm::vec3(1.0f, 0.0f, 0.0f));
}

TEST(ObjLoader, ConcaveStarIsEarClippedNotFanned) {
    // A 200-corner star: a fan from corner 0 would cover parts outside it (the "disc").
    const int points = 100;
    std::string text;
    double area = 0.0;
    std::vector<glm::dvec2> flat;
    for (int i = 0; i < 2 * points; ++i) {
        const double a = std::numbers::pi * i / points;
        const double r = i % 2 == 0 ? 10.0 : 3.0;
        flat.emplace_back(r * std::cos(a), r * std::sin(a));
        text += "v " + std::to_string(flat.back().x) + " 2 " + std::to_string(-flat.back().y) + "\n";  // in the xz plane
    }
    for (std::size_t i = 0; i < flat.size(); ++i) {
        const glm::dvec2 &p = flat[i], &q = flat[(i + 1) % flat.size()];
        area += 0.5 * (p.x * q.y - q.x * p.y);
    }
    text += "f";
    for (int i = 1; i <= 2 * points; ++i) text += " " + std::to_string(i);
    text += "\n";
    TempDir dir;
    const auto path = dir.write("star.obj", text);
    auto r = loadObj(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    const Mesh& m = r->meshes[0];
    EXPECT_EQ(m.triangleCount(), std::size_t(2 * points - 2));
    EXPECT_NEAR(surfaceArea(m), area, 1e-3 * area);
    // Every triangle faces +y, like the polygon (x, -z winding is counter-clockwise seen from +y).
    for (const glm::vec3& n : m.normals) EXPECT_NEAR(n.y, 1.0f, 1e-5f);
}

TEST(ObjLoader, ZeroAreaFacesAreDroppedAndAloneMeanNothingToDraw) {
    TempDir dir;
    const auto path = dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3 4\n");
    expectError(loadObj(path), path, "no faces");
}

}  // namespace
}  // namespace dyncull
