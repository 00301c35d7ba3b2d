// Static-model subdivision (p-HBVO, D-BVS, load-balanced octree, regular octree): every
// method checked by the brute-force validator (each triangle once, limits, tight boxes),
// determinism across thread counts, the exact p-HBVO sweep against an O(n^2) search,
// degenerate inputs, the 4-ary collapse, leaf models and the subdivision file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "dyncull/bsp/subdivision.hpp"
#include "dyncull/bsp/subdivision_file.hpp"
#include "dyncull/objects/checksum.hpp"

namespace dyncull {
namespace {

constexpr SubdivisionMethod kMethods[] = {SubdivisionMethod::Phbvo, SubdivisionMethod::Dbvs,
                                          SubdivisionMethod::Octree, SubdivisionMethod::Grid};

/// `clusters` clumps of small random triangles in a 100-unit cube, plus `floors` huge
/// triangles spanning it (a factory floor). Three unique vertices per triangle.
Mesh clusteredSoup(std::uint32_t clusters, std::uint32_t perCluster, std::uint32_t floors, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    Mesh m;
    m.name = "soup";
    auto tri = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c) {
        const auto base = static_cast<std::uint32_t>(m.positions.size());
        m.positions.insert(m.positions.end(), {a, b, c});
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
    };
    for (std::uint32_t k = 0; k < clusters; ++k) {
        const glm::vec3 centre(100.0f * unit(rng), 100.0f * unit(rng), 100.0f * unit(rng));
        for (std::uint32_t i = 0; i < perCluster; ++i) {
            const glm::vec3 p = centre + 3.0f * glm::vec3(unit(rng), unit(rng), unit(rng));
            tri(p, p + glm::vec3(unit(rng), 0, 0), p + glm::vec3(0, unit(rng), unit(rng)));
        }
    }
    for (std::uint32_t i = 0; i < floors; ++i) {
        const float y = float(i);
        tri({-1, y, -1}, {104, y, -1}, {-1, y, 104});
    }
    computeNormals(m);
    return m;
}

SubdivisionParams params(SubdivisionMethod method, std::uint32_t maxLeaf, unsigned threads = 2) {
    SubdivisionParams p;
    p.method = method;
    p.maxLeafTriangles = maxLeaf;
    p.threads = threads;
    return p;
}

bool sameNodes(const Subdivision& a, const Subdivision& b) {
    if (a.nodes.size() != b.nodes.size() || a.triangles != b.triangles) return false;
    for (std::size_t i = 0; i < a.nodes.size(); ++i) {
        const SubdivisionNode &x = a.nodes[i], &y = b.nodes[i];
        if (x.firstChild != y.firstChild || x.childCount != y.childCount || x.firstTriangle != y.firstTriangle ||
            x.triangleCount != y.triangleCount || x.depth != y.depth || x.box.min != y.box.min || x.box.max != y.box.max)
            return false;
    }
    return true;
}

TEST(Subdivision, EveryMethodPassesTheOracle) {
    const Mesh mesh = clusteredSoup(40, 150, 3, 7);
    for (SubdivisionMethod method : kMethods) {
        for (std::uint32_t collapse : {0u, 4u}) {
            SubdivisionParams p = params(method, 200);
            p.collapseTo = collapse;
            auto sub = subdivide(mesh, p);
            ASSERT_TRUE(sub) << sub.error().message;
            EXPECT_EQ(validateSubdivision(mesh, *sub, p.maxLeafTriangles, p.maxDepth), "") << toString(method);
            EXPECT_GE(sub->stats.leaves, mesh.triangleCount() / 200) << toString(method);
            EXPECT_LE(sub->stats.largestLeaf, 200u) << toString(method);
            EXPECT_EQ(sub->stats.oversizedLeaves, 0u);
            if (collapse) {
                EXPECT_LE(sub->stats.maxChildren, method == SubdivisionMethod::Dbvs ? 17u : 8u);
            }
            if (method == SubdivisionMethod::Phbvo) {
                EXPECT_EQ(sub->stats.maxChildren, collapse ? 4u : 2u);
            }
        }
    }
}

TEST(Subdivision, DeterministicForAnyThreadCountAcrossTheParallelGrain) {
    // 90,000 triangles: above the 65,536-triangle grain, so subtrees run on other threads.
    const Mesh mesh = clusteredSoup(60, 1500, 2, 11);
    for (SubdivisionMethod method : kMethods) {
        auto one = subdivide(mesh, params(method, 1000, 1));
        auto two = subdivide(mesh, params(method, 1000, 2));
        auto four = subdivide(mesh, params(method, 1000, 4));
        ASSERT_TRUE(one && two && four);
        EXPECT_TRUE(sameNodes(*one, *two)) << toString(method);
        EXPECT_TRUE(sameNodes(*one, *four)) << toString(method);
        EXPECT_EQ(validateSubdivision(mesh, *two, 1000, 32), "") << toString(method);
    }
}

TEST(Subdivision, ExactPhbvoSweepMatchesBruteForce) {
    for (std::uint32_t seed = 1; seed <= 20; ++seed) {
        const Mesh mesh = clusteredSoup(3, 12 + seed, seed % 3, seed);
        std::vector<std::uint32_t> tris(mesh.triangleCount());
        for (std::uint32_t i = 0; i < tris.size(); ++i) tris[i] = (i * 7919u) % static_cast<std::uint32_t>(tris.size());
        std::sort(tris.begin(), tris.end());
        tris.erase(std::unique(tris.begin(), tris.end()), tris.end());
        const PhbvoSplit fast = phbvoBestSplitSorted(mesh, tris);
        const PhbvoSplit slow = phbvoBestSplitBruteForce(mesh, tris);
        EXPECT_EQ(fast.axis, slow.axis) << "seed " << seed;
        EXPECT_EQ(fast.left, slow.left) << "seed " << seed;
        EXPECT_EQ(fast.cost, slow.cost) << "seed " << seed;
        EXPECT_GE(fast.axis, 0);
    }
    // Equal barycentres: no plane separates them.
    Mesh same = clusteredSoup(0, 0, 0, 1);
    for (int i = 0; i < 5; ++i) {
        const auto b = static_cast<std::uint32_t>(same.positions.size());
        same.positions.insert(same.positions.end(), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
        same.indices.insert(same.indices.end(), {b, b + 1, b + 2});
    }
    const std::vector<std::uint32_t> all = {0, 1, 2, 3, 4};
    EXPECT_EQ(phbvoBestSplitSorted(same, all).axis, -1);
    EXPECT_EQ(phbvoBestSplitBruteForce(same, all).axis, -1);
}

TEST(Subdivision, BinnedAndExactPhbvoBothValid) {
    const Mesh mesh = clusteredSoup(30, 100, 1, 3);
    for (std::uint32_t exactBelow : {0u, 100000u}) {
        SubdivisionParams p = params(SubdivisionMethod::Phbvo, 64);
        p.exactBelow = exactBelow;
        auto sub = subdivide(mesh, p);
        ASSERT_TRUE(sub);
        EXPECT_EQ(validateSubdivision(mesh, *sub, 64, p.maxDepth), "");
    }
}

TEST(Subdivision, PhbvoFindsTheClusters) {
    // Eight far-apart clusters of 100 triangles and a 100-triangle limit: SAH cuts between
    // clusters, so each leaf is one cluster (the paper's "polygons of individual objects
    // are detected and clustered together").
    Mesh mesh;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (int k = 0; k < 8; ++k) {
        const glm::vec3 c(float(k & 1) * 100.0f, float((k >> 1) & 1) * 100.0f, float(k >> 2) * 100.0f);
        for (int i = 0; i < 100; ++i) {
            const glm::vec3 p = c + glm::vec3(unit(rng), unit(rng), unit(rng));
            const auto b = static_cast<std::uint32_t>(mesh.positions.size());
            mesh.positions.insert(mesh.positions.end(), {p, p + glm::vec3(0.1f, 0, 0), p + glm::vec3(0, 0.1f, 0)});
            mesh.indices.insert(mesh.indices.end(), {b, b + 1, b + 2});
        }
    }
    auto sub = subdivide(mesh, params(SubdivisionMethod::Phbvo, 100));
    ASSERT_TRUE(sub);
    EXPECT_EQ(sub->stats.leaves, 8u);
    for (const SubdivisionNode& n : sub->nodes)
        if (n.isLeaf()) {
            EXPECT_LT(n.box.extent().x, 2.0f);
        }
}

TEST(Subdivision, DbvsPullsUpTheFloorNearTheRoot) {
    const Mesh mesh = clusteredSoup(30, 100, 1, 9);
    const std::uint32_t floor = static_cast<std::uint32_t>(mesh.triangleCount()) - 1;
    auto sub = subdivide(mesh, params(SubdivisionMethod::Dbvs, 50));
    ASSERT_TRUE(sub);
    ASSERT_EQ(validateSubdivision(mesh, *sub, 50, 32), "");
    for (const SubdivisionNode& n : sub->nodes) {
        if (!n.isLeaf()) continue;
        for (std::uint32_t k = 0; k < n.triangleCount; ++k)
            if (sub->triangleAt(n.firstTriangle + k) == floor) {
                EXPECT_LE(n.depth, 1u);
            }
    }
    // Without pulling up, the floor lands deep and stretches every box on its way.
    SubdivisionParams p = params(SubdivisionMethod::Dbvs, 50);
    p.pullUpWidths = 0.0f;
    auto plain = subdivide(mesh, p);
    ASSERT_TRUE(plain);
    EXPECT_EQ(validateSubdivision(mesh, *plain, 50, 32), "");
}

TEST(Subdivision, OctreesHaveUpToEightChildren) {
    const Mesh mesh = clusteredSoup(30, 100, 0, 4);
    auto lb = subdivide(mesh, params(SubdivisionMethod::Octree, 100));
    auto grid = subdivide(mesh, params(SubdivisionMethod::Grid, 100));
    ASSERT_TRUE(lb && grid);
    EXPECT_EQ(lb->nodes[0].childCount, 8u);
    // Load-balanced: the root's children differ by at most one triangle per halving.
    for (std::uint32_t c = 0; c < 8; ++c)
        EXPECT_NEAR(double(lb->nodes[1 + c].triangleCount), mesh.triangleCount() / 8.0, 2.0);
    EXPECT_LE(grid->stats.maxChildren, 8u);
}

TEST(Subdivision, DegenerateInputsStillRespectLimits) {
    // 300 copies of one triangle: no plane separates them; halving keeps the limit.
    Mesh same;
    for (int i = 0; i < 300; ++i) {
        const auto b = static_cast<std::uint32_t>(same.positions.size());
        same.positions.insert(same.positions.end(), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
        same.indices.insert(same.indices.end(), {b, b + 1, b + 2});
    }
    // Zero-area triangles at one point, and a flat soup (all z = 0).
    Mesh points = same;
    for (glm::vec3& p : points.positions) p = glm::vec3(2, 2, 2);
    Mesh flat = clusteredSoup(10, 50, 0, 2);
    for (glm::vec3& p : flat.positions) p.z = 0.0f;
    for (const Mesh* m : {&same, &points, &flat}) {
        for (SubdivisionMethod method : kMethods) {
            auto sub = subdivide(*m, params(method, 16));
            ASSERT_TRUE(sub) << sub.error().message;
            EXPECT_EQ(validateSubdivision(*m, *sub, 16, 32), "") << toString(method);
            EXPECT_EQ(sub->stats.oversizedLeaves, 0u) << toString(method);
        }
    }
    // Empty mesh: one empty leaf.
    auto empty = subdivide(Mesh{}, params(SubdivisionMethod::Phbvo, 16));
    ASSERT_TRUE(empty);
    EXPECT_EQ(empty->nodes.size(), 1u);
    EXPECT_EQ(validateSubdivision(Mesh{}, *empty, 16, 32), "");
    // Depth limit: leaves may exceed the triangle limit only there.
    SubdivisionParams shallow = params(SubdivisionMethod::Phbvo, 16);
    shallow.maxDepth = 2;
    auto sub = subdivide(flat, shallow);
    ASSERT_TRUE(sub);
    EXPECT_EQ(sub->stats.leaves, 4u);
    EXPECT_EQ(sub->stats.oversizedLeaves, 4u);
    EXPECT_EQ(validateSubdivision(flat, *sub, 16, 2), "");
}

TEST(Subdivision, BadInputIsAnError) {
    Mesh broken = clusteredSoup(1, 10, 0, 1);
    broken.indices.push_back(999999);
    broken.indices.push_back(0);
    broken.indices.push_back(1);
    EXPECT_FALSE(subdivide(broken, {}));
    const Mesh mesh = clusteredSoup(1, 10, 0, 1);
    SubdivisionParams p;
    p.maxLeafTriangles = 0;
    EXPECT_FALSE(subdivide(mesh, p));
    p = {};
    p.maxDepth = 1000;
    EXPECT_FALSE(subdivide(mesh, p));
    p = {};
    p.sahBins = 1;
    EXPECT_FALSE(subdivide(mesh, p));
    p = {};
    p.planeMove = 0.7f;
    EXPECT_FALSE(subdivide(mesh, p));
    p = {};
    p.threads = 0;
    EXPECT_FALSE(subdivide(mesh, p));
    EXPECT_FALSE(parseSubdivisionMethod("kdtree"));
    EXPECT_EQ(*parseSubdivisionMethod("dbvs"), SubdivisionMethod::Dbvs);
}

TEST(Subdivision, ValidatorCatchesBrokenTrees) {
    const Mesh mesh = clusteredSoup(10, 50, 0, 6);
    auto sub = subdivide(mesh, params(SubdivisionMethod::Phbvo, 50));
    ASSERT_TRUE(sub);
    Subdivision twice = *sub;
    twice.triangles[1] = twice.triangles[0];
    EXPECT_NE(validateSubdivision(mesh, twice, 50, 32).find("twice"), std::string::npos);
    Subdivision loose = *sub;
    loose.nodes.back().box.max.x -= 1.0f;
    EXPECT_NE(validateSubdivision(mesh, loose, 50, 32), "");
    EXPECT_NE(validateSubdivision(mesh, *sub, 10, 32).find("above the limit"), std::string::npos);
}

TEST(Subdivision, LeafModelsHoldEveryTriangleOnce) {
    Mesh mesh = clusteredSoup(20, 60, 1, 8);
    const Mesh original = mesh;
    auto sub = subdivide(mesh, params(SubdivisionMethod::Dbvs, 100));
    ASSERT_TRUE(sub);
    applyTriangleOrder(mesh, *sub);
    EXPECT_TRUE(sub->triangles.empty());
    EXPECT_EQ(validateSubdivision(mesh, *sub, 100, 32), "");
    const std::vector<LocalBsp> models = subdivisionLeafModels(mesh, *sub);
    EXPECT_EQ(models.size(), sub->stats.leaves);
    std::size_t tris = 0;
    double area = 0.0;
    for (const LocalBsp& b : models) {
        EXPECT_EQ(validateMesh(b.mesh), "");
        EXPECT_EQ(b.nodes.size(), 1u);
        EXPECT_TRUE(b.nodes[0].box.contains(b.mesh.bounds()));
        EXPECT_TRUE(b.mesh.bounds().contains(b.nodes[0].box));
        tris += b.mesh.triangleCount();
        area += surfaceArea(b.mesh);
    }
    EXPECT_EQ(tris, original.triangleCount());
    EXPECT_NEAR(area, surfaceArea(original), 1e-6 * surfaceArea(original));
}

TEST(Subdivision, CollapseKeepsLeavesAndHalvesInnerNodes) {
    const Mesh mesh = clusteredSoup(40, 100, 0, 12);
    auto bin = subdivide(mesh, params(SubdivisionMethod::Phbvo, 50));
    ASSERT_TRUE(bin);
    Subdivision quad = *bin;
    collapseSubdivision(quad, 4);
    recountSubdivisionStats(quad, 50);
    EXPECT_EQ(validateSubdivision(mesh, quad, 50, 32), "");
    EXPECT_EQ(quad.stats.leaves, bin->stats.leaves);
    EXPECT_EQ(quad.stats.maxChildren, 4u);
    EXPECT_LT(quad.stats.inner, bin->stats.inner * 2 / 3);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> a, b;
    for (const SubdivisionNode& n : bin->nodes)
        if (n.isLeaf()) a.push_back({n.firstTriangle, n.triangleCount});
    for (const SubdivisionNode& n : quad.nodes)
        if (n.isLeaf()) b.push_back({n.firstTriangle, n.triangleCount});
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b);
}

class SubdivisionFileTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("dyncull_subdivision_file_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::create_directories(dir_);
        model_.mesh = clusteredSoup(10, 40, 1, 2);
        model_.params = params(SubdivisionMethod::Phbvo, 30);
        model_.params.collapseTo = 4;
        auto sub = subdivide(model_.mesh, model_.params);
        ASSERT_TRUE(sub);
        model_.subdivision = sub.take();
        applyTriangleOrder(model_.mesh, model_.subdivision);
        model_.source = "model.ply";
        model_.sourceHash = 1234;
        path_ = dir_ / "m.dsub";
        ASSERT_TRUE(writeSubdivisionFile(path_, model_));
        // scripts/fuzz.sh: this small file is the subdivision-file fuzzer's seed.
        if (const char* seeds = std::getenv("DYNCULL_FUZZ_SEEDS"); seeds && *seeds) {
            const auto out = std::filesystem::path(seeds) / "dsub";
            std::filesystem::create_directories(out);
            std::filesystem::copy_file(path_, out / "m.dsub", std::filesystem::copy_options::overwrite_existing);
        }
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    std::vector<char> bytes() const {
        std::ifstream f(path_, std::ios::binary);
        return {std::istreambuf_iterator<char>(f), {}};
    }
    void write(const std::vector<char>& b) const {
        std::ofstream f(path_, std::ios::binary | std::ios::trunc);
        f.write(b.data(), static_cast<std::streamsize>(b.size()));
    }
    std::string error() const {
        auto r = readSubdivisionFile(path_);
        return r ? std::string() : r.error().message;
    }

    std::filesystem::path dir_, path_;
    SubdividedModel model_;
};

TEST_F(SubdivisionFileTest, RoundTrip) {
    auto r = readSubdivisionFile(path_);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->source, "model.ply");
    EXPECT_EQ(r->sourceHash, 1234u);
    EXPECT_EQ(r->params.collapseTo, 4u);
    EXPECT_EQ(r->mesh.positions, model_.mesh.positions);
    EXPECT_EQ(r->mesh.normals, model_.mesh.normals);
    EXPECT_EQ(r->mesh.indices, model_.mesh.indices);
    EXPECT_TRUE(sameNodes(r->subdivision, model_.subdivision));
    EXPECT_EQ(r->subdivision.stats.leaves, model_.subdivision.stats.leaves);
    EXPECT_EQ(r->subdivision.stats.inner, model_.subdivision.stats.inner);
}

TEST_F(SubdivisionFileTest, CorruptTruncatedAndForeignFilesAreRefused) {
    const std::vector<char> good = bytes();
    std::vector<char> b = good;
    b[b.size() / 2] ^= 0x10;
    write(b);
    EXPECT_NE(error().find("checksum mismatch"), std::string::npos) << error();
    b = good;
    b.resize(b.size() - 7);
    write(b);
    EXPECT_NE(error().find("truncated or padded"), std::string::npos) << error();
    b = good;
    b[0] = 'X';
    write(b);
    EXPECT_NE(error().find("bad magic"), std::string::npos) << error();
    b = good;
    b[8] = 99;
    write(b);
    EXPECT_NE(error().find("format version 99"), std::string::npos) << error();
    write(std::vector<char>(good.begin(), good.begin() + 20));
    EXPECT_NE(error().find("truncated header"), std::string::npos) << error();
    std::filesystem::remove(path_);
    EXPECT_NE(error().find("cannot open"), std::string::npos) << error();
}

TEST_F(SubdivisionFileTest, WellFormedButWrongContentIsRefused) {
    // A node's triangle count changed and the checksum recomputed: the validator refuses it.
    std::vector<char> b = bytes();
    const std::size_t nodeBytes = 44, tail = 16;  // stats after the nodes: f64 + u64
    const std::size_t lastNode = b.size() - tail - nodeBytes;
    std::uint32_t count = 0;
    std::memcpy(&count, b.data() + lastNode + 32, 4);
    ++count;
    std::memcpy(b.data() + lastNode + 32, &count, 4);
    const std::uint64_t sum = fnv1a64(b.data() + kSubdivisionFileHeaderSize, b.size() - kSubdivisionFileHeaderSize);
    std::memcpy(b.data() + 32, &sum, 8);
    write(b);
    const std::string e = error();
    EXPECT_NE(e, "");
    EXPECT_EQ(e.find("checksum"), std::string::npos) << e;
}

// Issue 19: a .dsub with a valid checksum is still checked field by field.
class SubdivisionFileContentTest : public SubdivisionFileTest {
protected:
    // Payload offsets of this fixture's file: source string, method, 6 parameters,
    // collapseTo, mesh name, then the three counted arrays.
    static constexpr std::size_t kSource = kSubdivisionFileHeaderSize;  // u32 length, "model.ply"
    static constexpr std::size_t kParams = kSource + 4 + 9;
    static constexpr std::size_t kName = kParams + 1 + 4 * 4 + 2 * 4 + 4;  // u32 length, "soup"
    static constexpr std::size_t kPositions = kName + 4 + 4;                // u64 count, then 12 bytes each
    std::size_t normalsAt(std::size_t positions) const { return kPositions + 8 + 12 * positions; }
    std::size_t indicesAt() const { return normalsAt(model_.mesh.positions.size()) + 8 + 12 * model_.mesh.normals.size(); }
    std::size_t nodesAt() const { return indicesAt() + 8 + 4 * model_.mesh.indices.size(); }

