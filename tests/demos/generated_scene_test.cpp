// Generated scenes: deterministic for a seed, sizes in the expected ranges, valid meshes.
#include <cstdlib>
#include <map>

#include <gtest/gtest.h>

#include "demos_test_util.hpp"
#include "generators.hpp"

namespace dyncull {
namespace {

PowerPlantOptions smallPlant(std::uint64_t seed = 1) {
    PowerPlantOptions o;
    o.seed = seed;
    o.size = 0.08f;
    o.detail = 0.3f;
    return o;
}

TEST(PowerPlant, SameSeedSameScene) {
    auto a = generatePowerPlant(smallPlant(), nullptr);
    auto b = generatePowerPlant(smallPlant(), nullptr);
    auto c = generatePowerPlant(smallPlant(2), nullptr);
    ASSERT_TRUE(a && b && c);
    EXPECT_EQ(test::hashScene(*a), test::hashScene(*b));
    EXPECT_NE(test::hashScene(*a), test::hashScene(*c));
    EXPECT_EQ(powerPlantParamsHash(smallPlant()), powerPlantParamsHash(smallPlant()));
    EXPECT_NE(powerPlantParamsHash(smallPlant()), powerPlantParamsHash(smallPlant(2)));
    PowerPlantOptions frames = smallPlant();
    frames.frames = 17;  // the camera path is not part of the cached geometry
    EXPECT_EQ(powerPlantParamsHash(frames), powerPlantParamsHash(smallPlant()));
}

TEST(PowerPlant, SmallVariantIsValid) {
    auto s = generatePowerPlant(smallPlant(), nullptr);
    ASSERT_TRUE(s);
    EXPECT_GT(s->objects.size(), 50u);
    for (const Mesh& m : s->meshes) EXPECT_EQ(validateMesh(m), "") << m.name;
    for (const PlacedObject& o : s->objects) {
        ASSERT_LT(o.model, s->meshes.size());
        EXPECT_TRUE(validateTransform(o.transform).ok());
    }
}

TEST(PowerPlant, FullSizeCountsMatchTheUncPlant) {
    auto s = generatePowerPlant(PowerPlantOptions{}, nullptr);
    ASSERT_TRUE(s);
    if (std::getenv("DYNCULL_BREAKDOWN")) {
        std::map<std::string, std::pair<std::size_t, std::size_t>> by;
        for (const PlacedObject& o : s->objects) {
            std::string n = s->meshes[o.model].name;
            n = n.substr(0, n.find('_'));
            by[n].first += 1;
            by[n].second += s->meshes[o.model].triangleCount();
        }
        for (auto& [n, v] : by) std::printf("%-12s %5zu objects %9zu tris\n", n.c_str(), v.first, v.second);
    }
    // The UNC Power Plant: about 1,200 objects and 12.7M triangles.
    EXPECT_GE(s->objects.size(), 1100u);
    EXPECT_LE(s->objects.size(), 1300u);
    EXPECT_GE(s->instancedTriangles(), 11'500'000u);
    EXPECT_LE(s->instancedTriangles(), 14'000'000u);
    // Instancing where natural, but many distinct meshes (every pipe differs).
    EXPECT_GE(s->meshes.size(), 500u);
    EXPECT_LT(s->meshes.size(), s->objects.size());
}

TEST(PowerPlant, RejectsBadOptions) {
    PowerPlantOptions o;
    o.size = 0.0f;
    auto s = generatePowerPlant(o, nullptr);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("size"), std::string::npos);
    o = {};
    o.detail = 2.0f;
    EXPECT_FALSE(generatePowerPlant(o, nullptr));
}

TEST(City, FullSizeCountsAndDeterminism) {
    auto a = generateCity(CityOptions{}, nullptr);
    ASSERT_TRUE(a);
    std::size_t buildings = 0;
    for (const Mesh& m : a->meshes) buildings += m.name.rfind("building_", 0) == 0;
    EXPECT_EQ(buildings, 400u);
    EXPECT_GE(a->instancedTriangles(), 1'200'000u);
    EXPECT_LE(a->instancedTriangles(), 1'600'000u);
    CityOptions small;
    small.blocksX = 3;
    small.blocksZ = 2;
    auto b = generateCity(small, nullptr), c = generateCity(small, nullptr);
    ASSERT_TRUE(b && c);
    EXPECT_EQ(test::hashScene(*b), test::hashScene(*c));
    for (const Mesh& m : b->meshes) EXPECT_EQ(validateMesh(m), "") << m.name;
    small.blocksX = 0;
    EXPECT_FALSE(generateCity(small, nullptr));
}

}  // namespace
}  // namespace dyncull
