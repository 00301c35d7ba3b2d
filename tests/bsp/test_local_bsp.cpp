// Tests for the local BSP builder (buildLocalBsp): tree layout invariants, area
// conservation under clipping, degenerate input, parameter errors, bunny defaults.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>

#include "dyncull/bsp/local_bsp.hpp"
#include "dyncull/loaders/loaders.hpp"
#include "objects/sphere_grid.hpp"

namespace dyncull {
namespace {

Mesh sphereMesh(int slices, int stacks, float radius = 1.0f, glm::vec3 centre = glm::vec3(0.0f)) {
    return test::sphereGridMesh(slices, stacks, radius, centre);
}

// A flat n x n grid of quads in the z = 0 plane.
Mesh gridMesh(int n, float size = 1.0f) {
    Mesh m;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) m.positions.push_back({size * float(i) / float(n), size * float(j) / float(n), 0.0f});
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            const auto a = std::uint32_t(j * (n + 1) + i), b = a + 1, c = a + std::uint32_t(n + 1), d = c + 1;
            m.indices.insert(m.indices.end(), {a, b, d, a, d, c});
        }
    }
    return m;
}

Mesh transformed(Mesh m, float scale, glm::vec3 offset) {
    for (glm::vec3& p : m.positions) p = p * scale + offset;
    return m;
}

// Checks every structural invariant of the result; returns the leaf count.
void checkInvariants(const LocalBsp& bsp, const LocalBspParams& params) {
    const Mesh& mesh = bsp.mesh;
    ASSERT_TRUE(validateMesh(mesh).empty()) << validateMesh(mesh);
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    ASSERT_FALSE(bsp.nodes.empty());
    EXPECT_EQ(bsp.root().firstIndex, 0u);
    EXPECT_EQ(bsp.root().indexCount, mesh.indices.size());
    EXPECT_EQ(bsp.root().subtreeSize, bsp.nodes.size());
    EXPECT_EQ(bsp.stats.trianglesAfter, mesh.triangleCount());
    std::uint32_t leaves = 0, nextLeafIndex = 0, maxDepth = 0;
    for (std::uint32_t i = 0; i < bsp.nodes.size(); ++i) {
        const LocalBspNode& n = bsp.nodes[i];
        ASSERT_LE(std::size_t(n.firstIndex) + n.indexCount, mesh.indices.size());
        ASSERT_EQ(n.indexCount % 3, 0u);
        ASSERT_GE(n.subtreeSize, 1u);
        ASSERT_LE(std::size_t(i) + n.subtreeSize, bsp.nodes.size());
        ASSERT_LE(n.depth, params.maxDepth);
        if (n.isLeaf()) {
            ++leaves;
            maxDepth = std::max<std::uint32_t>(maxDepth, n.depth);
            EXPECT_EQ(n.subtreeSize, 1u);
            // Leaves in DFS order tile the index buffer with no gap or overlap.
            EXPECT_EQ(n.firstIndex, nextLeafIndex);
            nextLeafIndex += n.indexCount;
            for (std::uint32_t k = n.firstIndex; k < n.firstIndex + n.indexCount; ++k)
                EXPECT_TRUE(n.box.contains(mesh.positions[mesh.indices[k]])) << "node " << i;
            if (n.indexCount / 3 > params.maxLeafTriangles && n.depth < params.maxDepth) {
                EXPECT_GT(bsp.stats.stalledLeaves, 0u);
            }
        } else {
            const std::uint32_t c0 = n.children[0], c1 = n.children[1];
            // Depth-first: below child right after the parent, above child after its subtree.
            ASSERT_EQ(c0, i + 1);
            ASSERT_EQ(c1, c0 + bsp.nodes[c0].subtreeSize);
            EXPECT_EQ(n.subtreeSize, 1 + bsp.nodes[c0].subtreeSize + bsp.nodes[c1].subtreeSize);
            EXPECT_EQ(bsp.nodes[c0].firstIndex, n.firstIndex);
            EXPECT_EQ(bsp.nodes[c1].firstIndex, n.firstIndex + bsp.nodes[c0].indexCount);
            EXPECT_EQ(n.indexCount, bsp.nodes[c0].indexCount + bsp.nodes[c1].indexCount);
            EXPECT_EQ(bsp.nodes[c0].depth, n.depth + 1);
            EXPECT_TRUE(n.box.contains(bsp.nodes[c0].box));
            EXPECT_TRUE(n.box.contains(bsp.nodes[c1].box));
            // The children lie on their side of the plane, up to the on-plane band.
            const float tol = 1e-4f * std::max(1.0f, std::abs(n.split)) +
                              1e-4f * (n.box.max[n.axis] - n.box.min[n.axis]);
            EXPECT_LE(bsp.nodes[c0].box.max[n.axis], n.split + tol);
            EXPECT_GE(bsp.nodes[c1].box.min[n.axis], n.split - tol);
        }
    }
    EXPECT_EQ(nextLeafIndex, mesh.indices.size());
    EXPECT_EQ(leaves, bsp.stats.leaves);
    EXPECT_EQ(maxDepth, bsp.stats.depth);
}