    // Rewrites the file with `value` at `offset` and a checksum that matches again.
    template <class T>
    void patch(std::size_t offset, T value) {
        std::vector<char> b = bytes();
        ASSERT_LE(offset + sizeof(T), b.size());
        std::memcpy(b.data() + offset, &value, sizeof(T));
        const std::uint64_t sum = fnv1a64(b.data() + kSubdivisionFileHeaderSize, b.size() - kSubdivisionFileHeaderSize);
        std::memcpy(b.data() + 32, &sum, 8);
        write(b);
    }
    void rewrite() { ASSERT_TRUE(writeSubdivisionFile(path_, model_)); }
    void expectRefused(const std::string& what) {
        const std::string e = error();
        EXPECT_NE(e.find(what), std::string::npos) << "expected '" << what << "' in: " << e;
        EXPECT_EQ(e.rfind("subdivision file " + path_.string() + ": ", 0), 0u) << e;
        EXPECT_EQ(e.find("checksum"), std::string::npos) << e;
    }
};

TEST_F(SubdivisionFileContentTest, NanOrZeroNormalsAreRefusedDespiteAValidChecksum) {
    computeNormals(model_.mesh);
    rewrite();
    ASSERT_EQ(error(), "");
    const Mesh good = model_.mesh;
    for (float bad : {NAN, INFINITY, -INFINITY}) {
        model_.mesh.normals[3].y = bad;
        rewrite();
        expectRefused("normal 3 is not finite");
        model_.mesh = good;
    }
    model_.mesh.normals[5] = glm::vec3(0.0f);
    rewrite();
    expectRefused("normal 5 has zero length");
    model_.mesh.normals[5] = glm::vec3(1e-7f, 0.0f, 0.0f);
    rewrite();
    expectRefused("normal 5 has zero length");
    model_.mesh = good;
    model_.mesh.normals.pop_back();
    rewrite();
    expectRefused("normal count");
}

TEST_F(SubdivisionFileContentTest, NonFinitePositionsAndBadIndicesAreRefused) {
    model_.mesh.positions[7].z = NAN;
    rewrite();
    expectRefused("vertex 7 has a non-finite coordinate");
    model_.mesh.positions[7].z = INFINITY;
    rewrite();
    expectRefused("vertex 7 has a non-finite coordinate");
    SetUp();  // the original model again
    for (std::uint32_t index : {static_cast<std::uint32_t>(model_.mesh.positions.size()), 0x7FFFFFFFu, 0xFFFFFFFFu}) {
        patch(indicesAt() + 8 + 4 * 10, index);
        expectRefused("index " + std::to_string(index) + " at position 10 out of range");
    }
}

TEST_F(SubdivisionFileContentTest, CountsNear2To32And2To64AreRefused) {
    const std::vector<char> good = bytes();
    auto restore = [&] { write(good); };
    for (std::uint64_t n : {std::uint64_t{0xFFFFFFFF}, std::uint64_t{1} << 32, (std::uint64_t{1} << 32) + 1,
                            std::uint64_t{1} << 63, ~std::uint64_t{0}, ~std::uint64_t{0} / 12 + 1}) {
        SCOPED_TRACE(n);
        patch(kPositions, n);
        expectRefused("truncated mesh");
        restore();
        patch(normalsAt(model_.mesh.positions.size()), n);
        expectRefused("truncated mesh");
        restore();
        patch(indicesAt(), n);
        expectRefused("truncated mesh");
        restore();
        patch(nodesAt(), n);
        expectRefused("node count out of range");
        restore();
    }
    for (std::uint32_t n : {0xFFFFFFFFu, 0x80000000u, 4097u}) {
        patch(kSource, n);
        expectRefused("truncated source name");
        restore();
        patch(kName, n);
        expectRefused("truncated mesh");
        restore();
    }
    // The header's payload size, which the file size must match exactly.
    for (std::uint64_t n : {std::uint64_t{0xFFFFFFFF}, std::uint64_t{1} << 32, ~std::uint64_t{0}}) {
        std::vector<char> b = good;
        std::memcpy(b.data() + 24, &n, 8);
        write(b);
        EXPECT_NE(error().find("truncated or padded: header says " + std::to_string(n)), std::string::npos) << error();
    }
}

TEST_F(SubdivisionFileContentTest, NodeRangesNear2To32AreRefused) {
    const std::size_t root = nodesAt() + 8;  // box (24 bytes), firstChild, childCount, firstTriangle, triangleCount, depth
    const std::vector<char> good = bytes();
    for (std::uint32_t v : {0xFFFFFFFFu, 0xFFFFFFFEu, 0x80000000u}) {
        for (std::size_t field : {24u, 28u, 32u, 36u, 40u}) {
            SCOPED_TRACE(std::to_string(field) + " " + std::to_string(v));
            patch(root + field, v);
            EXPECT_NE(error(), "");
            write(good);
        }
    }
    // A child's count chosen so that the parent's tiling sum would wrap in 32 bits.
    ASSERT_GE(model_.subdivision.nodes.size(), 3u);
    const SubdivisionNode& r = model_.subdivision.nodes[0];
    ASSERT_FALSE(r.isLeaf());
    const std::size_t first = nodesAt() + 8 + 44 * r.firstChild;
    const SubdivisionNode& c0 = model_.subdivision.nodes[r.firstChild];
    patch(first + 36, static_cast<std::uint32_t>(c0.triangleCount + (std::uint64_t{1} << 32) - r.triangleCount));
    EXPECT_NE(error(), "");
}

TEST_F(SubdivisionFileContentTest, ParametersNear2To32AreRefusedOrHarmless) {
    const std::vector<char> good = bytes();
    patch(kParams, std::uint8_t{0xFF});
    expectRefused("unknown method 255");
    for (std::uint32_t v : {0xFFFFFFFFu, 0x80000000u}) {
        write(good);
        patch(kParams + 5, v);
        expectRefused("maximum depth " + std::to_string(v) + " above");
        write(good);
        patch(kParams + 13, v);
        expectRefused("SAH bins must be in 2..256");
        // Limits that only loosen: the stored tree still satisfies them, so the file loads
        // (maxLeafTriangles) or the field only matters to a rebuild (exactBelow, collapseTo).
        for (std::size_t field : {std::size_t{1}, std::size_t{9}, std::size_t{25}}) {
            write(good);
            patch(kParams + field, v);
            EXPECT_EQ(error(), "") << field;
        }
    }
    for (float f : {NAN, INFINITY, -1.0f}) {
        write(good);
        patch(kParams + 17, f);
        expectRefused("plane move must be in [0, 0.5)");
        write(good);
        patch(kParams + 21, f);
        expectRefused("pull-up width must be finite and >= 0");
    }
}

TEST_F(SubdivisionFileContentTest, NonFiniteBuildTimeIsRefused) {
    const std::size_t buildMs = bytes().size() - 16;
    patch(buildMs, std::numeric_limits<double>::quiet_NaN());
    expectRefused("build time is not a finite duration");
    patch(buildMs, -1.0);
    expectRefused("build time");
}

}  // namespace
}  // namespace dyncull
