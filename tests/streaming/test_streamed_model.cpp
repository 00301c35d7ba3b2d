// Out-of-core subdivision and the streamed model files: every source triangle in exactly one
// leaf, limits held, the same leaves as in memory when nothing needs streaming, and every
// truncation or corruption of either file an error naming the file (and the leaf).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "dyncull/loaders/loaders.hpp"
#include "dyncull/loaders/ply_stream.hpp"
#include "dyncull/objects/checksum.hpp"
#include "dyncull/streaming/leaf_cache.hpp"
#include "dyncull/streaming/out_of_core_subdivision.hpp"
#include "dyncull/streaming/streamed_model.hpp"
#include "objects/test_files.hpp"
#include "streaming/streamed_test_models.hpp"

namespace dyncull {
namespace {

using test::sphereField;
using test::TempDir;

using Tri = std::array<float, 9>;

/// A triangle as its corner positions, rotated so the smallest corner comes first (leaf
/// ordering may rotate a triangle, never mirror it).
Tri canonical(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    std::array<glm::vec3, 3> v{a, b, c};
    auto less = [](const glm::vec3& x, const glm::vec3& y) {
        return std::tie(x.x, x.y, x.z) < std::tie(y.x, y.y, y.z);
    };
    int first = 0;
    for (int k = 1; k < 3; ++k)
        if (less(v[k], v[first])) first = k;
    Tri t;
    for (int k = 0; k < 3; ++k)
        for (int d = 0; d < 3; ++d) t[3 * k + d] = v[(first + k) % 3][d];
    return t;
}

std::vector<Tri> trianglesOf(const Mesh& m) {
    std::vector<Tri> out;
    for (std::size_t t = 0; t < m.triangleCount(); ++t)
        out.push_back(canonical(m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]], m.positions[m.indices[3 * t + 2]]));
    std::sort(out.begin(), out.end());
    return out;
}

/// Reads every leaf back; checks each against its node and returns all triangles, sorted.
std::vector<Tri> readAll(const StreamedModel& model, std::uint32_t maxLeaf) {
    auto file = GeometryFile::open(model);
    EXPECT_TRUE(file.ok()) << file.error().message;
    std::vector<Tri> out;
    Mesh g;
    std::vector<unsigned char> scratch;
    for (std::uint32_t i = 0; i < model.leaves.size(); ++i) {
        const Status s = file->read(i, g, scratch);
        EXPECT_TRUE(s.ok()) << s.message();
        const StreamedLeaf& leaf = model.leaves[i];
        EXPECT_LE(leaf.triangleCount, maxLeaf);
        EXPECT_EQ(g.indices.size(), 3u * leaf.triangleCount);
        for (const glm::vec3& n : g.normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-4f);
        for (const glm::vec3& p : g.positions)
            EXPECT_TRUE(leaf.obb.contains(p, 1e-4f * (1.0f + glm::length(p))));
        for (std::size_t t = 0; t < g.indices.size(); t += 3)
            out.push_back(canonical(g.positions[g.indices[t]], g.positions[g.indices[t + 1]], g.positions[g.indices[t + 2]]));
    }
    std::sort(out.begin(), out.end());
    return out;
}

OutOfCoreParams smallBudget(std::uint32_t maxLeaf = 1000) {
    OutOfCoreParams p;
    p.subdivision.maxLeafTriangles = maxLeaf;
    p.memoryBytes = std::size_t{16} << 20;  // the minimum: 100k triangles need streamed splits
    p.source = "test";
    return p;
}

