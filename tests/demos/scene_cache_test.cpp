// Scene cache: round trip, and every kind of damage (flipped byte, truncation, other
// version, other parameters, garbage) detected with a reason and then rebuilt.
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include <gtest/gtest.h>

#include "demos_test_util.hpp"
#include "generators.hpp"
#include "procedural_mesh.hpp"

namespace dyncull {
namespace {

PreparedScene smallPrepared() {
    PowerPlantOptions o;
    o.size = 0.05f;
    o.detail = 0.25f;
    auto g = generatePowerPlant(o, nullptr);
    EXPECT_TRUE(g);
    auto p = prepareScene(g.take(), 2, nullptr);
    EXPECT_TRUE(p);
    return p.take();
}

std::vector<char> readAll(const std::filesystem::path& p) {
    std::ifstream f(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void writeAll(const std::filesystem::path& p, const std::vector<char>& data) {
    std::ofstream f(p, std::ios::binary | std::ios::trunc);
    f.write(data.data(), static_cast<std::streamsize>(data.size()));
}

class SceneCache : public ::testing::Test {
protected:
    static void SetUpTestSuite() { scene_ = new PreparedScene(smallPrepared()); }
    static void TearDownTestSuite() { delete scene_; }
    static PreparedScene* scene_;
    test::TempDir dir_;
};
PreparedScene* SceneCache::scene_ = nullptr;

TEST_F(SceneCache, RoundTripIsExact) {
    const auto file = dir_.path() / "a.dcs";
    ASSERT_TRUE(writeSceneCache(file, *scene_, 77).ok());
    auto back = readSceneCache(file, 77);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->models.size(), scene_->models.size());
    EXPECT_EQ(back->objects.size(), scene_->objects.size());
    EXPECT_EQ(test::hashScene(*back), test::hashScene(*scene_));
    EXPECT_EQ(back->models[0].stats.leaves, scene_->models[0].stats.leaves);
}

TEST_F(SceneCache, DamageIsDetectedWithAReason) {
    const auto file = dir_.path() / "a.dcs";
    ASSERT_TRUE(writeSceneCache(file, *scene_, 77).ok());
    const std::vector<char> good = readAll(file);
    ASSERT_GT(good.size(), kSceneCacheHeaderSize + 100);

    auto expectError = [&](const std::vector<char>& bytes, const std::string& why, std::uint64_t hash = 77) {
        writeAll(file, bytes);
        auto r = readSceneCache(file, hash);
        ASSERT_FALSE(r) << why;
        EXPECT_NE(r.error().message.find(why), std::string::npos) << r.error().message;
        EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    };
    std::vector<char> flipped = good;
    flipped[good.size() / 2] ^= 0x10;
    expectError(flipped, "checksum");
    expectError(std::vector<char>(good.begin(), good.begin() + static_cast<long>(good.size() - 9)), "truncated");
    expectError(std::vector<char>(good.begin(), good.begin() + 20), "truncated header");
    std::vector<char> version = good;
    version[8] = 99;
    expectError(version, "format version");
    expectError(good, "stale", 78);
    std::vector<char> magic = good;
    magic[0] = 'X';
    expectError(magic, "magic");
    std::vector<char> padded = good;
    padded.push_back(0);
    expectError(padded, "truncated or padded");
}

TEST_F(SceneCache, MalformedPayloadWithValidChecksumIsRejected) {
    // A hostile file can carry a correct checksum: the payload itself must be checked.
    const auto file = dir_.path() / "a.dcs";
    PreparedScene bad;
    bad.models.push_back(scene_->models[0]);
    bad.objects.push_back({0, Transform{}, true});
    bad.models[0].mesh.indices[0] = 1u << 30;  // index out of range
    ASSERT_TRUE(writeSceneCache(file, bad, 5).ok());
    auto r = readSceneCache(file, 5);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("model 0"), std::string::npos) << r.error().message;

    bad.models[0] = scene_->models[0];
    bad.models[0].nodes[0].subtreeSize = 1000000;
    ASSERT_TRUE(writeSceneCache(file, bad, 5).ok());
    EXPECT_FALSE(readSceneCache(file, 5));

    bad.models[0] = scene_->models[0];
    bad.objects[0].model = 3;  // no such model
    ASSERT_TRUE(writeSceneCache(file, bad, 5).ok());
    EXPECT_FALSE(readSceneCache(file, 5));

    bad.objects[0].model = 0;
    bad.objects[0].transform.scale = glm::vec3(0.0f);
    ASSERT_TRUE(writeSceneCache(file, bad, 5).ok());
    EXPECT_FALSE(readSceneCache(file, 5));
}

TEST_F(SceneCache, GarbageNeverCrashes) {
    const auto file = dir_.path() / "g.dcs";
    procedural::Rng rng(9);
    const std::vector<char> good = [&] {
        EXPECT_TRUE(writeSceneCache(file, *scene_, 1).ok());
        return readAll(file);
    }();
    for (int trial = 0; trial < 40; ++trial) {
        std::vector<char> bytes = good;
        // Corrupt payload bytes and then fix the checksum, so the parser sees the damage.
        for (int k = 0; k < 4; ++k)
            bytes[kSceneCacheHeaderSize + static_cast<std::size_t>(rng.range(0, static_cast<int>(bytes.size() - kSceneCacheHeaderSize) - 1))] =
                static_cast<char>(rng.range(0, 255));
        const std::uint64_t sum = fnv1a64(bytes.data() + kSceneCacheHeaderSize, bytes.size() - kSceneCacheHeaderSize);
        std::memcpy(bytes.data() + 32, &sum, 8);
        writeAll(file, bytes);
        auto r = readSceneCache(file, 1);
        if (r) {
            EXPECT_EQ(r->models.size(), scene_->models.size());  // harmless flips (e.g. in a float) may pass
        }
    }
}

TEST_F(SceneCache, LoadOrPrepareRebuildsDamagedCache) {
    SceneCacheOptions cache;
    cache.dir = dir_.path().string();
    PowerPlantOptions o;
    o.size = 0.05f;
    o.detail = 0.25f;
    int generated = 0;
    auto gen = [&](ProgressBar&) {
        ++generated;
        return generatePowerPlant(o, nullptr);
    };
    auto first = loadOrPrepare(cache, "p.dcs", 11, 2, gen, nullptr);
    ASSERT_TRUE(first);
    EXPECT_EQ(generated, 1);
    std::string log;
    auto second = loadOrPrepare(cache, "p.dcs", 11, 2, gen, &log);
    ASSERT_TRUE(second);
    EXPECT_EQ(generated, 1) << "second run must come from the cache";
    EXPECT_NE(log.find("loaded"), std::string::npos);
    EXPECT_EQ(test::hashScene(*first), test::hashScene(*second));

    std::vector<char> bytes = readAll(dir_.path() / "p.dcs");
    bytes[bytes.size() - 3] ^= 1;
    writeAll(dir_.path() / "p.dcs", bytes);
    auto third = loadOrPrepare(cache, "p.dcs", 11, 2, gen, nullptr);
    ASSERT_TRUE(third);
    EXPECT_EQ(generated, 2);
    EXPECT_EQ(test::hashScene(*third), test::hashScene(*first));
    EXPECT_TRUE(readSceneCache(dir_.path() / "p.dcs", 11)) << "the rebuilt cache was written back";

    auto stale = loadOrPrepare(cache, "p.dcs", 12, 2, gen, nullptr);  // other parameters
    ASSERT_TRUE(stale);
    EXPECT_EQ(generated, 3);

    cache.enabled = false;
    ASSERT_TRUE(loadOrPrepare(cache, "p.dcs", 12, 2, gen, nullptr));
    EXPECT_EQ(generated, 4);
}

TEST(SceneCacheFile, TinySceneRoundTripsAndSeedsTheFuzzer) {
    // Two small models (a box and a box split by its local BSP) and three objects: the
    // smallest cache that exercises every record. With $DYNCULL_FUZZ_SEEDS set
    // (scripts/fuzz.sh) it is also the scene-cache fuzzer's seed.
    GeneratedScene g;
    g.meshes.resize(2);
    procedural::MeshBuilder(g.meshes[0]).box(glm::vec3(-1.0f), glm::vec3(1.0f));
    procedural::MeshBuilder two(g.meshes[1]);
    two.box(glm::vec3(-1.0f), glm::vec3(0.0f));
    two.box(glm::vec3(0.5f), glm::vec3(2.0f));
    Transform t;
    g.objects.push_back({0, t, true});
    t.translation = {3.0f, 0.0f, 0.0f};
    g.objects.push_back({1, t, false});
    t.scale = glm::vec3(2.0f);
    g.objects.push_back({1, t, true});
    auto p = prepareScene(std::move(g), 1, nullptr);
    ASSERT_TRUE(p) << p.error().message;
    test::TempDir dir;
    const auto file = dir.path() / "tiny.dcs";
    ASSERT_TRUE(writeSceneCache(file, *p, 3).ok());
    auto back = readSceneCache(file, 3);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(test::hashScene(*back), test::hashScene(*p));
    if (const char* seeds = std::getenv("DYNCULL_FUZZ_SEEDS"); seeds && *seeds) {
        const auto out = std::filesystem::path(seeds) / "dcs";
        std::filesystem::create_directories(out);
        std::filesystem::copy_file(file, out / "tiny.dcs", std::filesystem::copy_options::overwrite_existing);
    }
}

TEST(SceneCacheFile, MissingFileIsAnError) {
    auto r = readSceneCache("/nonexistent/dyncull/x.dcs", 1);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("cannot open"), std::string::npos);
}

TEST(SceneCacheFile, PreparedSceneMatchesGeneratedCounts) {
    PowerPlantOptions o;
    o.size = 0.05f;
    o.detail = 0.25f;
    auto g = generatePowerPlant(o, nullptr);
    ASSERT_TRUE(g);
    const std::size_t objects = g->objects.size(), meshes = g->meshes.size(), tris = g->instancedTriangles();
    auto p = prepareScene(g.take(), 2, nullptr);
    ASSERT_TRUE(p);
    EXPECT_EQ(p->objects.size(), objects);
    EXPECT_EQ(p->models.size(), meshes);
    EXPECT_GE(p->instancedTriangles(), tris);  // splitting only adds triangles
}

// Issue 19: a cache with a valid checksum is still checked field by field.
class SceneCacheContent : public SceneCache {
protected:
    std::filesystem::path file() const { return dir_.path() / "c.dcs"; }
    // One model with normals and a split root, placed once: known offsets, every record present.
    static PreparedScene oneModel() {
        PreparedScene one;
        for (const LocalBsp& b : scene_->models)
            if (b.nodes.size() > 1 && !b.mesh.normals.empty() && b.mesh.positions.size() > 4) {
                one.models.push_back(b);
                break;
            }
        EXPECT_EQ(one.models.size(), 1u);
        one.objects.push_back({0, Transform{}, true});
        return one;
    }
    std::string readError() const {
        auto r = readSceneCache(file(), 5);
        return r ? std::string() : r.error().message;
    }
    void expectRefused(const std::string& what) const {
        const std::string e = readError();
        EXPECT_NE(e.find(what), std::string::npos) << "expected '" << what << "' in: " << e;
        EXPECT_EQ(e.rfind("scene cache " + file().string() + ": ", 0), 0u) << e;
        EXPECT_EQ(e.find("checksum"), std::string::npos) << e;
    }
    // Rewrites `bytes` with `value` at `offset` and a matching checksum.
    template <class T>
    void patch(std::vector<char> bytes, std::size_t offset, T value) const {
        ASSERT_LE(offset + sizeof(T), bytes.size());
        std::memcpy(bytes.data() + offset, &value, sizeof(T));
        const std::uint64_t sum = fnv1a64(bytes.data() + kSceneCacheHeaderSize, bytes.size() - kSceneCacheHeaderSize);
        std::memcpy(bytes.data() + 32, &sum, 8);
        writeAll(file(), bytes);
    }
};

TEST_F(SceneCacheContent, NanOrZeroNormalsAndNanPositionsAreRefused) {
    const PreparedScene good = oneModel();
    ASSERT_EQ(good.models.size(), 1u);
    ASSERT_TRUE(writeSceneCache(file(), good, 5).ok());
    ASSERT_EQ(readError(), "");
    PreparedScene bad = good;
    for (float v : {NAN, INFINITY}) {
        bad.models[0].mesh.normals[2].x = v;
        ASSERT_TRUE(writeSceneCache(file(), bad, 5).ok());
        expectRefused("model 0: normal 2 is not finite");
        bad = good;
    }
    bad.models[0].mesh.normals[4] = glm::vec3(0.0f);
    ASSERT_TRUE(writeSceneCache(file(), bad, 5).ok());
    expectRefused("model 0: normal 4 has zero length");
    bad = good;
    bad.models[0].mesh.positions[1].y = NAN;
    ASSERT_TRUE(writeSceneCache(file(), bad, 5).ok());
    expectRefused("model 0: vertex 1 has a non-finite coordinate");
    bad = good;
    bad.models[0].stats.buildMs = NAN;
    ASSERT_TRUE(writeSceneCache(file(), bad, 5).ok());
    expectRefused("model 0: build time is not a finite duration");
}

TEST_F(SceneCacheContent, CountsAndRangesNear2To32AreRefused) {
    const PreparedScene scene = oneModel();
    ASSERT_EQ(scene.models.size(), 1u);
    ASSERT_TRUE(writeSceneCache(file(), scene, 5).ok());
    const std::vector<char> good = readAll(file());
    const Mesh& m = scene.models[0].mesh;
    const std::size_t H = kSceneCacheHeaderSize;
    const std::size_t name = H + 4;
    const std::size_t positions = name + 4 + m.name.size();
    const std::size_t normals = positions + 4 + 12 * m.positions.size();
    const std::size_t indices = normals + 4 + 12 * m.normals.size();
    const std::size_t nodes = indices + 4 + 4 * m.indices.size();
    const std::size_t root = nodes + 4;  // box 24, children 2 x 4, firstIndex, indexCount, subtreeSize, split, axis, depth
    const std::size_t objects = good.size() - 4 - 45 * scene.objects.size();
    for (std::uint32_t n : {0xFFFFFFFFu, 0xFFFFFFFEu, 0x80000000u}) {
        SCOPED_TRACE(n);
        patch(good, H, n);
        expectRefused("model count out of range");
        patch(good, name, n);
        expectRefused("model 0: truncated mesh");
        patch(good, positions, n);
        expectRefused("model 0: truncated mesh");
        patch(good, normals, n);
        expectRefused("model 0: truncated mesh");
        patch(good, indices, n);
        expectRefused("model 0: truncated mesh");
        patch(good, nodes, n);
        expectRefused("model 0: node count out of range");
        patch(good, objects, n);
        expectRefused("object count out of range");
        for (std::size_t field : {24u, 28u, 32u, 36u, 40u}) {
            patch(good, root + field, n);
            expectRefused("model 0: node 0: ");
        }
        patch(good, good.size() - 45, n);  // the last object's model
        expectRefused("model out of range");
    }
    for (std::uint64_t payload : {std::uint64_t{0xFFFFFFFF}, std::uint64_t{1} << 32, ~std::uint64_t{0}}) {
        std::vector<char> b = good;
        std::memcpy(b.data() + 24, &payload, 8);
        writeAll(file(), b);
        EXPECT_NE(readError().find("truncated or padded: header says " + std::to_string(payload)), std::string::npos)
            << readError();
    }
}

}  // namespace
}  // namespace dyncull
