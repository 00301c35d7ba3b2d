// k-DOPs: intervals and boundary meshes. Oracles: every input point inside the mesh (by
// explicit face-plane tests), the mesh closed/convex/outward (explicit edge and plane
// checks), its vertex set equal to the brute-force intersection of plane triples, the
// paper's triangle bounds (44/60/92), nesting 26 in 18 and 14 in the AABB, and the
// same after affine transforms with non-uniform scale.
#include <gtest/gtest.h>

#include <cmath>

#include "dyncull/objects/kdop.hpp"
#include "objects/convex_checks.hpp"
#include "objects/volume_test_points.hpp"

using namespace dyncull;

namespace {

const KdopType kTypes[] = {KdopType::K14, KdopType::K18, KdopType::K26};

std::size_t maxTriangles(KdopType t) { return t == KdopType::K14 ? 44 : t == KdopType::K18 ? 60 : 92; }

/// Every vertex of `inner` inside `outer` (within eps).
bool meshInside(const ConvexMesh& inner, const ConvexMesh& outer, double eps, double scale) {
    for (const glm::vec3& v : inner.vertices)
        if (!test::insideConvexMesh(outer.vertices, outer.indices, glm::dvec3(v), eps, scale)) return false;
    return true;
}

/// Every triangle lies in one of the k-DOP's planes and winds around its outward normal
/// (exact plane normals, so slivers of thin slabs are checked as well as big faces; a
/// winding within float noise of zero counts as either way).
std::string trianglesOnPlanes(const ConvexMesh& m, const Kdop& k, double eps) {
    const std::vector<KdopPlane> planes = kdopPlanes(k);
    const double ulp = 1.1920929e-7 * std::max(k.scale(), 1e-30);
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const glm::dvec3 a(m.vertices[m.indices[t]]), b(m.vertices[m.indices[t + 1]]), c(m.vertices[m.indices[t + 2]]);
        const double edge = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
        bool onPlane = false, outward = false;
        for (const KdopPlane& p : planes) {
            if (std::abs(glm::dot(p.normal, a) - p.offset) > eps || std::abs(glm::dot(p.normal, b) - p.offset) > eps ||
                std::abs(glm::dot(p.normal, c) - p.offset) > eps)
                continue;
            onPlane = true;
            outward |= glm::dot(glm::cross(b - a, c - a), p.normal) >= -8.0 * ulp * edge;
        }
        if (!onPlane) return "triangle " + std::to_string(t / 3) + " lies in no bounding plane";
        if (!outward) return "triangle " + std::to_string(t / 3) + " winds inward";
    }
    return {};
}

}  // namespace

TEST(Kdop, IntervalsAreTheExtremesAlongEachDirection) {
    const std::vector<glm::vec3> pts = {{0, 0, 0}, {1, 2, 3}, {-1, 0.5f, 2}};
    const Kdop k = computeKdop(KdopType::K26, pts);
    EXPECT_DOUBLE_EQ(k.lo[0], -1.0);
    EXPECT_DOUBLE_EQ(k.hi[2], 3.0);
    EXPECT_DOUBLE_EQ(k.hi[3], 6.0);    // (1,1,1).(1,2,3)
    EXPECT_DOUBLE_EQ(k.lo[10], -1.5);  // (1,-1,0).(-1,0.5,2)
    EXPECT_EQ(k.aabb().min, glm::vec3(-1, 0, 0));
    EXPECT_EQ(kdopPlanes(restrictKdop(k, KdopType::K14)).size(), 14u);
    EXPECT_EQ(kdopPlanes(restrictKdop(k, KdopType::K18)).size(), 18u);
    EXPECT_EQ(kdopPlanes(k).size(), 26u);
    EXPECT_TRUE(computeKdop(KdopType::K14, {}).empty);
    EXPECT_TRUE(kdopBoundary(computeKdop(KdopType::K26, {})).vertices.empty());
}