TEST(OutOfCoreSubdivision, EveryTriangleInExactlyOneLeafUnderASmallBudget) {
    TempDir dir;
    const Mesh mesh = sphereField(5, 30, 40);  // 50 spheres, 120,000 triangles
    ASSERT_GT(mesh.triangleCount(), 100000u);
    const auto path = dir.file("field.dnodes");
    auto stats = subdivideOutOfCore(meshSource(mesh), path, smallBudget());
    ASSERT_TRUE(stats.ok()) << stats.error().message;
    EXPECT_GT(stats->streamedSplits, 0u) << "the budget should force streamed splits";
    EXPECT_GT(stats->memorySubtrees, 1u);
    EXPECT_LE(stats->largestSubtree, stats->subtreeLimit);
    EXPECT_EQ(stats->triangles, mesh.triangleCount());
    EXPECT_FALSE(stats->normalsFromSource);

    auto model = readStreamedModel(path);
    ASSERT_TRUE(model.ok()) << model.error().message;
    EXPECT_EQ(model->triangles(), mesh.triangleCount());
    EXPECT_EQ(model->leaves.size(), stats->leaves);
    EXPECT_EQ(readAll(*model, 1000), trianglesOf(mesh));
    // No temporary files are left beside the output.
    const auto files = std::distance(std::filesystem::directory_iterator(dir.file("")), std::filesystem::directory_iterator());
    EXPECT_EQ(files, 2);
}

TEST(OutOfCoreSubdivision, NormalsAreTheMeshsOwnWhetherGivenOrComputed) {
    TempDir dir;
    Mesh mesh = sphereField(2, 12, 16);
    Mesh withNormals = mesh;
    computeNormals(withNormals);
    for (const bool given : {false, true}) {
        const auto path = dir.file(given ? "given.dnodes" : "computed.dnodes");
        auto stats = subdivideOutOfCore(meshSource(given ? withNormals : mesh), path, smallBudget(200));
        ASSERT_TRUE(stats.ok()) << stats.error().message;
        EXPECT_EQ(stats->normalsFromSource, given);
        auto model = readStreamedModel(path);
        ASSERT_TRUE(model.ok()) << model.error().message;
        auto file = GeometryFile::open(*model);
        ASSERT_TRUE(file.ok());
        // Each leaf vertex's normal is the whole mesh's normal of the vertex at that position.
        std::map<std::array<float, 3>, glm::vec3> expected;
        for (std::size_t v = 0; v < withNormals.positions.size(); ++v)
            expected[{withNormals.positions[v].x, withNormals.positions[v].y, withNormals.positions[v].z}] = withNormals.normals[v];
        Mesh g;
        std::vector<unsigned char> scratch;
        for (std::uint32_t i = 0; i < model->leaves.size(); ++i) {
            ASSERT_TRUE(file->read(i, g, scratch).ok());
            for (std::size_t v = 0; v < g.positions.size(); ++v) {
                const auto it = expected.find({g.positions[v].x, g.positions[v].y, g.positions[v].z});
                ASSERT_NE(it, expected.end());
                // Sphere poles repeat a position with different ids; only the rest are unique.
                if (std::fabs(std::fabs(g.positions[v].y - std::round(g.positions[v].y / 3.0f) * 3.0f) - 1.0f) < 1e-5f) continue;
                EXPECT_NEAR(glm::distance(g.normals[v], it->second), 0.0f, 1e-5f);
            }
        }
    }
}

TEST(OutOfCoreSubdivision, WithoutStreamedSplitsTheLeavesAreTheInMemoryOnes) {
    TempDir dir;
    const Mesh mesh = sphereField(3, 20, 30);
    OutOfCoreParams p = smallBudget(800);
    p.memoryBytes = std::size_t{256} << 20;
    auto stats = subdivideOutOfCore(meshSource(mesh), dir.file("big.dnodes"), p);
    ASSERT_TRUE(stats.ok()) << stats.error().message;
    EXPECT_EQ(stats->streamedSplits, 0u);
    EXPECT_EQ(stats->memorySubtrees, 1u);
    auto model = readStreamedModel(dir.file("big.dnodes"));
    ASSERT_TRUE(model.ok());
    auto sub = subdivide(mesh, p.subdivision);
    ASSERT_TRUE(sub.ok());
    ASSERT_EQ(model->nodes.size(), sub->nodes.size());
    for (std::size_t i = 0; i < sub->nodes.size(); ++i) {
        EXPECT_EQ(model->nodes[i].triangleCount, sub->nodes[i].triangleCount);
        EXPECT_EQ(model->nodes[i].box.min, sub->nodes[i].box.min);
        EXPECT_EQ(model->nodes[i].box.max, sub->nodes[i].box.max);
    }
}