LocalBsp buildOk(const Mesh& mesh, const LocalBspParams& params) {
    Expected<LocalBsp> r = buildLocalBsp(mesh, params);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
    return r.ok() ? r.take() : LocalBsp{};
}

void expectAreaConserved(const Mesh& before, const LocalBsp& bsp, double relTol = 1e-5) {
    const double a = surfaceArea(before), b = surfaceArea(bsp.mesh);
    EXPECT_NEAR(b, a, relTol * std::max(a, 1e-300)) << "area before " << a << " after " << b;
}

class BothMethods : public ::testing::TestWithParam<SplitMethod> {
protected:
    LocalBspParams params(std::uint32_t maxLeaf) const {
        LocalBspParams p;
        p.maxLeafTriangles = maxLeaf;
        p.method = GetParam();
        return p;
    }
};

TEST_P(BothMethods, SphereSplitsWithInvariantsAndConservedArea) {
    const Mesh mesh = sphereMesh(48, 32);
    const LocalBspParams p = params(200);
    const LocalBsp bsp = buildOk(mesh, p);
    checkInvariants(bsp, p);
    expectAreaConserved(mesh, bsp);
    EXPECT_GE(bsp.stats.leaves, mesh.triangleCount() / 200);
    EXPECT_GT(bsp.stats.trianglesAfter, bsp.stats.trianglesBefore);  // planes cut the sphere
    EXPECT_EQ(bsp.stats.stalledLeaves, 0u);
    for (const LocalBspNode& n : bsp.nodes)
        if (n.isLeaf()) {
            EXPECT_LE(n.indexCount / 3, p.maxLeafTriangles);
        }
}

TEST_P(BothMethods, OriginalVerticesKeptAndSplitVerticesShared) {
    const Mesh mesh = sphereMesh(32, 16);
    const LocalBsp bsp = buildOk(mesh, params(100));
    ASSERT_GE(bsp.mesh.positions.size(), mesh.positions.size());
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) EXPECT_EQ(bsp.mesh.positions[i], mesh.positions[i]);
    // Shared intersection vertices: far fewer new vertices than added triangles would need
    // if each piece had its own (3 per cut triangle).
    const std::size_t added = bsp.mesh.positions.size() - mesh.positions.size();
    const std::size_t addedTris = bsp.stats.trianglesAfter - bsp.stats.trianglesBefore;
    EXPECT_GT(added, 0u);
    EXPECT_LE(added, addedTris);
    for (const glm::vec3& n : bsp.mesh.normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-4f);
}