TEST(Kdop, BoundaryIsClosedConvexOutwardAndContainsEveryPoint) {
    for (const test::NamedPoints& set : test::volumeTestPointSets()) {
        const Kdop k26 = computeKdop(KdopType::K26, set.points);
        const double scale = test::lengthScale(set.points);
        const double eps = 1e-5 * scale;  // 10 plane epsilons: float vertices of the mesh
        for (KdopType t : kTypes) {
            SCOPED_TRACE(set.name + ", " + std::to_string(kdopK(t)) + "-DOP");
            const Kdop k = restrictKdop(k26, t);
            const ConvexMesh m = kdopBoundary(k);
            EXPECT_EQ(test::checkClosedConvexOutward(m.vertices, m.indices, eps, scale), "");
            EXPECT_EQ(trianglesOnPlanes(m, k, 2.0 * kdopPlaneEpsilon(k)), "");
            EXPECT_LE(m.triangleCount(), maxTriangles(t));
            EXPECT_LE(m.vertices.size(), 48u);
            for (const glm::vec3& p : set.points) {
                ASSERT_TRUE(k.contains(glm::dvec3(p), 0.0)) << "intervals are exact";
                ASSERT_TRUE(test::insideConvexMesh(m.vertices, m.indices, glm::dvec3(p), eps, scale));
            }
            // Every mesh vertex lies on the k-DOP: inside all slabs (grown by eps).
            for (const glm::vec3& v : m.vertices) ASSERT_TRUE(k.contains(glm::dvec3(v), eps + 4.0 * kdopPlaneEpsilon(k)));
            EXPECT_GT(meshVolume(m.vertices, m.indices), 0.0);
        }
    }
}

TEST(Kdop, VerticesMatchTheBruteForceIntersectionOfPlaneTriples) {
    for (const test::NamedPoints& set : test::volumeTestPointSets()) {
        const Kdop k26 = computeKdop(KdopType::K26, set.points);
        for (KdopType t : kTypes) {
            SCOPED_TRACE(set.name + ", " + std::to_string(kdopK(t)) + "-DOP");
            const Kdop k = restrictKdop(k26, t);
            const ConvexMesh m = kdopBoundary(k);
            const double planeEps = kdopPlaneEpsilon(k);
            // Cuts shallower than the plane epsilon are skipped on purpose, so vertices
            // match within a few of them (float output adds ulps of the coordinates).
            const double tol = 8.0 * planeEps;
            const std::vector<glm::dvec3> brute = kdopVerticesBruteForce(k, 1e-3 * planeEps);
            for (const glm::vec3& v : m.vertices) {
                double best = 1e300;
                for (const glm::dvec3& b : brute) best = std::min(best, glm::length(glm::dvec3(v) - b));
                EXPECT_LE(best, tol) << "mesh vertex not a k-DOP vertex";
            }
            for (const glm::dvec3& b : brute) {
                double best = 1e300;
                for (const glm::vec3& v : m.vertices) best = std::min(best, glm::length(glm::dvec3(v) - b));
                EXPECT_LE(best, tol) << "k-DOP vertex missing from the mesh";
            }
        }
    }
}

TEST(Kdop, GenericShapesReachThePapersTriangleCounts) {
    const auto sets = test::volumeTestPointSets();
    const test::NamedPoints& sphere = sets[1];
    ASSERT_EQ(sphere.name, "sphere");
    const Kdop k26 = computeKdop(KdopType::K26, sphere.points);
    EXPECT_EQ(kdopBoundary(restrictKdop(k26, KdopType::K14)).triangleCount(), 44u);
    EXPECT_EQ(kdopBoundary(restrictKdop(k26, KdopType::K18)).triangleCount(), 60u);
    EXPECT_EQ(kdopBoundary(k26).triangleCount(), 92u);
    EXPECT_EQ(kdopBoundary(k26).vertices.size(), 48u);
}

TEST(Kdop, CoincidentPlanesGiveTheBoxOrTheOctahedron) {
    // The corner and edge planes of a box's corners touch it only at vertices and edges.
    const auto sets = test::volumeTestPointSets();
    const ConvexMesh box = kdopBoundary(computeKdop(KdopType::K26, sets[3].points));
    EXPECT_EQ(box.vertices.size(), 8u);
    EXPECT_EQ(box.triangleCount(), 12u);
    // The octahedron's points: the 14-DOP's corner planes are its faces; the axis planes
    // touch it at its six vertices only.
    const ConvexMesh oct = kdopBoundary(computeKdop(KdopType::K14, sets[4].points));
    EXPECT_EQ(oct.vertices.size(), 6u);
    EXPECT_EQ(oct.triangleCount(), 8u);
    EXPECT_NEAR(meshVolume(oct.vertices, oct.indices), 4.0 / 3.0, 1e-5);
}