TEST(OutOfCoreSubdivision, StreamsAPlyFileWithPolygonsAndFacesFirst) {
    TempDir dir;
    // A 40 x 40 grid of quads (some as pentagons with a midpoint) with the face element first.
    const int n = 40;
    std::string verts, faces;
    int faceCount = 0;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) verts += std::to_string(i) + " " + std::to_string((i * j) % 7 * 0.1) + " " + std::to_string(j) + "\n";
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i, ++faceCount) {
            const int a = j * (n + 1) + i;
            faces += "4 " + std::to_string(a) + " " + std::to_string(a + n + 1) + " " + std::to_string(a + n + 2) + " " +
                     std::to_string(a + 1) + "\n";
        }
    const std::string ply = "ply\nformat ascii 1.0\nelement face " + std::to_string(faceCount) +
                            "\nproperty list uchar int vertex_indices\nelement vertex " + std::to_string((n + 1) * (n + 1)) +
                            "\nproperty float x\nproperty float y\nproperty float z\nend_header\n" + faces + verts;
    const auto src = dir.write("grid.ply", ply);
    auto scene = loadPly(src);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    auto stats = subdivideOutOfCore([&](MeshStreamSink& s) { return streamPly(src, s); }, dir.file("grid.dnodes"), smallBudget(100));
    ASSERT_TRUE(stats.ok()) << stats.error().message;
    EXPECT_EQ(stats->polygons, std::uint64_t(faceCount));
    auto model = readStreamedModel(dir.file("grid.dnodes"));
    ASSERT_TRUE(model.ok()) << model.error().message;
    EXPECT_EQ(readAll(*model, 100), trianglesOf(scene->meshes[0]));
}

TEST(OutOfCoreSubdivision, BadInputIsAnErrorAndLeavesNoFiles) {
    TempDir dir;
    const Mesh mesh = sphereField(1, 4, 4);
    OutOfCoreParams p = smallBudget();
    p.memoryBytes = std::size_t{8} << 20;
    auto r = subdivideOutOfCore(meshSource(mesh), dir.file("a.dnodes"), p);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("16 MiB"), std::string::npos) << r.error().message;
    p = smallBudget(0);
    EXPECT_FALSE(subdivideOutOfCore(meshSource(mesh), dir.file("a.dnodes"), p).ok());
    // A source that fails half-way: its error comes back, and nothing is left behind.
    const auto broken = [&](MeshStreamSink& s) -> Status {
        MeshStreamLayout l;
        l.vertices = 3;
        l.faces = 1;
        if (Status st = s.begin(l); !st) return st;
        if (Status st = s.vertex(glm::vec3(0.0f), glm::vec3(0.0f)); !st) return st;
        return Error{"broken source: vertex 1 is bad", ErrorCode::BadFile};
    };
    r = subdivideOutOfCore(broken, dir.file("b.dnodes"), smallBudget());
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("broken source"), std::string::npos);
    const auto empty = [&](MeshStreamSink& s) -> Status { return s.begin(MeshStreamLayout{}); };
    EXPECT_FALSE(subdivideOutOfCore(empty, dir.file("c.dnodes"), smallBudget()).ok());
    EXPECT_TRUE(std::filesystem::is_empty(dir.file("")));
}