// A game's own attributes follow the split: carrying the input positions themselves as
// the attribute must give the split mesh's positions (the planes cut edges in double
// precision and clamp, so equal to float rounding), and a constant stays constant.
TEST_P(BothMethods, AttributesCarriedThroughTheSplitMatchTheSplitPositions) {
    const Mesh mesh = sphereMesh(32, 16);
    const LocalBsp bsp = buildOk(mesh, params(60));
    ASSERT_EQ(bsp.sourceVertexCount, mesh.positions.size());
    ASSERT_EQ(bsp.sourceVertexCount + bsp.splitVertices.size(), bsp.mesh.positions.size());
    ASSERT_GT(bsp.splitVertices.size(), 0u);
    std::vector<float> xyzw;  // position and a constant fourth component
    for (const glm::vec3& p : mesh.positions) xyzw.insert(xyzw.end(), {p.x, p.y, p.z, 0.25f});
    auto carried = carryAttributes(bsp, xyzw, 4);
    ASSERT_TRUE(carried.ok()) << carried.error().message;
    ASSERT_EQ(carried->size(), 4 * bsp.mesh.positions.size());
    for (std::size_t v = 0; v < bsp.mesh.positions.size(); ++v) {
        for (int k = 0; k < 3; ++k) EXPECT_NEAR((*carried)[4 * v + k], bsp.mesh.positions[v][k], 1e-5f) << v;
        EXPECT_FLOAT_EQ((*carried)[4 * v + 3], 0.25f);
    }
    // Bad sizes and missing provenance are errors, not crashes.
    EXPECT_FALSE(carryAttributes(bsp, xyzw, 0).ok());
    EXPECT_FALSE(carryAttributes(bsp, xyzw, 0xFFFFFFFFu).ok());  // vertices x 2^32 - 1 components: sizes checked, not overflowed
    EXPECT_FALSE(carryAttributes(bsp, std::span<const float>(xyzw).first(xyzw.size() - 1), 4).ok());
    LocalBsp handMade = bsp;
    handMade.splitVertices.clear();
    auto none = carryAttributes(handMade, xyzw, 4);
    ASSERT_FALSE(none.ok());
    EXPECT_NE(none.error().message.find("provenance"), std::string::npos) << none.error().message;
}

TEST_P(BothMethods, FlatGridTerminates) {
    const Mesh mesh = gridMesh(60);
    const LocalBspParams p = params(300);
    const LocalBsp bsp = buildOk(mesh, p);
    checkInvariants(bsp, p);
    expectAreaConserved(mesh, bsp);
    EXPECT_GT(bsp.stats.leaves, 1u);
}

TEST_P(BothMethods, IdenticalTrianglesMakeOneStalledLeaf) {
    Mesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    for (int i = 0; i < 500; ++i) mesh.indices.insert(mesh.indices.end(), {0u, 1u, 2u});
    const LocalBspParams p = params(10);
    const LocalBsp bsp = buildOk(mesh, p);
    checkInvariants(bsp, p);
    expectAreaConserved(mesh, bsp);
    EXPECT_EQ(bsp.nodes.size(), 1u);
    EXPECT_EQ(bsp.stats.stalledLeaves, 1u);
    EXPECT_EQ(bsp.stats.trianglesAfter, 500u);
}

TEST_P(BothMethods, ZeroAreaTrianglesTerminate) {
    Mesh mesh = sphereMesh(24, 12);
    const auto base = std::uint32_t(mesh.positions.size());
    for (int i = 0; i < 300; ++i) {
        const float x = -1.0f + 2.0f * float(i) / 300.0f;
        mesh.positions.insert(mesh.positions.end(), {{x, 0, 0}, {x + 0.5f, 0.5f, 0.5f}, {x + 1.0f, 1.0f, 1.0f}});
        const auto v = base + 3 * std::uint32_t(i);
        mesh.indices.insert(mesh.indices.end(), {v, v + 1, v + 2});  // collinear
        mesh.indices.insert(mesh.indices.end(), {v, v, v});          // a point
    }
    const LocalBspParams p = params(50);
    const LocalBsp bsp = buildOk(mesh, p);
    checkInvariants(bsp, p);
    expectAreaConserved(mesh, bsp);
}

