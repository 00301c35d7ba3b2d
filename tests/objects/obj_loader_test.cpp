#include <string>

#include <gtest/gtest.h>

#include "dyncull/objects/loaders.hpp"
#include "objects/test_files.hpp"

namespace dyncull {
namespace {

using test::TempDir;

void expectError(const Expected<Scene>& r, const std::filesystem::path& path, const std::string& what) {
    ASSERT_FALSE(r.ok());
    const std::string& msg = r.error().message;
    EXPECT_EQ(msg.rfind(path.string(), 0), 0u) << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << "expected '" << what << "' in: " << msg;
}

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

TEST(ObjLoader, QuadsAndPolygonsAreFanTriangulatedPerShape) {
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
    expectError(loadObj(path), path, "vertex index 9 out of range (3 vertices)");
}

}  // namespace
}  // namespace dyncull
