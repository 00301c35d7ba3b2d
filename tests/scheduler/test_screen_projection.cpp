// ScreenProjection::boxDepth, the clusters' fast footprint, against its reference: the
// general volume path on the box built as a query volume (volumeDepth of
// QueryVolume::fromTransformedBox), on random boxes, matrices and cameras, perspective and
// orthographic, with degenerate (flat) boxes and huge coordinates on purpose.
#include <cmath>
#include <random>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "dyncull/objects/obb.hpp"
#include "dyncull/scheduler/query_scheduler.hpp"
#include "screen_projection.hpp"

namespace dyncull {
namespace {

// Both paths round differently (float vertices against exact double ones), so their
// rectangles may differ by the one pixel a rounding can move an edge across.
void expectRectNear(const ScreenRect& a, const ScreenRect& b) {
    EXPECT_LE(std::abs(a.x0 - b.x0), 1);
    EXPECT_LE(std::abs(a.y0 - b.y0), 1);
    EXPECT_LE(std::abs(a.x1 - b.x1), 1);
    EXPECT_LE(std::abs(a.y1 - b.y1), 1);
}

struct Case {
    Camera camera;
    glm::mat4 matrix{1.0f};
    Aabb box;
};

Case randomCase(std::mt19937& rng, bool orthographic, float scale) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), pos(0.05f, 1.0f);
    Case c;
    c.camera.position = glm::vec3(u(rng), u(rng), 6.0f + u(rng)) * scale;
    c.camera.target = glm::vec3(u(rng), u(rng), u(rng)) * scale;
    c.camera.nearPlane = 0.05f * scale;
    c.camera.farPlane = 100.0f * scale;
    if (orthographic) c.camera.orthoHeight = 8.0f * scale;
    glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(u(rng), u(rng), u(rng)) * scale);
    m = glm::rotate(m, 3.0f * u(rng), glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0.0f, 0.0f, 1.5f)));
    m = glm::scale(m, glm::vec3(pos(rng), pos(rng), pos(rng)) * scale);
    c.matrix = m;
    const glm::vec3 lo(u(rng), u(rng), u(rng));
    c.box = Aabb::fromMinMax(lo, lo + glm::vec3(pos(rng), pos(rng), pos(rng)));
    return c;
}

void compare(const Case& c, int& projected) {
    const FrameView view = FrameView::of(c.camera, 640, 360);
    const ScreenProjection screen(view);
    DepthFootprint fast, reference;
    const bool fastInFront = screen.boxDepth(screen.objectProjection(c.matrix), c.box, fast);
    const bool referenceInFront = screen.volumeDepth(QueryVolume::fromTransformedBox(c.matrix, c.box), reference);
    ASSERT_EQ(fastInFront, referenceInFront);
    ScreenRect centres;
    float nearest = 0.0f;
    ASSERT_EQ(screen.boxCentres(screen.objectProjection(c.matrix), c.box, centres, nearest), fastInFront);
    if (!fastInFront) return;
    EXPECT_EQ(centres, fast.centres);  // the same footprint, without its outer rectangle
    EXPECT_EQ(nearest, fast.nearest);
    ++projected;
    expectRectNear(fast.rect, reference.rect);
    expectRectNear(fast.centres, reference.centres);
    EXPECT_NEAR(fast.nearest, reference.nearest, 1e-5f * std::max(1.0f, std::abs(reference.nearest)));
    // Conservative on its own: every exact corner projects inside it, no nearer than it says.
    for (int i = 0; i < 8; ++i) {
        const glm::dvec3 local((i & 1) ? c.box.max.x : c.box.min.x, (i & 2) ? c.box.max.y : c.box.min.y, (i & 4) ? c.box.max.z : c.box.min.z);
        const glm::dvec3 rel = glm::dvec3(glm::dmat4(c.matrix) * glm::dvec4(local, 1.0)) - glm::dvec3(c.camera.position);
        const glm::dvec4 clip = view.viewProjRelative * glm::dvec4(rel, 1.0);
        const glm::dvec2 px = (glm::dvec2(clip) / clip.w + 1.0) * 0.5 * glm::dvec2(view.width, view.height);
        EXPECT_LE(clip.z / clip.w, double(fast.nearest) + 1e-7);
        if (px.x >= 0.0 && px.x <= view.width && px.y >= 0.0 && px.y <= view.height) {
            EXPECT_GE(px.x, fast.rect.x0);
            EXPECT_LE(px.x, fast.rect.x1);
            EXPECT_GE(px.y, fast.rect.y0);
            EXPECT_LE(px.y, fast.rect.y1);
        }
    }
}

