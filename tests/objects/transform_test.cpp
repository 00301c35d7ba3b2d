#include <cmath>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/transform.hpp"

namespace dyncull {
namespace {

void expectMatNear(const glm::mat4& a, const glm::mat4& b, float eps) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) EXPECT_NEAR(a[c][r], b[c][r], eps) << "element " << c << "," << r;
}

TEST(Transform, MatrixFromMatrixRoundTrip) {
    Transform t;
    t.translation = {1.5f, -2.0f, 30.0f};
    t.rotation = glm::angleAxis(0.7f, glm::normalize(glm::vec3(1, 2, 3)));
    t.scale = {2.0f, 0.5f, 3.0f};
    const glm::mat4 m = t.matrix();
    const Transform back = Transform::fromMatrix(m);
    expectMatNear(back.matrix(), m, 1e-5f);
    EXPECT_NEAR(back.scale.y, 0.5f, 1e-6f);
    EXPECT_NEAR(glm::length(back.translation - t.translation), 0.0f, 1e-6f);
}

TEST(Transform, MirroredMatrixRoundTrip) {
    const glm::mat4 m = glm::scale(glm::translate(glm::mat4(1.0f), {1, 2, 3}), {-1.0f, 2.0f, 1.0f});
    expectMatNear(Transform::fromMatrix(m).matrix(), m, 1e-5f);
}

TEST(Transform, MatrixAppliesScaleThenRotationThenTranslation) {
    Transform t;
    t.translation = {10, 0, 0};
    t.rotation = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 0, 1));
    t.scale = glm::vec3(2.0f);
    const glm::vec3 p = glm::vec3(t.matrix() * glm::vec4(1, 0, 0, 1));
    EXPECT_NEAR(glm::distance(p, glm::vec3(10, 2, 0)), 0.0f, 1e-5f);
}

TEST(Transform, ValidateRejectsNanAndZeroScale) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    Transform t;
    EXPECT_TRUE(validateTransform(t).ok());
    t.translation.y = nan;
    EXPECT_FALSE(validateTransform(t).ok());
    t = Transform{};
    t.scale.z = 0.0f;
    EXPECT_FALSE(validateTransform(t).ok());
    t = Transform{};
    t.scale.x = std::numeric_limits<float>::infinity();
    EXPECT_FALSE(validateTransform(t).ok());
    t = Transform{};
    t.rotation.w = nan;
    EXPECT_FALSE(validateTransform(t).ok());
    t = Transform{};
    t.rotation = glm::quat(2.0f, 0.0f, 0.0f, 0.0f);
    EXPECT_FALSE(validateTransform(t).ok());
}

TEST(Transform, ValidateMatrixRejectsSingularAndNan) {
    EXPECT_TRUE(validateMatrix(glm::mat4(1.0f)).ok());
    EXPECT_FALSE(validateMatrix(glm::scale(glm::mat4(1.0f), {1, 0, 1})).ok());
    glm::mat4 m(1.0f);
    m[3][1] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(validateMatrix(m).ok());
}

TEST(Aabb, TransformAabbContainsTransformedCorners) {
    const Aabb box = Aabb::fromMinMax({-1, 2, -3}, {4, 5, 6});
    Transform t;
    t.translation = {3, -7, 1};
    t.rotation = glm::angleAxis(1.1f, glm::normalize(glm::vec3(-1, 2, 0.5f)));
    t.scale = {1.5f, -0.5f, 2.0f};
    const glm::mat4 m = t.matrix();
    const Aabb world = transformAabb(m, box);
    // Float slack relative to the box size.
    const Aabb slack = world.inflated(1e-5f * glm::length(world.extent()));
    Aabb corners;
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 c(i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y, i & 4 ? box.max.z : box.min.z);
        const glm::vec3 w(m * glm::vec4(c, 1.0f));
        EXPECT_TRUE(slack.contains(w)) << "corner " << i;
        corners.extend(w);
    }
    // Arvo's box is exactly the bound of the corners, not larger.
    EXPECT_NEAR(glm::distance(corners.min, world.min), 0.0f, 1e-4f);
    EXPECT_NEAR(glm::distance(corners.max, world.max), 0.0f, 1e-4f);
    EXPECT_TRUE(transformAabb(m, Aabb{}).empty());
}

}  // namespace
}  // namespace dyncull
