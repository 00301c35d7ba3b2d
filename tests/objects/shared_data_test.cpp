// Loads the real files of ../shared/data (or $DYNCULL_DATA); skipped when absent.
#include <chrono>
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "dyncull/loaders/loaders.hpp"

namespace dyncull {
namespace {

std::filesystem::path dataFile(const char* name) {
    std::filesystem::path dir;
    if (const char* env = std::getenv("DYNCULL_DATA"); env && *env) dir = env;
    else dir = DYNCULL_SHARED_DATA_DIR;
    return dir / name;
}

#define REQUIRE_DATA(path) \
    if (!std::filesystem::exists(path)) GTEST_SKIP() << (path) << " not available"

TEST(SharedData, StanfordBunnyPly) {
    const auto path = dataFile("bun_zipper.ply");
    REQUIRE_DATA(path);
    const auto t0 = std::chrono::steady_clock::now();
    auto r = loadScene(path);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->meshes.size(), 1u);
    EXPECT_EQ(r->meshes[0].vertexCount(), 35947u);
    EXPECT_EQ(r->meshes[0].triangleCount(), 69451u);
    EXPECT_LT(ms, 1000.0);  // whole-file read + from_chars; tens of ms on a slow core
    RecordProperty("load_ms", static_cast<int>(ms));
}

TEST(SharedData, TwoCylinderEngineGltf) {
    const auto path = dataFile("2CylinderEngine.gltf");
    REQUIRE_DATA(path);
    auto r = loadScene(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->instances.size(), 67u);
    EXPECT_EQ(r->meshes.size(), 29u);
    EXPECT_EQ(r->instancedTriangleCount(), 121496u);
    EXPECT_EQ(r->uniqueTriangleCount(), 75730u);
    EXPECT_EQ(r->origin, glm::dvec3(0.0));  // near its file's origin: instances keep file coordinates
}

TEST(SharedData, SponzaGltf) {
    const auto path = dataFile("sponza_dabrovic.gltf");
    REQUIRE_DATA(path);
    auto r = loadScene(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->instances.size(), 34u);
    EXPECT_EQ(r->instancedTriangleCount(), 66454u);
    EXPECT_EQ(r->origin, glm::dvec3(0.0));
}

}  // namespace
}  // namespace dyncull