TEST(Kdop, NestingTwentySixInEighteenAndFourteenInTheAabb) {
    for (const test::NamedPoints& set : test::volumeTestPointSets()) {
        SCOPED_TRACE(set.name);
        const double scale = test::lengthScale(set.points), eps = 1e-5 * scale;
        const Kdop k26 = computeKdop(KdopType::K26, set.points);
        const ConvexMesh m26 = kdopBoundary(k26), m18 = kdopBoundary(restrictKdop(k26, KdopType::K18)),
                         m14 = kdopBoundary(restrictKdop(k26, KdopType::K14));
        const Aabb box = k26.aabb();
        ConvexMesh aabb;
        for (int i = 0; i < 8; ++i)
            aabb.vertices.push_back({(i & 1) ? box.max.x : box.min.x, (i & 2) ? box.max.y : box.min.y, (i & 4) ? box.max.z : box.min.z});
        aabb.indices.assign(kBoxTriangles.begin(), kBoxTriangles.end());
        EXPECT_TRUE(meshInside(m26, m18, eps, scale));
        EXPECT_TRUE(meshInside(m26, m14, eps, scale));
        EXPECT_TRUE(meshInside(m18, aabb, eps, scale));
        EXPECT_TRUE(meshInside(m14, aabb, eps, scale));
        // Volumes shrink the same way (within the thin-slab widening of degenerate sets).
        const double slack = 1e-3 * std::pow(test::lengthScale(set.points), 3.0) * 1e-3;
        EXPECT_LE(meshVolume(m26.vertices, m26.indices), meshVolume(m18.vertices, m18.indices) + slack);
        EXPECT_LE(meshVolume(m26.vertices, m26.indices), meshVolume(m14.vertices, m14.indices) + slack);
    }
}

TEST(Kdop, AffineTransformsKeepContainmentAndShape) {
    // Section 3.3: under rigid (here also non-uniformly scaled) motion the boundary
    // vertices are transformed and the triangles kept.
    glm::mat4 m(1.0f);
    m = glm::mat4(glm::mat3(test::testRotation(1.1f, -0.4f, 2.0f)) * glm::mat3(glm::vec3(3.0f, 0, 0), glm::vec3(0, 0.2f, 0), glm::vec3(0, 0, 1.7f)));
    m[3] = glm::vec4(-40.0f, 12.0f, 300.0f, 1.0f);
    for (const test::NamedPoints& set : test::volumeTestPointSets()) {
        const Kdop k26 = computeKdop(KdopType::K26, set.points);
        std::vector<glm::vec3> moved;
        for (const glm::vec3& p : set.points) moved.push_back(glm::vec3(m * glm::vec4(p, 1.0f)));
        const double scale = test::lengthScale(moved), eps = 1e-5 * scale;
        for (KdopType t : kTypes) {
            SCOPED_TRACE(set.name + ", " + std::to_string(kdopK(t)) + "-DOP");
            ConvexMesh mesh = kdopBoundary(restrictKdop(k26, t));
            for (glm::vec3& v : mesh.vertices) v = glm::vec3(m * glm::vec4(v, 1.0f));
            EXPECT_EQ(test::checkClosedConvexOutward(mesh.vertices, mesh.indices, eps, scale), "");
            for (const glm::vec3& p : moved)
                ASSERT_TRUE(test::insideConvexMesh(mesh.vertices, mesh.indices, glm::dvec3(p), eps, scale));
        }
    }
}

TEST(Kdop, TheOracleChecksCatchBrokenMeshes) {
    const auto sets = test::volumeTestPointSets();
    const ConvexMesh good = kdopBoundary(computeKdop(KdopType::K26, sets[2].points));
    const double scale = test::lengthScale(sets[2].points), eps = 1e-5 * scale;
    ASSERT_EQ(test::checkClosedConvexOutward(good.vertices, good.indices, eps, scale), "");
    ConvexMesh flipped = good;
    std::swap(flipped.indices[0], flipped.indices[1]);
    EXPECT_NE(test::checkClosedConvexOutward(flipped.vertices, flipped.indices, eps, scale), "");
    ConvexMesh open = good;
    open.indices.resize(open.indices.size() - 3);
    EXPECT_NE(test::checkClosedConvexOutward(open.vertices, open.indices, eps, scale), "");
    ConvexMesh dented = good;
    dented.vertices[0] *= 0.5f;  // pulled inside: faces around it fold inward
    EXPECT_NE(test::checkClosedConvexOutward(dented.vertices, dented.indices, eps, scale), "");
    ConvexMesh inverted = good;
    for (std::size_t t = 0; t < inverted.indices.size(); t += 3) std::swap(inverted.indices[t], inverted.indices[t + 1]);
    EXPECT_NE(test::checkClosedConvexOutward(inverted.vertices, inverted.indices, eps, scale), "");
    EXPECT_FALSE(test::insideConvexMesh(good.vertices, good.indices, glm::dvec3(0, 5, 0), eps, scale));
}
