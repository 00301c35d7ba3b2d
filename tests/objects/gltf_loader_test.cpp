#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "dyncull/loaders/loaders.hpp"
#include "objects/test_files.hpp"

namespace dyncull {
namespace {

using test::put;
using test::TempDir;
using test::expectError;
using test::base64;

// 124 bytes: interleaved position+normal of a unit quad (stride 24), uint16 triangle
// indices, uint8 strip indices, uint32 indices.
std::string bufferBytes(float nanAt = 0.0f, std::uint32_t lastIndex = 2) {
    std::string b;
    const float quad[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    for (const auto& p : quad) {
        put<float>(b, p[0] + nanAt, false);
        put<float>(b, p[1], false);
        put<float>(b, p[2], false);
        put<float>(b, 0.0f, false);
        put<float>(b, 0.0f, false);
        put<float>(b, 1.0f, false);
    }
    for (std::uint16_t i : {0, 1, 2, 0, 2, 3}) put<std::uint16_t>(b, i, false);
    for (std::uint8_t i : {0, 1, 3, 2}) put<std::uint8_t>(b, i, false);
    for (std::uint32_t i : {0u, 1u, lastIndex}) put<std::uint32_t>(b, i, false);
    return b;
}

std::string gltfJson(const std::string& uri, const std::string& extraAccessor = "", const std::string& cycle = "",
                     int lastCount = 3) {
    return R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [
    {"name": "root", "translation": [10, 0, 0], "children": [1, 2]},
    {"name": "a", "mesh": 0, "scale": [2, 2, 2]},
    {"name": "b", "mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,5,0,1], "children": [3]},
    {"name": "c", "mesh": 1, "rotation": [0, 0, 0.70710678, 0.70710678])" + cycle + R"(},
    {"name": "unused", "mesh": 1}
  ],
  "meshes": [
    {"name": "quad", "primitives": [
      {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "mode": 4},
      {"attributes": {"POSITION": 0}, "mode": 0},
      {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 3, "mode": 5}
    ]},
    {"name": "tri", "primitives": [{"attributes": {"POSITION": 0}, "indices": 4}]}
  ],
  "buffers": [{"byteLength": 124, "uri": ")" + uri + R"("}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 96, "byteStride": 24},
    {"buffer": 0, "byteOffset": 96, "byteLength": 12},
    {"buffer": 0, "byteOffset": 108, "byteLength": 4},
    {"buffer": 0, "byteOffset": 112, "byteLength": 12}
  ],
  "accessors": [
    {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]},
    {"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 4, "type": "VEC3"},
    {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
    {"bufferView": 2, "componentType": 5121, "count": 4, "type": "SCALAR"},
    {"bufferView": 3, "componentType": 5125, "count": )" + std::to_string(lastCount) + R"(, "type": "SCALAR")" +
           extraAccessor + R"(}
  ]
})";
}

std::string embedded(const std::string& bytes) { return "data:application/octet-stream;base64," + base64(bytes); }

void checkHierarchyScene(const Scene& s) {
    ASSERT_EQ(s.meshes.size(), 2u);  // "quad" shared by two nodes, "tri"; "unused" not in the scene
    ASSERT_EQ(s.instances.size(), 3u);
    const Mesh& quad = s.meshes[s.instances[0].mesh];
    EXPECT_EQ(quad.name, "quad");
    EXPECT_EQ(quad.triangleCount(), 4u);  // 2 from the list + 2 from the strip; points skipped
    EXPECT_EQ(quad.vertexCount(), 8u);
    EXPECT_EQ(quad.normals[5], glm::vec3(0, 0, 1));
    EXPECT_EQ(s.instances[0].mesh, s.instances[1].mesh);
    EXPECT_EQ(s.instances[0].name, "a");
    EXPECT_EQ(s.instances[2].name, "c");
    EXPECT_EQ(s.meshes[s.instances[2].mesh].triangleCount(), 1u);
    EXPECT_EQ(s.instancedTriangleCount(), 9u);

    // a = T(10,0,0) S(2): (1,1,0) -> (12,2,0)
    const glm::vec4 pa = s.instances[0].transform * glm::vec4(1, 1, 0, 1);
    EXPECT_NEAR(glm::distance(glm::vec3(pa), glm::vec3(12, 2, 0)), 0.0f, 1e-5f);
    // c = T(10,0,0) T(0,5,0) Rz(90): (1,0,0) -> (10,6,0)
    const glm::vec4 pc = s.instances[2].transform * glm::vec4(1, 0, 0, 1);
    EXPECT_NEAR(glm::distance(glm::vec3(pc), glm::vec3(10, 6, 0)), 0.0f, 1e-5f);
    // Strip winding is kept: every quad triangle faces +Z.
    for (std::size_t t = 0; t < quad.indices.size(); t += 3) {
        const glm::vec3 n = glm::cross(quad.positions[quad.indices[t + 1]] - quad.positions[quad.indices[t]],
                                       quad.positions[quad.indices[t + 2]] - quad.positions[quad.indices[t]]);
        EXPECT_GT(n.z, 0.0f) << "triangle " << t / 3;
    }
}

TEST(GltfLoader, EmbeddedBufferHierarchyAndSharedMesh) {
    TempDir dir;
    const auto path = dir.write("scene.gltf", gltfJson(embedded(bufferBytes())));
    auto r = loadGltf(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    checkHierarchyScene(*r);
}

TEST(GltfLoader, ExternalBinFile) {
    TempDir dir;
    dir.write("scene.bin", bufferBytes());
    const auto path = dir.write("scene.gltf", gltfJson("scene.bin"));
    auto r = loadScene(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    checkHierarchyScene(*r);
}

TEST(GltfLoader, BinaryGlb) {
    std::string json = gltfJson("x");
    const std::string uri = R"(, "uri": "x")";
    json.replace(json.find(uri), uri.size(), "");
    while (json.size() % 4) json += ' ';
    std::string bin = bufferBytes();
    while (bin.size() % 4) bin += '\0';
    std::string glb;
    put<std::uint32_t>(glb, 0x46546C67u, false);  // "glTF"
    put<std::uint32_t>(glb, 2, false);
    put<std::uint32_t>(glb, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()), false);
    put<std::uint32_t>(glb, static_cast<std::uint32_t>(json.size()), false);
    put<std::uint32_t>(glb, 0x4E4F534Au, false);  // "JSON"
    glb += json;
    put<std::uint32_t>(glb, static_cast<std::uint32_t>(bin.size()), false);
    put<std::uint32_t>(glb, 0x004E4942u, false);  // "BIN\0"
    glb += bin;
    TempDir dir;
    const auto path = dir.write("scene.GLB", glb);
    auto r = loadScene(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    checkHierarchyScene(*r);
}

TEST(GltfLoader, TruncatedJsonIsAnErrorNotACrash) {
    TempDir dir;
    const std::string full = gltfJson(embedded(bufferBytes()));
    for (std::size_t n = 1; n < full.size(); n += 17) {
        const auto path = dir.write("cut.gltf", full.substr(0, n));
        auto r = loadGltf(path);
        ASSERT_FALSE(r.ok()) << n;
        ASSERT_EQ(r.error().message.rfind(path.string(), 0), 0u) << r.error().message;
    }
}

TEST(GltfLoader, TruncatedBinFileIsAnError) {
    TempDir dir;
    dir.write("scene.bin", bufferBytes().substr(0, 100));
    const auto path = dir.write("scene.gltf", gltfJson("scene.bin"));
    auto r = loadGltf(path);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().message.rfind(path.string(), 0), 0u) << r.error().message;
}

TEST(GltfLoader, MissingFile) {
    TempDir dir;
    const auto path = dir.file("none.gltf");
    expectError(loadGltf(path), path, "not found");
}

TEST(GltfLoader, EmptyFile) {
    TempDir dir;
    const auto path = dir.write("e.gltf", "");
    expectError(loadGltf(path), path, "empty");
}

TEST(GltfLoader, InvalidJson) {
    TempDir dir;
    const auto path = dir.write("bad.gltf", "{ \"asset\": ");
    auto r = loadGltf(path);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().message.rfind(path.string(), 0), 0u) << r.error().message;
}

TEST(GltfLoader, NoMeshes) {
    TempDir dir;
    const auto path = dir.write("nomesh.gltf", R"({"asset": {"version": "2.0"}, "nodes": [{"name": "n"}]})");
    expectError(loadGltf(path), path, "no meshes");
}

TEST(GltfLoader, MissingBinFile) {
    TempDir dir;
    const auto path = dir.write("scene.gltf", gltfJson("missing.bin"));
    auto r = loadGltf(path);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().message.rfind(path.string(), 0), 0u) << r.error().message;
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
}

TEST(GltfLoader, IndexOutOfRange) {
    TempDir dir;
    const auto path = dir.write("range.gltf", gltfJson(embedded(bufferBytes(0.0f, 9))));
    expectError(loadGltf(path), path, "index 9 at position 2 out of range (4 vertices)");
}

TEST(GltfLoader, AccessorPastItsBufferView) {
    TempDir dir;
    const auto path = dir.write("past.gltf", gltfJson(embedded(bufferBytes()), "", "", 30));
    expectError(loadGltf(path), path, "past the end");
}

TEST(GltfLoader, SparseAccessorIsReported) {
    TempDir dir;
    const std::string sparse =
        R"(, "sparse": {"count": 1, "indices": {"bufferView": 3, "componentType": 5125}, "values": {"bufferView": 3}})";
    const auto path = dir.write("sparse.gltf", gltfJson(embedded(bufferBytes()), sparse));
    auto r = loadGltf(path);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("sparse"), std::string::npos) << r.error().message;
}

TEST(GltfLoader, NodeCycle) {
    TempDir dir;
    const auto path = dir.write("cycle.gltf", gltfJson(embedded(bufferBytes()), "", R"(, "children": [0])"));
    expectError(loadGltf(path), path, "reached twice");
}

TEST(GltfLoader, NanPosition) {
    TempDir dir;
    const auto path = dir.write("nan.gltf", gltfJson(embedded(bufferBytes(std::numeric_limits<float>::quiet_NaN()))));
    expectError(loadGltf(path), path, "non-finite");
}

}  // namespace
}  // namespace dyncull
