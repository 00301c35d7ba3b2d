#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/camera.hpp"

namespace dyncull {
namespace {

Frustum lookDownMinusZ() {
    Camera c;
    c.position = {0, 0, 0};
    c.target = {0, 0, -1};
    c.fovYRadians = 1.0f;
    c.aspect = 1.0f;
    c.nearPlane = 1.0f;
    c.farPlane = 100.0f;
    return Frustum::fromMatrix(c.viewProjection());
}

TEST(Frustum, ClassifiesInsideOutsideIntersecting) {
    const Frustum f = lookDownMinusZ();
    EXPECT_EQ(f.classify(Aabb::fromMinMax({-1, -1, -11}, {1, 1, -9})), Frustum::Side::Inside);
    EXPECT_EQ(f.classify(Aabb::fromMinMax({-1, -1, 5}, {1, 1, 7})), Frustum::Side::Outside);      // behind
    EXPECT_EQ(f.classify(Aabb::fromMinMax({-1, -1, -300}, {1, 1, -200})), Frustum::Side::Outside);  // past far
    EXPECT_EQ(f.classify(Aabb::fromMinMax({50, -1, -11}, {52, 1, -9})), Frustum::Side::Outside);  // to the right
    EXPECT_EQ(f.classify(Aabb::fromMinMax({-1, -1, -2}, {1, 1, 2})), Frustum::Side::Intersecting);  // crosses near
    EXPECT_TRUE(f.outside(Aabb::fromMinMax({-1, 50, -11}, {1, 52, -9})));
}

TEST(Frustum, PlanesAreNormalised) {
    const Frustum f = lookDownMinusZ();
    for (const glm::vec4& p : f.planes) EXPECT_NEAR(glm::length(glm::vec3(p)), 1.0f, 1e-5f);
}

TEST(Camera, FramingSeesTheWholeBox) {
    const Aabb box = Aabb::fromMinMax({-3, 2, 10}, {5, 4, 30});
    for (float aspect : {0.5f, 1.0f, 16.0f / 9.0f}) {
        const Camera c = Camera::framing(box, aspect);
        ASSERT_TRUE(validateCamera(c).ok()) << validateCamera(c).message();
        EXPECT_EQ(Frustum::fromMatrix(c.viewProjection()).classify(box), Frustum::Side::Inside) << aspect;
    }
}

TEST(Camera, FramingEmptyBoxIsStillValid) {
    EXPECT_TRUE(validateCamera(Camera::framing(Aabb{}, 1.5f)).ok());
}

TEST(Camera, ValidateRejectsBadInput) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    Camera c;
    EXPECT_TRUE(validateCamera(c).ok());
    c.position.x = nan;
    EXPECT_FALSE(validateCamera(c).ok());
    c = Camera{};
    c.fovYRadians = nan;
    EXPECT_FALSE(validateCamera(c).ok());
    c = Camera{};
    c.nearPlane = 0.0f;
    EXPECT_FALSE(validateCamera(c).ok());
    c = Camera{};
    c.farPlane = c.nearPlane;
    EXPECT_FALSE(validateCamera(c).ok());
    c = Camera{};
    c.target = c.position;
    EXPECT_FALSE(validateCamera(c).ok());
    c = Camera{};
    c.up = c.target - c.position;
    EXPECT_FALSE(validateCamera(c).ok());
}

}  // namespace
}  // namespace dyncull
