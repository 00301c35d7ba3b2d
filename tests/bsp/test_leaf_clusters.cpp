// Tests for leaf clusters (clustersOf, the meshlet order of optimizeLeafOrder) and their
// back-face test against the brute-force oracle: a cluster called back-facing has no
// triangle facing the eye, computed exactly per triangle in double.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <set>

#include "dyncull/bsp/local_bsp.hpp"
#include "dyncull/loaders/loaders.hpp"
#include "objects/sphere_grid.hpp"

namespace dyncull {
namespace {

Mesh sphereMesh(int slices, int stacks) { return test::sphereGridMesh(slices, stacks); }

LocalBsp build(const Mesh& mesh, std::uint32_t leafTriangles) {
    LocalBspParams p;
    p.maxLeafTriangles = leafTriangles;
    auto bsp = buildLocalBsp(mesh, p);
    EXPECT_TRUE(bsp.ok());
    return std::move(*bsp);
}

// Clusters tile each leaf's range in order, within the size limits, with boxes around
// their vertices; nodeFirst gives every subtree's clusters.
void expectTiling(const LocalBsp& bsp) {
    const LeafClusters& c = bsp.clusters;
    ASSERT_TRUE(c.builtFor(bsp.nodes.size()));
    for (std::uint32_t n = 0; n < bsp.nodes.size(); ++n) {
        const LocalBspNode& node = bsp.nodes[n];
        const auto clusters = c.ofSubtree(n, node.subtreeSize);
        std::uint32_t next = node.firstIndex;
        for (const LeafCluster& cl : clusters) {
            EXPECT_EQ(cl.firstIndex, next) << "node " << n;
            EXPECT_GT(cl.indexCount, 0u);
            EXPECT_LE(cl.indexCount / 3, kClusterMaxTriangles);
            std::set<std::uint32_t> vertices;
            for (std::uint32_t i = cl.firstIndex; i < cl.firstIndex + cl.indexCount; ++i) {
                const std::uint32_t v = bsp.mesh.indices[i];
                vertices.insert(v);
                EXPECT_TRUE(cl.box.contains(bsp.mesh.positions[v]));
            }
            EXPECT_LE(vertices.size(), kClusterMaxVertices);
            next = cl.firstIndex + cl.indexCount;
        }
        if (node.indexCount > 0) {
            EXPECT_EQ(next, node.firstIndex + node.indexCount) << "node " << n;
        }
    }
}

// The oracle: every triangle with an area faces away from `eye` (or is seen edge-on).
bool allFaceAway(const LocalBsp& bsp, const LeafCluster& cl, const glm::dvec3& eye) {
    for (std::uint32_t i = cl.firstIndex; i < cl.firstIndex + cl.indexCount; i += 3) {
        const glm::dvec3 a(bsp.mesh.positions[bsp.mesh.indices[i]]), b(bsp.mesh.positions[bsp.mesh.indices[i + 1]]),
            c(bsp.mesh.positions[bsp.mesh.indices[i + 2]]);
        if (glm::dot(glm::cross(b - a, c - a), a - eye) < 0.0) return false;
    }
    return true;
}

bool allFaceAwayAlong(const LocalBsp& bsp, const LeafCluster& cl, const glm::dvec3& direction) {
    for (std::uint32_t i = cl.firstIndex; i < cl.firstIndex + cl.indexCount; i += 3) {
        const glm::dvec3 a(bsp.mesh.positions[bsp.mesh.indices[i]]), b(bsp.mesh.positions[bsp.mesh.indices[i + 1]]),
            c(bsp.mesh.positions[bsp.mesh.indices[i + 2]]);
        if (glm::dot(glm::cross(b - a, c - a), direction) < 0.0) return false;
    }
    return true;
}

// Random eyes around the model (near, inside and far) and random view directions: never a
// back-facing verdict the oracle refutes, and on a closed mesh some verdicts at all.
void expectConesConservative(const LocalBsp& bsp, std::uint32_t seed) {
    std::mt19937 rng(seed);
    const Aabb box = bsp.root().box;
    const glm::dvec3 centre = glm::dvec3(box.center());
    const double size = glm::length(glm::dvec3(box.max) - glm::dvec3(box.min));
    std::uniform_real_distribution<double> unit(-1.0, 1.0), scale(0.01, 4.0);
    std::size_t culled = 0, tests = 0;
    for (int k = 0; k < 60; ++k) {
        const glm::dvec3 dir = glm::normalize(glm::dvec3(unit(rng), unit(rng), unit(rng)) + glm::dvec3(1e-9));
        const glm::dvec3 eye = centre + dir * size * scale(rng);
        for (const LeafCluster& cl : bsp.clusters.clusters) {
            ++tests;
            if (cl.backFacingFrom(eye)) {
                ++culled;
                ASSERT_TRUE(allFaceAway(bsp, cl, eye)) << "cluster at index " << cl.firstIndex << ", eye " << eye.x << " "
                                                       << eye.y << " " << eye.z;
            }
            if (cl.backFacingAlong(dir)) {
                ASSERT_TRUE(allFaceAwayAlong(bsp, cl, dir));
            }
        }
    }
    EXPECT_GT(culled, tests / 10) << "the cones cull almost nothing";
}

TEST(LeafClusters, TileTheLeavesOfASphereWithinTheLimits) {
    const LocalBsp bsp = build(sphereMesh(96, 48), 2000);
    ASSERT_GT(bsp.stats.leaves, 2u);
    expectTiling(bsp);
    // meshoptimizer's meshlets are nearly full and the greedy cut finds them again. The
    // vertex limit binds first: a patch of V grid vertices holds about 2V less its
    // perimeter triangles (38.9 a cluster at 32 vertices, 80 at 64).
    const double perCluster = double(bsp.mesh.triangleCount()) / double(bsp.clusters.clusters.size());
    EXPECT_GT(perCluster, 1.1 * kClusterMaxVertices);
}

TEST(LeafClusters, ConesNeverCallAVisibleTriangleBackFacing) {
    expectConesConservative(build(sphereMesh(64, 32), 1000), 1);
}

TEST(LeafClusters, AnyIndexOrderIsCutToo) {
    // A tree from a cache or a game keeps its order: clustersOf still tiles it.
    LocalBspParams p;
    p.maxLeafTriangles = 500;
    p.optimizeOrder = false;
    auto bsp = buildLocalBsp(sphereMesh(40, 20), p);
    ASSERT_TRUE(bsp.ok());
    expectTiling(*bsp);
    expectConesConservative(*bsp, 2);
}

TEST(LeafClusters, DegenerateInputHasClustersThatNeverCull) {
    // Zero-area triangles only (collinear points): no normal, no cone verdict.
    Mesh m;
    m.name = "collinear";
    for (int i = 0; i < 30; ++i) m.positions.push_back({float(i), 0.0f, 0.0f});
    for (std::uint32_t i = 0; i + 2 < 30; ++i) m.indices.insert(m.indices.end(), {i, i + 1, i + 2});
    LocalBspParams p;
    p.faces = FacePolicy::TwoSided;
    auto bsp = buildLocalBsp(m, p);
    ASSERT_TRUE(bsp.ok());
    expectTiling(*bsp);
    for (const LeafCluster& cl : bsp->clusters.clusters) {
        EXPECT_FALSE(cl.backFacingFrom({5.0, 3.0, 1.0}));
        EXPECT_FALSE(cl.backFacingAlong({0.0, 0.0, 1.0}));
    }
    // An empty mesh: one empty leaf, no clusters.
    auto empty = buildLocalBsp(Mesh{}, {});
    ASSERT_TRUE(empty.ok());
    EXPECT_TRUE(empty->clusters.builtFor(empty->nodes.size()));
    EXPECT_TRUE(empty->clusters.clusters.empty());
}

TEST(LeafClusters, BunnyClustersAreTightAndConservative) {
    const std::filesystem::path path = std::filesystem::path(DYNCULL_TEST_DATA_DIR) / "bun_zipper.ply";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "no " << path;
    Expected<Scene> scene = loadScene(path);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->meshes.size(), 1u);
    const LocalBsp bsp = build(scene->meshes[0], 800);
    expectTiling(bsp);
    const double perCluster = double(bsp.mesh.triangleCount()) / double(bsp.clusters.clusters.size());
    // As many as meshoptimizer built: 37.3 a cluster at 32 vertices, 80.4 at 64.
    EXPECT_GT(perCluster, 1.1 * kClusterMaxVertices);
    expectConesConservative(bsp, 3);
}

}  // namespace
}  // namespace dyncull