// Checks that point `world` (world space; the eye is subtracted here) lies no
// nearer than `fp`'s nearest depth and front-face planes at its own window position, inside
// its outline, and inside its rectangle where it is on screen. `what` names the case.
void expectBoundsPoint(const DepthFootprint& fp, const FrameView& view, const Camera& camera, const glm::dvec3& world, bool checkRect,
                       const std::string& what) {
    const glm::dvec4 clip = view.viewProjRelative * glm::dvec4(world - glm::dvec3(camera.position), 1.0);
    const glm::dvec2 px = (glm::dvec2(clip) / clip.w + 1.0) * 0.5 * glm::dvec2(view.width, view.height);
    const double depth = clip.z / clip.w;
    if (checkRect) {
        EXPECT_LE(depth, double(fp.nearest) + 1e-7) << what;
        if (px.x >= 0.0 && px.x <= view.width && px.y >= 0.0 && px.y <= view.height) {
            EXPECT_GE(px.x, fp.rect.x0) << what;
            EXPECT_LE(px.x, fp.rect.x1) << what;
            EXPECT_GE(px.y, fp.rect.y0) << what;
            EXPECT_LE(px.y, fp.rect.y1) << what;
        }
    }
    for (std::uint32_t j = 0; j < fp.planes.count; ++j) {
        const auto& [a, b, d0] = fp.planes.planes[j];
        EXPECT_GE(a * px.x + b * px.y + d0, depth - 1e-9 * std::abs(depth)) << what << ", plane " << j;
    }
    for (std::uint32_t j = 0; j < fp.planes.edgeCount; ++j) {
        const auto& [a, b, d0] = fp.planes.edges[j];
        EXPECT_LE(a * px.x + b * px.y, d0 + 1e-9 * (std::abs(a * px.x) + std::abs(b * px.y) + std::abs(d0))) << what << ", edge " << j;
    }
}

TEST(ScreenProjection, BoxDepthMatchesTheVolumePath) {
    std::mt19937 rng(7);
    for (const bool orthographic : {false, true})
        for (const float scale : {1.0f, 1e-3f, 1e4f}) {
            int projected = 0;
            for (int i = 0; i < 400; ++i) compare(randomCase(rng, orthographic, scale), projected);
            EXPECT_GT(projected, 100) << "too few boxes in front of the eye to compare";
        }
}

TEST(ScreenProjection, BoxDepthOfDegenerateBoxes) {
    std::mt19937 rng(11);
    int projected = 0;
    for (int i = 0; i < 300; ++i) {
        Case c = randomCase(rng, false, 1.0f);
        // Flat along one axis, along two (a segment), or a point: the thin path, as the reference takes it.
        const int flat = i % 3;
        c.box.max.x = c.box.min.x;
        if (flat >= 1) c.box.max.y = c.box.min.y;
        if (flat >= 2) c.box.max.z = c.box.min.z;
        compare(c, projected);
    }
    EXPECT_GT(projected, 100);
}

TEST(ScreenProjection, BoxDepthFarFromTheOrigin) {
    // Huge coordinates: the rounding margins grow with them, and both paths must agree.
    std::mt19937 rng(13);
    int projected = 0;
    for (int i = 0; i < 300; ++i) {
        Case c = randomCase(rng, false, 1.0f);
        const glm::vec3 far(3e6f, -2e6f, 1e6f);
        c.camera.position += far;
        c.camera.target += far;
        c.matrix = glm::translate(glm::mat4(1.0f), far) * c.matrix;
        compare(c, projected);
    }
    EXPECT_GT(projected, 100);
}

// roughBoxDepth, cluster history's guess (float, no rounding margins, corners from the
// centre and half axes): the exact footprint within a pixel and within float rounding of
// its depth, wherever the exact path projects the box and no corner is near the eye.
TEST(ScreenProjection, RoughBoxDepthIsTheExactFootprintWithinRounding) {
    std::mt19937 rng(17);
    int compared = 0;
    for (int i = 0; i < 600; ++i) {
        const Case c = randomCase(rng, false, i % 2 ? 1.0f : 1e3f);
        const FrameView view = FrameView::of(c.camera, 640, 360);
        const ScreenProjection screen(view);
        ScreenRect exact, rough;
        float exactNearest = 0.0f, roughNearest = 0.0f;
        if (!screen.boxCentres(screen.objectProjection(c.matrix), c.box, exact, exactNearest)) continue;
        ASSERT_TRUE(screen.roughBoxDepth(screen.clipMatrixOf(c.matrix), c.box, rough, roughNearest)) << "case " << i;
        expectRectNear(rough, exact);
        EXPECT_NEAR(roughNearest, exactNearest, 1e-5f) << "case " << i;
        ++compared;
    }
    EXPECT_GT(compared, 200);
}