class StreamedModelFiles : public ::testing::Test {
protected:
    void SetUp() override {
        mesh_ = sphereField(3, 16, 24);
        nodes_ = dir_.file("m.dnodes");
        auto stats = subdivideOutOfCore(meshSource(mesh_), nodes_, smallBudget(300));
        ASSERT_TRUE(stats.ok()) << stats.error().message;
        geometry_ = geometryPathFor(nodes_);
        nodeBytes_ = readBytes(nodes_);
        geometryBytes_ = readBytes(geometry_);
    }
    static std::string readBytes(const std::filesystem::path& p) {
        std::ifstream f(p, std::ios::binary);
        return {std::istreambuf_iterator<char>(f), {}};
    }
    static void writeBytes(const std::filesystem::path& p, const std::string& b) { std::ofstream(p, std::ios::binary) << b; }
    void restore() {
        writeBytes(nodes_, nodeBytes_);
        writeBytes(geometry_, geometryBytes_);
    }
    TempDir dir_;
    Mesh mesh_;
    std::filesystem::path nodes_, geometry_;
    std::string nodeBytes_, geometryBytes_;
};

TEST_F(StreamedModelFiles, EveryTruncationOfTheNodeFileIsAnError) {
    for (std::size_t len = 0; len < nodeBytes_.size(); len += 1 + len / 7) {
        writeBytes(nodes_, nodeBytes_.substr(0, len));
        auto r = readStreamedModel(nodes_);
        ASSERT_FALSE(r.ok()) << len;
        EXPECT_EQ(r.error().message.rfind("node file " + nodes_.string(), 0), 0u) << r.error().message;
    }
}

TEST_F(StreamedModelFiles, EveryFlippedByteOfTheNodeFileIsAnError) {
    for (std::size_t at = 0; at < nodeBytes_.size(); at += 1 + at / 13) {
        std::string b = nodeBytes_;
        b[at] = static_cast<char>(b[at] ^ 0x5a);
        writeBytes(nodes_, b);
        EXPECT_FALSE(readStreamedModel(nodes_).ok()) << "byte " << at;
    }
}

TEST_F(StreamedModelFiles, AForgedLeafTableIsCaughtByTheTreeCheck) {
    // Valid checksum, bad content: rewrite a leaf's offset to overlap its neighbour, then
    // re-seal the payload's checksum as a hostile writer would.
    auto model = readStreamedModel(nodes_);
    ASSERT_TRUE(model.ok());
    ASSERT_GE(model->leaves.size(), 2u);
    std::string b = nodeBytes_;
    const std::size_t payload = b.size() - kStreamedHeaderSize;
    // The leaf table is the payload's tail: 4-byte count, then 120 bytes per leaf; the
    // offset is at byte 16 of a leaf.
    const std::size_t leaf1 = b.size() - 120 * (model->leaves.size() - 1);
    std::uint64_t off = model->leaves[0].offset;
    std::memcpy(&b[leaf1 + 16], &off, 8);
    const std::uint64_t sum = fnv1a64(b.data() + kStreamedHeaderSize, payload);
    std::memcpy(&b[32], &sum, 8);
    writeBytes(nodes_, b);
    auto r = readStreamedModel(nodes_);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("leaf"), std::string::npos) << r.error().message;
}

TEST_F(StreamedModelFiles, ATruncatedOrForeignGeometryFileIsRefusedAtOpen) {
    writeBytes(geometry_, geometryBytes_.substr(0, geometryBytes_.size() - 1));
    auto r = readStreamedModel(nodes_);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("truncated"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(geometry_.string()), std::string::npos);
    std::filesystem::remove(geometry_);
    EXPECT_FALSE(readStreamedModel(nodes_).ok());
    // Another model's geometry file of the same name.
    TempDir other;
    const Mesh m2 = sphereField(2, 16, 24);
    ASSERT_TRUE(subdivideOutOfCore(meshSource(m2), other.file("m.dnodes"), smallBudget(300)).ok());
    std::filesystem::copy_file(geometryPathFor(other.file("m.dnodes")), geometry_);
    r = readStreamedModel(nodes_);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("does not belong"), std::string::npos) << r.error().message;
}

