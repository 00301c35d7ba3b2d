#include <string>

#include <gtest/gtest.h>

#include "dyncull/loaders/loaders.hpp"
#include "dyncull/objects/file_extension.hpp"
#include "objects/test_files.hpp"

namespace dyncull {
namespace {

using test::TempDir;

const char* kTriPly =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

TEST(SceneLoader, DispatchIsCaseInsensitive) {
    TempDir dir;
    for (const char* name : {"a.ply", "b.PLY", "c.Ply"}) {
        auto r = loadScene(dir.write(name, kTriPly));
        ASSERT_TRUE(r.ok()) << r.error().message;
        EXPECT_EQ(r->uniqueTriangleCount(), 1u);
    }
    auto obj = loadScene(dir.write("d.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
    ASSERT_TRUE(obj.ok()) << obj.error().message;
    EXPECT_EQ(obj->uniqueTriangleCount(), 1u);
}

// The one extension convention: the last dot's suffix, ASCII lowercase; none for a name
// without a dot or a dot file ("" then: the loaders say "no file extension").
TEST(SceneLoader, ExtensionsAreComparedInLowercase) {
    EXPECT_EQ(lowercaseExtension("Bunny.PLY"), ".ply");
    EXPECT_EQ(lowercaseExtension("dir.GLTF/Model.GlB"), ".glb");
    EXPECT_EQ(lowercaseExtension("campus.tar.DNODES"), ".dnodes");
    EXPECT_EQ(lowercaseExtension("noextension"), "");
    EXPECT_EQ(lowercaseExtension(".hidden"), "");
    EXPECT_EQ(lowercaseExtension("trailing."), ".");
    EXPECT_EQ(lowercaseExtension("caf\xc3\xa9.\xc3\x89"), ".\xc3\x89") << "bytes outside ASCII are kept as they are";
}

TEST(SceneLoader, UnknownExtension) {
    TempDir dir;
    const auto path = dir.write("mesh.stl", "solid x\n");
    auto r = loadScene(path);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().message.rfind(path.string(), 0), 0u);
    EXPECT_NE(r.error().message.find("unknown format '.stl'"), std::string::npos) << r.error().message;
}

TEST(SceneLoader, NoExtension) {
    TempDir dir;
    const auto path = dir.write("mesh", kTriPly);
    auto r = loadScene(path);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("no file extension"), std::string::npos) << r.error().message;
}

TEST(SceneLoader, PlyContentWithWrongExtensionIsAnErrorNotACrash) {
    TempDir dir;
    const auto path = dir.write("mesh.gltf", kTriPly);
    auto r = loadScene(path);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().message.rfind(path.string(), 0), 0u) << r.error().message;
}

}  // namespace
}  // namespace dyncull
