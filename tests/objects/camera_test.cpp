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

// Near 1e-4 with far 1e7 (issue: robustness, numerical extremes): the float matrix the GPU
// gets, applied in float as the GPU does, gives depth 1 at the near plane and 0 at the far
// plane, and separates points 1e-5 of their distance apart at every decade from 1e-3 to
// 1e6, on and off the view axis. (OpenGL's [-1, 1] projection in float gives 1.0 for both
// from ~3,400 units on.)
TEST(Camera, ReversedZDepthResolvesEveryDecadeFromNear1eMinus4ToFar1e7) {
    for (const glm::vec3& target : {glm::vec3(0, 0, -1), glm::vec3(1, 2, 3)}) {
        Camera c;
        c.position = {0, 0, 0};
        c.target = target;
        c.nearPlane = 1e-4f;
        c.farPlane = 1e7f;
        const glm::mat4 vp = c.viewProjectionRelative();
        const glm::vec3 f = c.forward();
        auto depth = [&](double d, const glm::vec3& dir) {
            const glm::vec4 clip = vp * glm::vec4(glm::vec3(glm::dvec3(dir) * d), 1.0f);
            return clip.z / clip.w;
        };
        EXPECT_NEAR(depth(1e-4, f), 1.0f, 1e-6f);
        EXPECT_NEAR(depth(1e7, f), 0.0f, 1e-6f * depth(1e6, f));
        const glm::vec3 offAxis = glm::normalize(f + 0.3f * glm::normalize(glm::cross(f, c.up)));
        for (int k = -3; k <= 6; ++k) {
            const double d = std::pow(10.0, k);
            for (const glm::vec3& dir : {f, offAxis}) {
                // Off axis the view distance is d * cos; the ratio of the two points is the same.
                EXPECT_GT(depth(d, dir), depth(d * (1.0 + 1e-5), dir)) << "distance " << d;
                EXPECT_GT(depth(d * (1.0 + 1e-5), dir), 0.0f);
                EXPECT_LT(depth(d, dir), 1.0f);
            }
        }
    }
}

TEST(Frustum, PlanesOfNear1eMinus4AndFar1e7AreExact) {
    // The far plane keeps a unit normal (OpenGL's (f + n) / (f - n) rounds to 1 in float and
    // the plane extracted from it degenerates), and both planes sit where they should.
    Camera c;
    c.position = {3, 4, 5};
    c.target = {3, 4, 4};
    c.nearPlane = 1e-4f;
    c.farPlane = 1e7f;
    const Frustum f = Frustum::fromCamera(c);
    for (const glm::vec4& p : f.planes) EXPECT_NEAR(glm::length(glm::vec3(p)), 1.0f, 1e-5f);
    EXPECT_NEAR(f.planes[4].w, -1e-4f, 1e-10f);  // near: -z_view >= 1e-4
    EXPECT_NEAR(f.planes[5].w, 1e7f, 1.0f);      // far: -z_view <= 1e7
    auto at = [&](float d, float h) { return Aabb::fromMinMax({3 - h, 4 - h, 5 - d - h}, {3 + h, 4 + h, 5 - d + h}); };
    EXPECT_EQ(f.classify(at(2e-4f, 5e-5f)), Frustum::Side::Inside);
    EXPECT_EQ(f.classify(at(1e-4f, 5e-5f)), Frustum::Side::Intersecting);  // crosses near
    EXPECT_EQ(f.classify(at(9.9e6f, 1e3f)), Frustum::Side::Inside);
    EXPECT_EQ(f.classify(at(1.01e7f, 1e3f)), Frustum::Side::Outside);  // past far
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