TEST_F(StreamedModelFiles, ACorruptChunkIsAnErrorNamingTheLeafAndOnlyThatLeaf) {
    auto model = readStreamedModel(nodes_);
    ASSERT_TRUE(model.ok());
    const std::uint32_t bad = static_cast<std::uint32_t>(model->leaves.size() / 2);
    std::string b = geometryBytes_;
    b[model->leaves[bad].offset + model->leaves[bad].chunkBytes / 2] ^= 0x01;
    writeBytes(geometry_, b);
    auto file = GeometryFile::open(*model);
    ASSERT_TRUE(file.ok());
    Mesh g;
    std::vector<unsigned char> scratch;
    for (std::uint32_t i = 0; i < model->leaves.size(); ++i) {
        const Status s = file->read(i, g, scratch);
        if (i != bad) {
            EXPECT_TRUE(s.ok()) << s.message();
            continue;
        }
        ASSERT_FALSE(s.ok());
        EXPECT_NE(s.message().find("leaf " + std::to_string(bad) + " "), std::string::npos) << s.message();
        EXPECT_NE(s.message().find(geometry_.string()), std::string::npos) << s.message();
        EXPECT_EQ(s.error().code, ErrorCode::BadFile);
    }
    EXPECT_FALSE(file->read(static_cast<std::uint32_t>(model->leaves.size()), g, scratch).ok());
}

}  // namespace
}  // namespace dyncull

