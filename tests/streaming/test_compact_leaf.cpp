// CompactLeaf against the mesh it encodes: positions within half a quantisation step (and
// inside the box), normals within 0.01 degrees, indices exact; flat and far-off boxes, wide
// indices, and the byte count the node file predicts.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "dyncull/streaming/compact_leaf.hpp"
#include "dyncull/streaming/streamed_model.hpp"

namespace dyncull {
namespace {

Mesh randomMesh(std::uint32_t vertices, std::uint32_t triangles, const Aabb& box, std::mt19937& rng) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f), s(-1.0f, 1.0f);
    Mesh m;
    for (std::uint32_t i = 0; i < vertices; ++i) {
        m.positions.push_back(box.min + (box.max - box.min) * glm::vec3(u(rng), u(rng), u(rng)));
        glm::vec3 n(s(rng), s(rng), s(rng));
        if (i % 7 == 0) n = {0.0f, 0.0f, i % 2 ? 1.0f : -1.0f};  // the octahedron's poles and folds
        if (i % 11 == 0) n = {1.0f, 0.0f, 0.0f};
        m.normals.push_back(glm::normalize(n));
    }
    std::uniform_int_distribution<std::uint32_t> idx(0, vertices - 1);
    for (std::uint32_t i = 0; i < triangles * 3; ++i) m.indices.push_back(idx(rng));
    m.indices[0] = vertices - 1;  // the largest index round-trips too
    return m;
}

/// Every property the header promises, checked vertex by vertex.
void expectFaithful(const Mesh& in, const Aabb& box) {
    CompactLeaf c;
    compactLeaf(in, box, c);
    StreamedLeaf counts;
    counts.vertexCount = static_cast<std::uint32_t>(in.positions.size());
    counts.triangleCount = static_cast<std::uint32_t>(in.indices.size() / 3);
    EXPECT_EQ(c.bytes(), compactLeafBytes(counts));
    EXPECT_LT(c.bytes(), leafBytes(in));
    Mesh out;
    expandLeaf(c, out);
    ASSERT_EQ(out.positions.size(), in.positions.size());
    EXPECT_EQ(out.indices, in.indices);
    const glm::vec3 extent = box.max - box.min;
    for (std::size_t i = 0; i < in.positions.size(); ++i) {
        for (int a = 0; a < 3; ++a) {
            // Half a step, plus the float rounding of min + q * step at these magnitudes.
            const float magnitude = std::max(std::abs(box.min[a]), std::abs(box.max[a]));
            const float tolerance = 0.5f * extent[a] / 65535.0f + 4.0f * magnitude * 1.2e-7f;
            EXPECT_NEAR(out.positions[i][a], in.positions[i][a], tolerance) << "vertex " << i << " axis " << a;
            EXPECT_GE(out.positions[i][a], box.min[a]);
            EXPECT_LE(out.positions[i][a], box.max[a]);
        }
        EXPECT_NEAR(glm::length(out.normals[i]), 1.0f, 1e-5f);
        // The angle in double, from the cross product: acos of a float dot product cannot
        // resolve angles this small.
        const glm::dvec3 p(out.normals[i]), q(in.normals[i]);
        const double degrees = std::atan2(glm::length(glm::cross(p, q)), glm::dot(p, q)) * 180.0 / 3.141592653589793;
        EXPECT_LT(degrees, 0.01) << "normal " << i;
    }
}

TEST(CompactLeaf, RoundTripsWithinHalfAStep) {
    std::mt19937 rng(5);
    const Aabb box = Aabb::fromMinMax({-3.0f, 0.5f, 10.0f}, {4.0f, 0.75f, 200.0f});
    expectFaithful(randomMesh(500, 900, box, rng), box);
}

TEST(CompactLeaf, FlatAndFarOffBoxes) {
    std::mt19937 rng(6);
    // No extent along y: that axis comes back exactly.
    const Aabb flat = Aabb::fromMinMax({0.0f, 2.0f, 0.0f}, {1.0f, 2.0f, 1.0f});
    Mesh m = randomMesh(64, 64, flat, rng);
    expectFaithful(m, flat);
    CompactLeaf c;
    compactLeaf(m, flat, c);
    Mesh out;
    expandLeaf(c, out);
    for (const glm::vec3& p : out.positions) EXPECT_EQ(p.y, 2.0f);
    // Far from the origin, a small box: float spacing dominates the step.
    const Aabb far = Aabb::fromMinMax({1e6f, -2e6f, 5e5f}, {1e6f + 3.0f, -2e6f + 1.0f, 5e5f + 2.0f});
    expectFaithful(randomMesh(64, 64, far, rng), far);
    // A single point.
    const Aabb point = Aabb::fromMinMax({1.0f, 1.0f, 1.0f}, {1.0f, 1.0f, 1.0f});
    expectFaithful(randomMesh(3, 1, point, rng), point);
}

TEST(CompactLeaf, MoreThan65536VerticesTakeWideIndices) {
    std::mt19937 rng(7);
    const Aabb box = Aabb::fromMinMax({0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f});
    const Mesh m = randomMesh(70000, 300, box, rng);
    CompactLeaf c;
    compactLeaf(m, box, c);
    EXPECT_TRUE(c.wideIndices);
    expectFaithful(m, box);
    const Mesh small = randomMesh(0x10000, 10, box, rng);  // indices up to 65,535 still fit
    compactLeaf(small, box, c);
    EXPECT_FALSE(c.wideIndices);
    expectFaithful(small, box);
}

// Counts from the node file near 2^32: the byte count is exact in 64 bits, wide indices included.
TEST(CompactLeaf, ByteCountsOfCountsNear2To32) {
    StreamedLeaf leaf;
    leaf.vertexCount = 0xffffffffu;
    leaf.triangleCount = 0xffffffffu;
    EXPECT_EQ(compactLeafBytes(leaf), (std::uint64_t{0xffffffffu} * 5 + std::uint64_t{0xffffffffu} * 6) * 2);
    leaf.vertexCount = 0x10000;  // the last count with narrow indices
    leaf.triangleCount = 1;
    EXPECT_EQ(compactLeafBytes(leaf), (std::size_t{0x10000} * 5 + 3) * 2);
}

TEST(CompactLeaf, PositionsOutsideTheBoxAreClampedIntoIt) {
    const Aabb box = Aabb::fromMinMax({0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f});
    Mesh m;
    m.positions = {{-1.0f, 0.5f, 2.0f}, {0.5f, 0.5f, 0.5f}, {1.0f, 1.0f, 1.0f}};
    m.normals.assign(3, {0.0f, 0.0f, 1.0f});
    m.indices = {0, 1, 2};
    CompactLeaf c;
    compactLeaf(m, box, c);
    Mesh out;
    expandLeaf(c, out);
    EXPECT_EQ(out.positions[0], glm::vec3(0.0f, out.positions[0].y, 1.0f));
    EXPECT_EQ(out.positions[2], glm::vec3(1.0f));
}

}  // namespace
}  // namespace dyncull
