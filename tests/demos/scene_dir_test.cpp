// Directory scenes: every .ply/.obj under a directory, sorted, one object each.
#include <fstream>

#include <gtest/gtest.h>

#include "demos_test_util.hpp"
#include "generators.hpp"

namespace dyncull {
namespace {

void writeTetraPly(const std::filesystem::path& p, float offset) {
    std::ofstream f(p);
    f << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
         "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
    f << offset << " 0 0\n" << offset + 1 << " 0 0\n" << offset << " 1 0\n" << offset << " 0 1\n";
    f << "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
}

void writeQuadObj(const std::filesystem::path& p) {
    std::ofstream f(p);
    f << "o a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\no b\nv 0 0 2\nv 1 0 2\nv 1 1 2\nf 5 6 7\n";
}

TEST(SceneDir, LoadsEveryPartSortedAsOneObjectEach) {
    test::TempDir dir;
    std::filesystem::create_directories(dir.path() / "sub");
    writeTetraPly(dir.path() / "b.ply", 0.0f);
    writeTetraPly(dir.path() / "A.PLY", 5.0f);
    writeQuadObj(dir.path() / "sub" / "c.obj");
    std::ofstream(dir.path() / "readme.txt") << "not a model";
    auto s = loadSceneDir(dir.path().string(), nullptr);
    ASSERT_TRUE(s) << s.error().message;
    ASSERT_EQ(s->meshes.size(), 3u);
    ASSERT_EQ(s->objects.size(), 3u);
    EXPECT_EQ(s->meshes[0].name, "A.PLY");
    EXPECT_EQ(s->meshes[1].name, "b.ply");
    EXPECT_EQ(s->meshes[2].name, "sub/c.obj");
    EXPECT_EQ(s->meshes[0].triangleCount(), 4u);
    EXPECT_EQ(s->meshes[2].triangleCount(), 3u);  // both OBJ shapes merged into one mesh
    EXPECT_FLOAT_EQ(s->meshes[0].bounds().min.x, 5.0f);
    for (std::uint32_t i = 0; i < 3; ++i) {
        EXPECT_EQ(s->objects[i].model, i);
        EXPECT_TRUE(s->objects[i].isStatic);
    }
    auto p = prepareScene(s.take(), 2, nullptr);
    ASSERT_TRUE(p);
    EXPECT_EQ(p->models.size(), 3u);
}

TEST(SceneDir, ErrorsNameTheProblem) {
    test::TempDir dir;
    auto empty = loadSceneDir(dir.path().string(), nullptr);
    ASSERT_FALSE(empty);
    EXPECT_NE(empty.error().message.find("no .ply or .obj"), std::string::npos);
    auto missing = loadSceneDir((dir.path() / "nope").string(), nullptr);
    ASSERT_FALSE(missing);
    EXPECT_NE(missing.error().message.find("not a directory"), std::string::npos);
    std::ofstream(dir.path() / "bad.ply") << "ply\nformat ascii 1.0\nelement vertex 99\n";
    auto bad = loadSceneDir(dir.path().string(), nullptr);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("bad.ply"), std::string::npos);
}

TEST(SceneDir, MakeSceneResolvesDirectoriesAndBuiltins) {
    test::TempDir dir;
    writeTetraPly(dir.path() / "x.ply", 0.0f);
    SceneOptions o;
    auto asPath = makeScene(dir.path().string(), o);
    ASSERT_TRUE(asPath);
    o.sceneDir = dir.path().string();
    auto asPlant = makeScene("powerplant", o);
    ASSERT_TRUE(asPlant);
    EXPECT_EQ((*asPlant)->name(), (*asPath)->name());
    o.sceneDir = (dir.path() / "missing").string();
    EXPECT_FALSE(makeScene("powerplant", o));
    o.sceneDir.clear();
    auto plant = makeScene("powerplant", o);
    ASSERT_TRUE(plant);
    EXPECT_EQ((*plant)->name(), "powerplant");
    EXPECT_GE((*plant)->defaultFrames(), 250u);
    auto city = makeScene("city", o);
    ASSERT_TRUE(city);
    EXPECT_EQ((*city)->name(), "city");
    const auto names = builtinSceneNames();
    EXPECT_NE(std::find(names.begin(), names.end(), "city"), names.end());
}

}  // namespace
}  // namespace dyncull