namespace dyncull {
namespace {

class LeafCacheTest : public ::testing::Test {
protected:
    void SetUp() override {
        const Mesh mesh = sphereField(3, 16, 24);
        ASSERT_TRUE(subdivideOutOfCore(meshSource(mesh), dir_.file("m.dnodes"), smallBudget(300)).ok());
        auto m = readStreamedModel(dir_.file("m.dnodes"));
        ASSERT_TRUE(m.ok());
        model_ = m.take();
        auto file = GeometryFile::open(model_);
        ASSERT_TRUE(file.ok());
        std::vector<unsigned char> scratch;
        for (std::uint32_t i = 0; i < model_.leaves.size(); ++i) {
            Mesh g;
            CompactLeaf c;  // the cache keeps leaves compact
            ASSERT_TRUE(file->readCompact(i, c, g, scratch).ok());
            CompactLeaf again;  // the same as the leaf read in full and then compacted
            compactLeaf(g, model_.leaves[i].box, again);
            ASSERT_EQ(c.words, again.words);
            ASSERT_EQ(c.bytes(), compactLeafBytes(model_.leaves[i]));
            total_ += c.bytes();
            largest_ = std::max(largest_, c.bytes());
            truth_.push_back(std::move(c));
        }
        ASSERT_GE(truth_.size(), 8u);
    }
    test::TempDir dir_;
    StreamedModel model_;
    std::vector<CompactLeaf> truth_;
    std::size_t total_ = 0, largest_ = 0;
};

TEST_F(LeafCacheTest, ReadAheadAndDemandLoadsStayWithinTheBudget) {
    const std::size_t budget = std::max(total_ / 4, 2 * largest_);
    auto cache = LeafCache::create(model_, budget);
    ASSERT_TRUE(cache.ok()) << cache.error().message;
    std::vector<std::uint32_t> all(truth_.size());
    for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
    (*cache)->prefetch(all);
    (*cache)->drain();
    LeafCacheStats s = (*cache)->stats();
    EXPECT_GT(s.prefetchLoads, 0u);
    EXPECT_LT(s.prefetchLoads, all.size()) << "read-ahead stops where the budget is full";
    EXPECT_EQ(s.evictions, 0u) << "read-ahead never evicts leaves earlier in its own list";
    // The leaves read ahead are hits; every leaf comes back exact, in any order.
    for (std::uint32_t k = 0; k < all.size(); ++k) {
        const std::uint32_t leaf = (k * 7) % static_cast<std::uint32_t>(all.size());
        auto g = (*cache)->acquire(leaf);
        ASSERT_TRUE(g.ok()) << g.error().message;
        EXPECT_EQ((*g)->words, truth_[leaf].words);
        (*cache)->release(leaf);
        ASSERT_LE((*cache)->stats().residentBytes, budget);
    }
    s = (*cache)->stats();
    EXPECT_GT(s.hits, 0u);
    EXPECT_GT(s.misses, 0u);
    EXPECT_EQ(s.hits + s.misses, all.size());
    EXPECT_GT(s.evictions, 0u);
    EXPECT_LE(s.peakResidentBytes, budget);
}

TEST_F(LeafCacheTest, PinnedLeavesStayAndAFullBudgetOfPinsIsAnError) {
    auto cache = LeafCache::create(model_, 3 * largest_);
    ASSERT_TRUE(cache.ok());
    auto a = (*cache)->acquire(0);
    auto b = (*cache)->acquire(1);
    ASSERT_TRUE(a.ok() && b.ok());
    const CompactLeaf* pa = *a;
    // Other leaves come and go through the one free slot; the pinned two stay untouched.
    for (std::uint32_t i = 2; i < truth_.size(); ++i) {
        auto g = (*cache)->acquire(i);
        ASSERT_TRUE(g.ok()) << g.error().message;
        (*cache)->release(i);
    }
    EXPECT_TRUE((*cache)->resident(0) && (*cache)->resident(1));
    EXPECT_EQ(pa->words, truth_[0].words);
    // Pin a third leaf, then ask for a fourth: no room, and nothing pinned may go.
    auto c = (*cache)->acquire(2);
    ASSERT_TRUE(c.ok());
    std::uint32_t big = 3;
    for (std::uint32_t i = 3; i < truth_.size(); ++i)
        if (truth_[i].bytes() > truth_[big].bytes()) big = i;
    const std::size_t used = truth_[0].bytes() + truth_[1].bytes() + truth_[2].bytes();
    if (used + truth_[big].bytes() > 3 * largest_) {
        auto d = (*cache)->acquire(big);
        ASSERT_FALSE(d.ok());
        EXPECT_EQ(d.error().code, ErrorCode::OutOfMemory);
    }
    (*cache)->release(0);
    auto d = (*cache)->acquire(big);
    EXPECT_TRUE(d.ok()) << "room once a pin is released";
}

TEST_F(LeafCacheTest, ALeafLargerThanTheBudgetIsAnErrorNamingIt) {
    auto cache = LeafCache::create(model_, largest_ - 1);
    ASSERT_FALSE(cache.ok());
    EXPECT_NE(cache.error().message.find("more than the whole budget"), std::string::npos) << cache.error().message;
}

TEST_F(LeafCacheTest, ReadAheadAndTheRenderThreadAtOnce) {
    auto cache = LeafCache::create(model_, std::max(total_ / 3, 2 * largest_));
    ASSERT_TRUE(cache.ok());
    std::vector<std::uint32_t> order(truth_.size());
    for (int round = 0; round < 20; ++round) {
        for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = (i * 5 + static_cast<std::uint32_t>(round)) % order.size();
        (*cache)->prefetch(order);
        for (std::uint32_t k = 0; k < 6; ++k) {
            const std::uint32_t leaf = order[(k * 11) % order.size()];
            if (const CompactLeaf* g = (*cache)->tryAcquire(leaf)) {
                EXPECT_EQ(g->triangleCount, truth_[leaf].triangleCount);
                (*cache)->release(leaf);
            }
            auto g = (*cache)->acquire(leaf);
            ASSERT_TRUE(g.ok()) << g.error().message;
            EXPECT_EQ((*g)->words, truth_[leaf].words);
            (*cache)->release(leaf);
        }
    }
    (*cache)->drain();
    EXPECT_LE((*cache)->stats().peakResidentBytes, (*cache)->budget());
}

}  // namespace
}  // namespace dyncull