// boxDepth's front-face planes bound the box's depth pixel by pixel: every point of the box
// (corners, points on its faces, inside) projects no nearer than each plane's depth at its
// own window position, and inside its outline. Planes in perspective only (an orthographic
// view gets none); the outline in both.
TEST(ScreenProjection, FrontFacePlanesAreNeverBehindTheBox) {
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int withPlanes = 0, withOutline = 0, points = 0;
    for (const float scale : {1.0f, 1e-3f, 1e4f}) {
        for (int i = 0; i < 400; ++i) {
            const Case c = randomCase(rng, false, scale);
            const FrameView view = FrameView::of(c.camera, 640, 360);
            const ScreenProjection screen(view);
            DepthFootprint fp;
            if (!screen.boxDepth(screen.objectProjection(c.matrix), c.box, fp)) continue;
            ASSERT_LE(fp.planes.count, 3u);
            withPlanes += fp.planes.count > 0;
            withOutline += fp.planes.edgeCount >= 4;  // a box's outline has 4 or 6 corners
            for (int k = 0; k < 64; ++k) {
                // Corners first, then points on the faces, then inside.
                glm::dvec3 t(u(rng), u(rng), u(rng));
                if (k < 8) t = glm::dvec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
                else if (k < 32) t[k % 3] = (k & 8) ? 1.0 : 0.0;
                const glm::dvec3 local = glm::dvec3(c.box.min) + t * (glm::dvec3(c.box.max) - glm::dvec3(c.box.min));
                expectBoundsPoint(fp, view, c.camera, glm::dvec3(glm::dmat4(c.matrix) * glm::dvec4(local, 1.0)), false, "case " + std::to_string(i));
                ++points;
            }
        }
    }
    EXPECT_GT(withPlanes, 300) << "too few boxes with planes to check";
    EXPECT_GT(withOutline, 300) << "too few boxes with outlines to check";
    EXPECT_GT(points, 20000);
    // Orthographic: none.
    const Case c = randomCase(rng, true, 1.0f);
    const FrameView view = FrameView::of(c.camera, 640, 360);
    const ScreenProjection screen(view);
    DepthFootprint fp;
    if (screen.boxDepth(screen.objectProjection(c.matrix), c.box, fp)) {
        EXPECT_EQ(fp.planes.count, 0u);
        EXPECT_GE(fp.planes.edgeCount, 4u);
    }
}

// A part's PCA box projected as a box in its own frame (boxFrame of its float corners,
// frameBoxDepth): every point the box was fitted to, under the object's float matrix, lies
// inside the footprint's rectangle and outline, and no nearer than its nearest depth or any
// front-face plane at its own window position; at three scales and far from the origin.
TEST(ScreenProjection, AnObbInItsOwnFrameBoundsItsPoints) {
    std::mt19937 rng(29);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    int projected = 0, withPlanes = 0;
    for (const float scale : {1.0f, 1e-3f, 1e4f}) {
        for (int i = 0; i < 200; ++i) {
            Case c = randomCase(rng, false, scale);
            if (i % 4 == 3) {  // far from the origin
                const glm::vec3 far(3e6f * scale, -2e6f * scale, 1e6f * scale);
                c.camera.position += far;
                c.camera.target += far;
                c.matrix = glm::translate(glm::mat4(1.0f), far) * c.matrix;
            }
            // A stretched, rotated cloud (planar every fifth case: a flat box takes the thin path).
            const glm::mat3 shape = glm::mat3(glm::rotate(glm::mat4(1.0f), 3.0f * u(rng), glm::normalize(glm::vec3(u(rng), u(rng), 1.0f)))) *
                                    glm::mat3(glm::scale(glm::mat4(1.0f), glm::vec3(1.0f, 0.3f, i % 5 == 0 ? 0.0f : 0.1f)));
            std::vector<glm::vec3> points(40);
            for (glm::vec3& p : points) p = shape * glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0.2f);
            const Obb obb = fitObbPca(points);
            const std::array<glm::vec3, 8> corners = obb.corners();
            const FrameView view = FrameView::of(c.camera, 640, 360);
            const ScreenProjection screen(view);
            DepthFootprint fp;
            const std::optional<bool> inFront =
                screen.frameBoxDepth(screen.objectProjection(glm::dmat4(c.matrix) * boxFrame(corners)), Aabb{glm::vec3(-1.0f), glm::vec3(1.0f)}, fp);
            if (!inFront || !*inFront) continue;  // thin (the caller's volume path), or at the near plane
            ++projected;
            withPlanes += fp.planes.count > 0;
            for (const glm::vec3& p : points)  // under the float transform a GPU makes
                expectBoundsPoint(fp, view, c.camera, glm::dvec3(c.matrix * glm::vec4(p, 1.0f)), true, "case " + std::to_string(i));
        }
    }
    EXPECT_GT(projected, 200) << "too few boxes in front of the eye to check";
    EXPECT_GT(withPlanes, 100);
}

