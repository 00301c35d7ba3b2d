#include <cmath>

#include <gtest/gtest.h>

#include "dyncull/objects/motion.hpp"

namespace dyncull {
namespace {

const Aabb kBox = Aabb::fromMinMax({-10, 0, -5}, {10, 4, 5});

TEST(BouncingMotion, SameSeedSamePositions) {
    const BouncingMotion a(50, kBox, 0.3f, 0.5f, 1234), b(50, kBox, 0.3f, 0.5f, 1234);
    for (std::uint32_t i = 0; i < 50; ++i) {
        for (std::uint64_t f : {0ull, 1ull, 777ull, 123456789ull}) EXPECT_EQ(a.position(i, f), b.position(i, f));
        EXPECT_EQ(a.orientation(i), b.orientation(i));
    }
}

TEST(BouncingMotion, DifferentSeedsDiffer) {
    const BouncingMotion a(10, kBox, 0.3f, 0.5f, 1), b(10, kBox, 0.3f, 0.5f, 2);
    int differ = 0;
    for (std::uint32_t i = 0; i < 10; ++i) differ += a.position(i, 0) != b.position(i, 0);
    EXPECT_GE(differ, 9);
}

TEST(BouncingMotion, StaysInsideTheInnerBoxFor10000Frames) {
    const float margin = 0.75f;
    const BouncingMotion m(20, kBox, 0.9f, margin, 99);
    const Aabb inner = Aabb::fromMinMax(kBox.min + glm::vec3(margin), kBox.max - glm::vec3(margin));
    for (std::uint64_t f = 0; f < 10000; ++f)
        for (std::uint32_t i = 0; i < m.count(); ++i) ASSERT_TRUE(inner.contains(m.position(i, f))) << i << " @ " << f;
}

TEST(BouncingMotion, MovesAtTheGivenSpeedAwayFromWalls) {
    // Box large enough that no wall is hit in one frame, small enough for float precision.
    const BouncingMotion m(4, Aabb::fromMinMax(glm::vec3(-1e3f), glm::vec3(1e3f)), 0.5f, 0.0f, 7);
    for (std::uint32_t i = 0; i < m.count(); ++i) {
        EXPECT_NEAR(glm::distance(m.position(i, 0), m.position(i, 1)), 0.5f, 1e-3f);
        EXPECT_NEAR(glm::length(m.orientation(i)), 1.0f, 1e-5f);  // unit quaternion
    }
}

TEST(BouncingMotion, ReflectsOffTheWall) {
    // Closed form vs. a frame-by-frame simulation with explicit reflection.
    const BouncingMotion m(8, kBox, 0.37f, 0.25f, 5);
    const Aabb inner = Aabb::fromMinMax(kBox.min + glm::vec3(0.25f), kBox.max - glm::vec3(0.25f));
    for (std::uint32_t i = 0; i < m.count(); ++i) {
        glm::vec3 p = m.position(i, 0);
        glm::vec3 v = m.position(i, 1) - p;  // valid unless a wall is hit in frame 0; checked below
        bool exact = true;
        for (int a = 0; a < 3; ++a) exact &= p[a] + v[a] > inner.min[a] && p[a] + v[a] < inner.max[a];
        if (!exact) continue;
        for (std::uint64_t f = 1; f <= 500; ++f) {
            glm::vec3 q = p + v;
            for (int a = 0; a < 3; ++a) {
                if (q[a] > inner.max[a]) { q[a] = 2 * inner.max[a] - q[a]; v[a] = -v[a]; }
                if (q[a] < inner.min[a]) { q[a] = 2 * inner.min[a] - q[a]; v[a] = -v[a]; }
            }
            p = q;
            ASSERT_NEAR(glm::distance(p, m.position(i, f)), 0.0f, 1e-3f) << i << " @ " << f;
        }
    }
}

TEST(BouncingMotion, MarginLargerThanBoxPinsToCentre) {
    const BouncingMotion m(3, Aabb::fromMinMax({0, 0, 0}, {10, 1, 10}), 0.5f, 2.0f, 3);
    for (std::uint64_t f : {0ull, 5ull, 1000ull}) EXPECT_FLOAT_EQ(m.position(1, f).y, 0.5f);
}

TEST(CameraPath, PassesThroughWaypoints) {
    const std::vector<glm::vec3> eyes = {{0, 0, 10}, {10, 2, 0}, {0, 5, -10}, {-10, 1, 3}};
    const std::vector<glm::vec3> targets = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (bool loop : {false, true}) {
        const CameraPath path(eyes, targets, 30, loop);
        EXPECT_EQ(path.frameCount(), loop ? 120u : 90u);
        Camera c;
        for (std::size_t k = 0; k < eyes.size(); ++k) {
            path.apply(30 * k, c);
            EXPECT_NEAR(glm::distance(c.position, eyes[k]), 0.0f, 1e-4f) << k << " loop " << loop;
            EXPECT_NEAR(glm::distance(c.target, targets[k]), 0.0f, 1e-4f) << k << " loop " << loop;
        }
        // Past the end: clamped paths rest at the last waypoint, loops wrap around.
        path.apply(10000 * 120 + 30, c);
        EXPECT_NEAR(glm::distance(c.position, loop ? eyes[1] : eyes.back()), 0.0f, 1e-4f);
    }
}

TEST(CameraPath, IsContinuousAndHandlesRepeatedWaypoints) {
    const CameraPath path({{0, 0, 0}, {0, 0, 0}, {4, 0, 0}, {4, 0, 0}, {4, 4, 0}}, {{0, 0, -1}}, 10, false);
    Camera c, prev;
    path.apply(0, prev);
    for (std::uint64_t f = 1; f <= path.frameCount(); ++f) {
        path.apply(f, c);
        ASSERT_TRUE(std::isfinite(c.position.x) && std::isfinite(c.position.y)) << f;
        EXPECT_LT(glm::distance(c.position, prev.position), 1.0f) << f;
        EXPECT_EQ(c.target, glm::vec3(0, 0, -1));
        prev = c;
    }
}

TEST(CameraPath, OrbitStaysOnTheCircle) {
    const glm::vec3 centre(1, 2, 3);
    const CameraPath path = CameraPath::orbit(centre, 10.0f, 4.0f, 360);
    EXPECT_EQ(path.frameCount(), 360u);
    Camera c;
    for (std::uint64_t f = 0; f < 360; f += 7) {
        path.apply(f, c);
        EXPECT_NEAR(c.position.y, centre.y + 4.0f, 1e-4f);
        const float r = glm::length(glm::vec2(c.position.x - centre.x, c.position.z - centre.z));
        EXPECT_NEAR(r, 10.0f, 0.01f) << f;  // spline through 18 points deviates < 0.1%
        EXPECT_EQ(c.target, centre);
    }
    path.apply(360, c);
    Camera c0;
    path.apply(0, c0);
    EXPECT_NEAR(glm::distance(c.position, c0.position), 0.0f, 1e-4f);
}

}  // namespace
}  // namespace dyncull
