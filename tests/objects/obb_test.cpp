// PCA boxes: contain every point (epsilon scaled to the data), tighter than the AABB on
// rotated data, the AABB itself when not tighter, and sane on degenerate sets.
#include <gtest/gtest.h>

#include "dyncull/objects/convex_mesh.hpp"
#include "dyncull/objects/obb.hpp"
#include "objects/convex_checks.hpp"
#include "objects/volume_test_points.hpp"

using namespace dyncull;

TEST(Obb, ContainsEveryPointOfEverySet) {
    for (const test::NamedPoints& set : test::volumeTestPointSets()) {
        SCOPED_TRACE(set.name);
        const Obb o = fitObbPca(set.points);
        // Containment is the guarantee: float corners may be a few ulps of the coordinates off.
        const double scale = test::lengthScale(set.points), eps = 1e-6 * scale;
        const std::array<glm::vec3, 8> c = o.corners();
        for (const glm::vec3& p : set.points) {
            ASSERT_TRUE(o.contains(p, static_cast<float>(eps)));
            ASSERT_TRUE(test::insideConvexMesh(c, kBoxTriangles, glm::dvec3(p), eps, scale));
        }
        EXPECT_NEAR(glm::determinant(o.axes), 1.0f, 1e-5f);
        EXPECT_GE(o.halfExtents.x, 0.0f);
        EXPECT_GE(o.halfExtents.y, 0.0f);
        EXPECT_GE(o.halfExtents.z, 0.0f);
        Aabb aabb;
        for (const glm::vec3& p : set.points) aabb.extend(p);
        EXPECT_LE(o.surfaceArea(), aabb.surfaceArea() * (1.0f + 1e-6f) + 1e-30f) << "never looser than the AABB";
        if (o.isAabb) {
            EXPECT_EQ(o.axes, glm::mat3(1.0f));
        } else {
            // A real rotated box is a proper (outward, closed) box.
            const std::string bad = test::checkClosedConvexOutward(c, kBoxTriangles, eps, scale);
            if (o.halfExtents.x > 1e-3f && o.halfExtents.y > 1e-3f && o.halfExtents.z > 1e-3f) {
                EXPECT_EQ(bad, "");
            }
        }
    }
}

TEST(Obb, RotatedBoxIsFoundByPca) {
    const auto sets = test::volumeTestPointSets();
    const test::NamedPoints& box = sets[0];
    ASSERT_EQ(box.name, "rotated box 10x2x0.5");
    const Obb o = fitObbPca(box.points);
    ASSERT_FALSE(o.isAabb);
    const glm::mat3 rot = test::testRotation(0.4f, 0.9f, -0.3f);
    // Principal axes are the box's own (up to sign), extents close to 5, 1, 0.25.
    EXPECT_NEAR(std::abs(glm::dot(o.axes[0], rot[0])), 1.0f, 1e-2f);
    EXPECT_NEAR(std::abs(glm::dot(o.axes[1], rot[1])), 1.0f, 2e-2f);
    EXPECT_NEAR(o.halfExtents.x, 5.0f, 0.1f);
    EXPECT_NEAR(o.halfExtents.y, 1.0f, 0.05f);
    EXPECT_NEAR(o.halfExtents.z, 0.25f, 0.02f);
    Aabb aabb;
    for (const glm::vec3& p : box.points) aabb.extend(p);
    EXPECT_LT(o.volume(), 0.25f * aabb.volume());
}

TEST(Obb, AxisAlignedAndDegenerateSetsFallBackToTheAabb) {
    const auto sets = test::volumeTestPointSets();
    for (const test::NamedPoints& s : sets) {
        if (s.name != "cube corners" && s.name != "single point" && s.name != "repeated point" &&
            s.name != "planar (axis plane y=2)" && s.name != "octahedron")
            continue;
        SCOPED_TRACE(s.name);
        const Obb o = fitObbPca(s.points);
        EXPECT_TRUE(o.isAabb);
        Aabb aabb;
        for (const glm::vec3& p : s.points) aabb.extend(p);
        EXPECT_NEAR(glm::length(o.center - aabb.center()), 0.0f, 1e-6f * test::lengthScale(s.points));
    }
    // Collinear along a diagonal: the PCA box is a thin needle, far tighter than the AABB.
    for (const test::NamedPoints& s : sets) {
        if (s.name != "collinear (diagonal)") continue;
        const Obb o = fitObbPca(s.points);
        EXPECT_FALSE(o.isAabb);
        EXPECT_LT(o.halfExtents.y + o.halfExtents.z, 1e-4f);
    }
    const Obb none = fitObbPca({});
    EXPECT_EQ(none.halfExtents, glm::vec3(0.0f));
}