// Left out, the planes and outline are empty and said to be; asked for, the same footprint
// has them.
TEST(ScreenProjection, PlanesLeftOutAreMadeOnRequest) {
    std::mt19937 rng(31);
    int checked = 0;
    for (int i = 0; i < 200; ++i) {
        const Case c = randomCase(rng, false, 1.0f);
        const FrameView view = FrameView::of(c.camera, 640, 360);
        const ScreenProjection screen(view);
        DepthFootprint without, with;
        const bool inFront = screen.boxDepth(screen.objectProjection(c.matrix), c.box, without, false);
        ASSERT_EQ(screen.boxDepth(screen.objectProjection(c.matrix), c.box, with), inFront);
        if (!inFront) continue;
        EXPECT_TRUE(without.planesLeftOut);
        EXPECT_FALSE(with.planesLeftOut);
        EXPECT_EQ(without.planes.count, 0u);
        EXPECT_EQ(without.planes.edgeCount, 0u);
        EXPECT_EQ(without.rect, with.rect);
        EXPECT_EQ(without.centres, with.centres);
        EXPECT_EQ(without.nearest, with.nearest);
        checked += with.planes.edgeCount > 0;
    }
    EXPECT_GT(checked, 50);
}

TEST(ScreenProjection, BoxAroundTheEyeIsVisible) {
    Camera camera;
    camera.position = {0.3f, -0.2f, 0.1f};
    camera.target = {0.0f, 0.0f, -5.0f};
    const FrameView view = FrameView::of(camera, 640, 360);
    const ScreenProjection screen(view);
    const glm::mat4 m = glm::rotate(glm::mat4(1.0f), 0.7f, glm::vec3(0.0f, 1.0f, 0.0f));
    DepthFootprint fp;
    EXPECT_FALSE(screen.boxDepth(screen.objectProjection(m), Aabb::fromMinMax({-1.0f, -1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}), fp));
}

// QueryVolume::enlargedForRounding moves every face of a volume out by at least its margin
// (the vertices' magnitude times 2^-22 sqrt 3): checked per triangle against the distances
// computed plainly (a square root per face), on transformed boxes and k-DOP-like volumes
// from near the origin to 1e30 from it.
TEST(QueryVolume, EnlargedForRoundingPushesEveryFaceOutByItsMargin) {
    std::mt19937 rng(11);
    int checked = 0;
    for (const float scale : {1.0f, 1e4f, 1e7f, 1e30f}) {
        for (int n = 0; n < 200; ++n) {
            const Case c = randomCase(rng, false, scale);
            const QueryVolume v = QueryVolume::fromTransformedBox(c.matrix, c.box);
            std::array<glm::dvec3, QueryVolume::kMaxVertices> out;
            bool asBox = false;
            const std::uint32_t count = v.enlargedForRounding(glm::dvec3(0.0), out, asBox);
            if (asBox) continue;  // too thin for faces: its box, tested by the volume paths
            ASSERT_EQ(count, v.vertexCount);
            double magnitude = 0.0;
            glm::dvec3 centre(0.0);
            for (const glm::vec3& p : v.points()) {
                magnitude = std::max({magnitude, std::abs(double(p.x)), std::abs(double(p.y)), std::abs(double(p.z))});
                centre += glm::dvec3(p) / 8.0;
            }
            const double push = magnitude * 0x1p-22 * std::sqrt(3.0);
            const std::span<const std::uint8_t> tris = v.triangles();
            for (std::size_t t = 0; t + 2 < tris.size(); t += 3) {
                const glm::dvec3 a(v.vertices[tris[t]]), b(v.vertices[tris[t + 1]]), d(v.vertices[tris[t + 2]]);
                glm::dvec3 normal = glm::cross(b - a, d - a);
                if (glm::length(normal) == 0.0) continue;
                normal = glm::normalize(normal);
                if (glm::dot(normal, a - centre) < 0.0) normal = -normal;  // outward
                // Every enlarged vertex of the face lies at least `push` beyond its plane.
                for (std::size_t k = 0; k < 3; ++k)
                    EXPECT_GE(glm::dot(normal, out[tris[t + k]] - a), push * (1.0 - 1e-9)) << scale << " triangle " << t / 3;
                ++checked;
            }
        }
    }
    EXPECT_GT(checked, 4 * 150 * 12);
}

}  // namespace
}  // namespace dyncull