TEST_P(BothMethods, SingleTriangleIsOneLeaf) {
    Mesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh.indices = {0, 1, 2};
    const LocalBspParams p = params(1);
    const LocalBsp bsp = buildOk(mesh, p);
    checkInvariants(bsp, p);
    EXPECT_FALSE(bsp.hasTree());
    EXPECT_EQ(bsp.root().indexCount, 3u);
    ASSERT_EQ(bsp.mesh.normals.size(), 3u);
    EXPECT_NEAR(bsp.mesh.normals[0].z, 1.0f, 1e-6f);  // computed since the input had none
}

TEST_P(BothMethods, ExtremeOffsetsAndScalesKeepInvariants) {
    const Mesh base = sphereMesh(32, 20);
    for (const auto& [scale, offset] : {std::pair{1.0f, glm::vec3(1e7f)}, std::pair{1e-6f, glm::vec3(0.0f)},
                                       std::pair{1e6f, glm::vec3(0.0f)}, std::pair{1e-6f, glm::vec3(1.0f)},
                                       std::pair{1e3f, glm::vec3(1e7f, -1e7f, 3e6f)}}) {
        SCOPED_TRACE("scale " + std::to_string(scale) + " offset " + std::to_string(offset.x));
        const Mesh mesh = transformed(base, scale, offset);
        const LocalBspParams p = params(100);
        const LocalBsp bsp = buildOk(mesh, p);
        checkInvariants(bsp, p);
        // New vertices are floats: at |x| = 1e7 they land on a grid of 1 unit, which is
        // ~1e-3 of this sphere's edges, so conservation holds only to that precision there.
        const float ulp = std::nextafter(glm::length(offset), INFINITY) - glm::length(offset);
        const float edge = scale * 0.2f;
        expectAreaConserved(mesh, bsp, std::max(1e-5, 2.0 * double(ulp) / double(edge)));
        if (offset == glm::vec3(0.0f)) {
            EXPECT_GT(bsp.stats.leaves, 1u);  // well-resolved floats: real splits happen
        }
    }
}

TEST_P(BothMethods, DepthLimitIsRespected) {
    const Mesh mesh = sphereMesh(48, 32);
    LocalBspParams p = params(1);
    p.maxDepth = 3;
    const LocalBsp bsp = buildOk(mesh, p);
    checkInvariants(bsp, p);
    EXPECT_EQ(bsp.stats.depth, 3u);
    EXPECT_EQ(bsp.stats.leaves, 8u);
}

INSTANTIATE_TEST_SUITE_P(LocalBsp, BothMethods, ::testing::Values(SplitMethod::SpatialMedian, SplitMethod::Sah),
                         [](const ::testing::TestParamInfo<SplitMethod>& param) {
                             return std::string(param.param == SplitMethod::Sah ? "Sah" : "SpatialMedian");
                         });

TEST(LocalBsp, MeshBelowThresholdIsSingleLeaf) {
    const Mesh mesh = sphereMesh(16, 8);
    LocalBspParams p;
    p.maxLeafTriangles = std::uint32_t(mesh.triangleCount());
    p.optimizeOrder = false;  // the triangles exactly as given (LeafOrder... tests the reordering)
    const LocalBsp bsp = buildOk(mesh, p);
    checkInvariants(bsp, p);
    EXPECT_FALSE(bsp.hasTree());
    EXPECT_EQ(bsp.mesh.indices, mesh.indices);
    EXPECT_EQ(bsp.root().box.min, mesh.bounds().min);
    EXPECT_EQ(bsp.root().box.max, mesh.bounds().max);
}

TEST(LocalBsp, EmptyMeshIsSingleEmptyLeaf) {
    const LocalBsp bsp = buildOk(Mesh{}, LocalBspParams{});
    ASSERT_EQ(bsp.nodes.size(), 1u);
    EXPECT_TRUE(bsp.root().isLeaf());
    EXPECT_EQ(bsp.root().indexCount, 0u);
    EXPECT_TRUE(bsp.root().box.empty());
    EXPECT_EQ(bsp.stats.leaves, 1u);
}

