// The file-scene camera choice: walk through elongated interiors, orbit everything else.
#include <algorithm>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "file_camera.hpp"
#include "procedural_mesh.hpp"

namespace dyncull {
namespace {

using procedural::MeshBuilder;

Scene oneMeshScene(Mesh mesh) {
    Scene s;
    s.meshes.push_back(std::move(mesh));
    s.instances.push_back({0, glm::mat4(1.0f), "m"});
    return s;
}

// A 20 x 4 x 6 hall: the box primitive with its winding reversed, so every face
// points into the room, as an architectural model's walls do.
Scene hall() {
    Mesh m;
    MeshBuilder(m).box({0, 0, 0}, {20, 4, 6});
    for (std::size_t t = 0; t < m.indices.size(); t += 3) std::swap(m.indices[t + 1], m.indices[t + 2]);
    for (glm::vec3& n : m.normals) n = -n;
    return oneMeshScene(std::move(m));
}

TEST(FileCamera, ElongatedInteriorIsWalkedThrough) {
    const Scene s = hall();
    const FileCameraChoice c = chooseFileCamera(s, s.worldBounds());
    EXPECT_TRUE(c.walkthrough);
    EXPECT_DOUBLE_EQ(c.enclosedFraction, 1.0);  // closed room: every ray meets a wall's front
}

TEST(FileCamera, ElongatedSolidIsOrbited) {
    Mesh m;
    MeshBuilder(m).box({0, 0, 0}, {20, 4, 6});  // outward faces: the walk runs inside a solid
    const Scene s = oneMeshScene(std::move(m));
    const FileCameraChoice c = chooseFileCamera(s, s.worldBounds());
    EXPECT_FALSE(c.walkthrough);
    EXPECT_DOUBLE_EQ(c.enclosedFraction, 0.0);  // every ray meets a back face
}

TEST(FileCamera, CompactModelIsOrbitedWithoutRayCasting) {
    Mesh m;
    MeshBuilder(m).box({0, 0, 0}, {4, 4, 4});
    const Scene s = oneMeshScene(std::move(m));
    const FileCameraChoice c = chooseFileCamera(s, s.worldBounds());
    EXPECT_FALSE(c.walkthrough);
    EXPECT_FALSE(c.elongated);
    EXPECT_EQ(c.enclosedFraction, 0.0);
}

TEST(FileCamera, MirroredInstanceKeepsItsFrontFaces) {
    // A mirroring transform flips the winding; the hall must still read as an interior.
    Scene s = hall();
    s.instances[0].transform = glm::scale(glm::mat4(1.0f), glm::vec3(-1.0f, 1.0f, 1.0f));
    const FileCameraChoice c = chooseFileCamera(s, s.worldBounds());
    EXPECT_TRUE(c.walkthrough);
}

TEST(FileCamera, EmptyAndDegenerateScenesAreOrbited) {
    Scene empty;
    EXPECT_FALSE(chooseFileCamera(empty, Aabb{}).walkthrough);
    Mesh flat;  // zero-area triangles only
    flat.positions = {{0, 0, 0}, {10, 0, 0}, {20, 0, 0}, {0, 0, 1}};
    flat.indices = {0, 1, 2, 0, 1, 2};
    const Scene s = oneMeshScene(std::move(flat));
    const FileCameraChoice c = chooseFileCamera(s, Aabb{{0, 0, 0}, {20, 2, 1}});
    EXPECT_FALSE(c.walkthrough);
    EXPECT_EQ(c.enclosedFraction, 0.0);
}

TEST(FileCamera, DirectionsAreUnitAndSpread) {
    const std::vector<glm::vec3> d = sphereDirections(48);
    ASSERT_EQ(d.size(), 48u);
    glm::vec3 sum(0.0f);
    for (const glm::vec3& v : d) {
        EXPECT_NEAR(glm::length(v), 1.0f, 1e-5f);
        sum += v;
    }
    EXPECT_LT(glm::length(sum) / 48.0f, 0.05f);  // balanced over the sphere
}

}  // namespace
}  // namespace dyncull