TEST(LocalBsp, NudgingNeverAddsTrianglesAtASplit) {
    // A sphere whose equator rings sit exactly at the median would be cut along edges;
    // an offset centre makes the median cut through triangles so the nudge has work.
    const Mesh mesh = sphereMesh(40, 27, 1.0f, glm::vec3(0.013f, 0.0f, 0.0f));
    for (const SplitMethod method : {SplitMethod::SpatialMedian, SplitMethod::Sah}) {
        LocalBspParams p;
        p.maxLeafTriangles = 1;
        p.maxDepth = 1;  // exactly one plane
        p.method = method;
        p.nudgeFraction = 0.0f;
        const LocalBsp plain = buildOk(mesh, p);
        p.nudgeFraction = 0.25f;
        const LocalBsp nudged = buildOk(mesh, p);
        checkInvariants(nudged, p);
        EXPECT_LE(nudged.stats.trianglesAfter, plain.stats.trianglesAfter);
        expectAreaConserved(mesh, nudged);
    }
}

TEST(LocalBsp, BadInputIsAnError) {
    Mesh bad = sphereMesh(8, 4);
    bad.indices.push_back(100000);
    bad.indices.push_back(0);
    bad.indices.push_back(1);
    Expected<LocalBsp> r = buildLocalBsp(bad);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("out of range"), std::string::npos) << r.error().message;

    const Mesh good = sphereMesh(8, 4);
    LocalBspParams p;
    p.maxLeafTriangles = 0;
    r = buildLocalBsp(good, p);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("maxLeafTriangles"), std::string::npos);
    for (const float f : {-0.1f, 0.6f, std::nanf(""), INFINITY}) {
        p = {};
        p.nudgeFraction = f;
        r = buildLocalBsp(good, p);
        ASSERT_FALSE(r.ok()) << f;
        EXPECT_NE(r.error().message.find("nudgeFraction"), std::string::npos);
    }
    p = {};
    p.maxDepth = kLocalBspMaxDepth + 1;
    r = buildLocalBsp(good, p);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("maxDepth"), std::string::npos);
}

// A closed cube, outward (counter-clockwise seen from outside), side 2 around the origin.
Mesh cubeMesh(bool inward = false) {
    Mesh m;
    for (int i = 0; i < 8; ++i)
        m.positions.push_back({(i & 1) ? 1.0f : -1.0f, (i & 2) ? 1.0f : -1.0f, (i & 4) ? 1.0f : -1.0f});
    m.indices = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    if (inward)
        for (std::size_t t = 0; t < m.indices.size(); t += 3) std::swap(m.indices[t + 1], m.indices[t + 2]);
    return m;
}

double signedVolume(const Mesh& m) {
    double v = 0.0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3)
        v += glm::dot(glm::dvec3(m.positions[m.indices[t]]),
                      glm::cross(glm::dvec3(m.positions[m.indices[t + 1]]), glm::dvec3(m.positions[m.indices[t + 2]])));
    return v / 6.0;
}

// Each node's triangles as a sorted list of (rotated so the smallest index leads) triples:
// what must survive any reordering inside a leaf, winding included.
std::vector<std::array<std::uint32_t, 3>> trianglesOf(const LocalBsp& bsp, const LocalBspNode& n) {
    std::vector<std::array<std::uint32_t, 3>> out;
    for (std::uint32_t k = n.firstIndex; k < n.firstIndex + n.indexCount; k += 3) {
        std::array<std::uint32_t, 3> t{bsp.mesh.indices[k], bsp.mesh.indices[k + 1], bsp.mesh.indices[k + 2]};
        std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
        out.push_back(t);
    }
    std::sort(out.begin(), out.end());
    return out;
}

TEST(LocalBsp, LeafOrderKeepsEveryNodesTrianglesAndWinding) {
    const Mesh sphere = sphereMesh(96, 64);
    LocalBspParams p;
    p.maxLeafTriangles = 1500;
    p.optimizeOrder = false;
    const LocalBsp loadOrder = buildOk(sphere, p);
    p.optimizeOrder = true;
    const LocalBsp ordered = buildOk(sphere, p);
    checkInvariants(ordered, p);
    ASSERT_EQ(ordered.nodes.size(), loadOrder.nodes.size());
    ASSERT_GT(ordered.stats.leaves, 4u);
    EXPECT_NE(ordered.mesh.indices, loadOrder.mesh.indices) << "nothing was reordered";
    for (std::size_t i = 0; i < ordered.nodes.size(); ++i) {
        ASSERT_EQ(ordered.nodes[i].firstIndex, loadOrder.nodes[i].firstIndex);
        ASSERT_EQ(ordered.nodes[i].indexCount, loadOrder.nodes[i].indexCount);
        EXPECT_EQ(trianglesOf(ordered, ordered.nodes[i]), trianglesOf(loadOrder, loadOrder.nodes[i])) << "node " << i;
    }
    EXPECT_EQ(ordered.mesh.positions, loadOrder.mesh.positions);
}

TEST(LocalBsp, FacePolicyDecidesTheFaceMode) {
    LocalBspParams p;
    p.maxLeafTriangles = 4;  // split the cube: orientation must be decided before splitting
    EXPECT_EQ(buildOk(cubeMesh(), p).faces, FaceMode::CullBack);

    // Inward: flipped before splitting, so every part of the split mesh faces outwards.
    const LocalBsp flipped = buildOk(cubeMesh(true), p);
    EXPECT_EQ(flipped.faces, FaceMode::CullBack);
    EXPECT_NEAR(signedVolume(flipped.mesh), 8.0, 1e-5);

    Mesh open = cubeMesh();
    open.indices.resize(open.indices.size() - 6);  // one face missing: its hole shows the inside
    EXPECT_EQ(buildOk(open, p).faces, FaceMode::TwoSided);

    p.faces = FacePolicy::CullBack;
    const LocalBsp forced = buildOk(open, p);
    EXPECT_EQ(forced.faces, FaceMode::CullBack);
    p.faces = FacePolicy::TwoSided;
    const LocalBsp twoSided = buildOk(cubeMesh(true), p);
    EXPECT_EQ(twoSided.faces, FaceMode::TwoSided);
    EXPECT_NEAR(signedVolume(twoSided.mesh), -8.0, 1e-5) << "TwoSided leaves the winding as it was";
}

TEST(LocalBsp, BunnyDefaultsMatchThePaper) {
    const std::filesystem::path path = std::filesystem::path(DYNCULL_TEST_DATA_DIR) / "bun_zipper.ply";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
    Expected<Scene> scene = loadScene(path);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->meshes.size(), 1u);
    const Mesh& mesh = scene->meshes[0];
    ASSERT_EQ(mesh.triangleCount(), 69451u);
    for (const SplitMethod method : {SplitMethod::SpatialMedian, SplitMethod::Sah}) {
        LocalBspParams p;
        p.method = method;
        const LocalBsp bsp = buildOk(mesh, p);
        checkInvariants(bsp, p);
        expectAreaConserved(mesh, bsp);
        EXPECT_GE(bsp.stats.leaves, 20u);
        EXPECT_LE(bsp.stats.leaves, 30u);
        EXPECT_LE(double(bsp.stats.trianglesAfter), 1.12 * double(bsp.stats.trianglesBefore));
        std::printf("bunny %s: %u leaves, %zu -> %zu triangles (+%.1f%%), depth %u, %.1f ms\n",
                    method == SplitMethod::Sah ? "sah" : "median", bsp.stats.leaves, bsp.stats.trianglesBefore,
                    bsp.stats.trianglesAfter,
                    100.0 * (double(bsp.stats.trianglesAfter) / double(bsp.stats.trianglesBefore) - 1.0),
                    bsp.stats.depth, bsp.stats.buildMs);
    }
}

}  // namespace
}  // namespace dyncull
