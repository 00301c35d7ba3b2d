// The batched raster test (GlQueryBackend::testVolumes) against its oracle, one hardware
// query per volume: the same answer for every volume of a random scene, volumes reaching
// the near plane answered Visible undrawn, and the GL state left as it was found.
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "dyncull/engine/gl_query_backend.hpp"
#include "dyncull/objects/aabb.hpp"
#include "gl_test_util.hpp"
#include "procedural_meshes.hpp"

namespace dyncull {
namespace {

/// Random volumes around the origin: axis-aligned boxes, rotated boxes and, as convex
/// meshes, the same rotated boxes' 12 triangles, of sizes from a pixel to half the view.
std::vector<QueryVolume> randomVolumes(std::mt19937& rng, int count) {
    std::uniform_real_distribution<float> pos(-1.6f, 1.6f), depth(-3.0f, 2.0f), size(0.01f, 0.6f), angle(0.0f, 6.3f);
    std::vector<QueryVolume> out;
    for (int i = 0; i < count; ++i) {
        const glm::vec3 c(pos(rng), pos(rng), depth(rng));
        const glm::vec3 h(size(rng), size(rng), size(rng));
        const Aabb local = Aabb::fromMinMax(-h, h);
        glm::mat4 m = glm::translate(glm::mat4(1.0f), c);
        switch (i % 3) {
        case 0: out.push_back(QueryVolume::fromAabb(Aabb::fromMinMax(c - h, c + h))); break;
        case 1: out.push_back(QueryVolume::fromTransformedBox(glm::rotate(m, angle(rng), glm::normalize(glm::vec3(1, 2, 3))), local)); break;
        default: {
            QueryVolume v = QueryVolume::fromTransformedBox(glm::rotate(m, angle(rng), glm::vec3(0, 1, 0)), local);
            const std::span<const std::uint8_t> tris = v.triangles();
            std::copy(tris.begin(), tris.end(), v.indices.begin());
            v.triangleCount = static_cast<std::uint32_t>(tris.size() / 3);  // the mesh path
            out.push_back(v);
        }
        }
    }
    return out;
}

TEST(BatchedRasterTest, AnswersEveryVolumeAsOneHardwareQueryEach) {
    auto ctx = test::headless(160, 120);
    ASSERT_TRUE(ctx);
    auto made = Renderer::create(*ctx);
    ASSERT_TRUE(made.ok()) << made.error().message;
    Renderer& r = **made;
    auto backendOr = GlQueryBackend::create(*ctx);
    ASSERT_TRUE(backendOr.ok()) << backendOr.error().message;
    GlQueryBackend& b = **backendOr;
    Camera cam = test::cameraOnZ(4.0f);
    cam.aspect = 160.0f / 120.0f;
    const MeshId sphere = *r.upload(test::sphereMesh(1.0f, 16, 32));
    const MeshId quad = *r.upload(test::quadMesh(1.0f));

    std::mt19937 rng(2026);
    int visible = 0, occluded = 0;
    for (int scene = 0; scene < 4; ++scene) {
        ctx->clearFramebuffer(Renderer::kClearColour);
        r.beginFrame(cam);
        // Occluders: spheres and tilted quads scattered between the volumes.
        std::uniform_real_distribution<float> pos(-1.5f, 1.5f), z(-1.0f, 1.5f), s(0.2f, 0.9f);
        for (int k = 0; k < 8; ++k) {
            glm::mat4 m = glm::translate(glm::mat4(1.0f), {pos(rng), pos(rng), z(rng)});
            m = glm::scale(glm::rotate(m, pos(rng), glm::vec3(1, 0, 0)), glm::vec3(s(rng)));
            r.drawMesh(k % 2 ? sphere : quad, m, {0.5f, 0.5f, 0.5f});
        }
        b.beginFrame(FrameView::of(cam, 160, 120));
        const std::vector<QueryVolume> volumes = randomVolumes(rng, 300);
        std::vector<QueryId> oracle;
        b.beginBatch();
        for (const QueryVolume& v : volumes) oracle.push_back(b.issue(v));
        b.endBatch();
        const BatchId batch = b.testVolumes(volumes);
        ASSERT_NE(batch, kNoBatch);
        std::vector<QueryResult> answers(volumes.size(), QueryResult::NotReady);
        ASSERT_TRUE(b.collectVolumes(batch, answers, 10000.0));
        for (std::size_t i = 0; i < volumes.size(); ++i) {
            const QueryResult expected = b.wait(oracle[i], 10000.0);
            b.release(oracle[i]);
            EXPECT_EQ(answers[i], expected) << "scene " << scene << ", volume " << i;
            (answers[i] == QueryResult::Visible ? visible : occluded) += 1;
        }
        r.endFrame();
    }
    // Both answers occur, so the comparison says something.
    EXPECT_GT(visible, 100);
    EXPECT_GT(occluded, 100);
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

TEST(BatchedRasterTest, NearPlaneVolumesAreVisibleUndrawnAndStateIsRestored) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    auto made = Renderer::create(*ctx);
    ASSERT_TRUE(made.ok()) << made.error().message;
    Renderer& r = **made;
    auto backendOr = GlQueryBackend::create(*ctx);
    ASSERT_TRUE(backendOr.ok()) << backendOr.error().message;
    GlQueryBackend& b = **backendOr;
    const Camera cam = test::cameraOnZ(3.0f);  // near plane at z = 2.9
    const MeshId wall = *r.upload(test::quadMesh(5.0f));  // fills the whole view at z = 0
    ctx->clearFramebuffer(Renderer::kClearColour);
    r.beginFrame(cam);
    r.drawMesh(wall, glm::mat4(1.0f), {0.5f, 0.5f, 0.5f});
    b.beginFrame(FrameView::of(cam, test::kW, test::kH));

    // A game's state, which the test must leave as it was.
    GLuint ssbo = 0;
    glCreateBuffers(1, &ssbo);
    glNamedBufferData(ssbo, 256, nullptr, GL_STATIC_DRAW);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 0, ssbo, 64, 128);
    glColorMask(GL_TRUE, GL_FALSE, GL_TRUE, GL_TRUE);
    glEnable(GL_CULL_FACE);
    GLint programBefore = 0, vaoBefore = 0;
    glGetIntegerv(GL_CURRENT_PROGRAM, &programBefore);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &vaoBefore);

    const std::vector<QueryVolume> volumes = {
        QueryVolume::fromAabb(Aabb::fromMinMax({-0.5f, -0.5f, -2.0f}, {0.5f, 0.5f, -1.0f})),  // behind the wall
        QueryVolume::fromAabb(Aabb::fromMinMax({-0.5f, -0.5f, 1.0f}, {0.5f, 0.5f, 2.0f})),    // in front
        // Behind the wall but reaching past the near plane: clipped there it might miss the
        // samples in front of the wall, so it is Visible without being drawn.
        QueryVolume::fromAabb(Aabb::fromMinMax({-0.1f, -0.1f, -1.0f}, {0.1f, 0.1f, 2.95f})),
    };
    const BatchId batch = b.testVolumes(volumes);
    std::vector<QueryResult> answers(volumes.size());
    bool done = false;
    for (int spin = 0; spin < 1000000 && !done; ++spin) done = b.collectVolumes(batch, answers, 0.0);  // never blocks
    ASSERT_TRUE(done);
    EXPECT_EQ(answers[0], QueryResult::Occluded);
    EXPECT_EQ(answers[1], QueryResult::Visible);
    EXPECT_EQ(answers[2], QueryResult::Visible);
    // An empty batch answers at once.
    const BatchId empty = b.testVolumes({});
    EXPECT_TRUE(b.collectVolumes(empty, {}, 10000.0));

    GLint program = 0, vao = 0, bound = 0;
    GLint64 start = 0, size = 0;
    GLboolean mask[4] = {};
    glGetIntegerv(GL_CURRENT_PROGRAM, &program);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &vao);
    glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, 0, &bound);
    glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_START, 0, &start);
    glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_SIZE, 0, &size);
    glGetBooleanv(GL_COLOR_WRITEMASK, mask);
    EXPECT_EQ(program, programBefore);
    EXPECT_EQ(vao, vaoBefore);
    EXPECT_EQ(bound, static_cast<GLint>(ssbo));
    EXPECT_EQ(start, 64);
    EXPECT_EQ(size, 128);
    EXPECT_EQ(mask[0], GL_TRUE);
    EXPECT_EQ(mask[1], GL_FALSE);
    EXPECT_TRUE(glIsEnabled(GL_CULL_FACE));
    EXPECT_FALSE(glIsEnabled(GL_POLYGON_OFFSET_FILL));
    glDisable(GL_CULL_FACE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDeleteBuffers(1, &ssbo);
    r.endFrame();
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

/// Pixels (x, y from the bottom) a drawn part covers: not the clear colour.
std::vector<glm::ivec2> coveredPixels(Renderer& r, int w, int h) {
    const Image img = r.readPixels();
    std::vector<glm::ivec2> out;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (!test::isClear(img.at(x, h - 1 - y))) out.push_back({x, y});
    return out;
}

/// Sets every pixel's depth but p's to the nearest (reversed Z: 1), so only p can pass a
/// volume test.
void nearestExceptPixel(glm::ivec2 p, int w, int h) {
    glEnable(GL_SCISSOR_TEST);
    glClearDepth(1.0);
    for (const glm::ivec4 rect : {glm::ivec4(0, 0, w, p.y), glm::ivec4(0, p.y + 1, w, h - p.y - 1), glm::ivec4(0, p.y, p.x, 1),
                                  glm::ivec4(p.x + 1, p.y, w - p.x - 1, 1)}) {
        if (rect.z <= 0 || rect.w <= 0) continue;
        glScissor(rect.x, rect.y, rect.z, rect.w);
        glClear(GL_DEPTH_BUFFER_BIT);
    }
    glDisable(GL_SCISSOR_TEST);
    glClearDepth(0.0);
}

// The rasteriser snaps window coordinates to 1/256 pixel (llvmpipe), so a part's slanted
// edge can cover a pixel centre just outside its exact outline, and the edge of a tight
// volume through the same line, snapped on its own, can miss it. Each random triangle gets
// a box with one face through its edge AB; each of its pixels alone is left uncovered by a
// nearer depth, and a hardware query of the box must see it. Without a snapping margin
// some pixels are missed (the test shows the case exists); with it, or with the box grown
// across the view direction instead (the default for boxes), none is.
TEST(VolumeSnapping, TheMarginKeepsEveryPixelOfAPartInsideItsVolume) {
    constexpr int kSize = 64;
    auto ctx = test::headless(kSize, kSize);
    ASSERT_TRUE(ctx);
    auto made = Renderer::create(*ctx);
    ASSERT_TRUE(made.ok()) << made.error().message;
    Renderer& r = **made;
    const Camera cam = test::cameraOnZ(3.0f);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> coord(-0.9f, 0.9f), angle(0.0f, 6.2832f), len(0.3f, 0.9f), height(0.05f, 0.3f);
    std::uint32_t missedWithout = 0, missedRing = 0, missedGrown = 0, pixels = 0;
    for (SnappingMargin margin : {SnappingMargin::None, SnappingMargin::Ring, SnappingMargin::GrowBoxes}) {
        GlQueryParams qp;
        qp.snapping = margin;
        auto backendOr = GlQueryBackend::create(*ctx, qp);
        ASSERT_TRUE(backendOr.ok()) << backendOr.error().message;
        GlQueryBackend& b = **backendOr;
        rng.seed(7);
        for (int trial = 0; trial < 1500; ++trial) {
            // Triangle A, B, C in the plane z = 0, and the box spanned by AB and C.
            // Line AB passes through the view axis, so the box's depth does not move its outline
            // on screen there, and the box is thick enough that its rounding growth is far below
            // a snapping step: the box's outline lies on the line AB to within 1e-4 pixel.
            const float phi = angle(rng);
            const glm::vec3 u(std::cos(phi), std::sin(phi), 0.0f), v(-u.y, u.x, 0.0f);
            const glm::vec3 a = (coord(rng) - 0.45f) * u;
            const glm::vec3 bv = a + len(rng) * u, c = a + 0.5f * len(rng) * u + height(rng) * v;
            Mesh tri;
            tri.name = "triangle";
            tri.positions = {a, bv, c};
            tri.normals.assign(3, {0, 0, 1});
            tri.indices = {0, 1, 2};
            const MeshId id = *r.upload(tri);
            glm::mat4 frame(1.0f);
            frame[0] = glm::vec4(u, 0.0f);
            frame[1] = glm::vec4(v, 0.0f);
            frame[2] = glm::vec4(0.0f, 0.0f, 1.0f, 0.0f);
            frame[3] = glm::vec4(a, 1.0f);
            const float cu = glm::dot(c - a, u), bu = glm::dot(bv - a, u);
            // The box's edge on line AB ends beyond A and B, so it snaps unlike the triangle's.
            const float before = 0.05f + 0.25f * height(rng), after = 0.05f + 0.25f * height(rng);
            const Aabb local = Aabb::fromMinMax({std::min(0.0f, cu) - before, 0.0f, -0.2f},
                                                {std::max(bu, cu) + after, glm::dot(c - a, v), 0.2f});
            const QueryVolume volume = QueryVolume::fromTransformedBox(frame, local);

            ctx->clearFramebuffer(Renderer::kClearColour);
            r.beginFrame(cam);
            r.drawMesh(id, glm::mat4(1.0f), {1, 1, 1});
            // Only pixel centres within a few snapping steps of line AB can be missed (elsewhere
            // the box reaches past the part by more than snapping moves an edge).
            const glm::dmat4 vp = cam.viewProjectionRelativeDouble();
            auto toPixel = [&](const glm::vec3& w) {
                const glm::dvec4 clip = vp * glm::dvec4(glm::dvec3(w) - glm::dvec3(cam.position), 1.0);
                return glm::dvec2((clip.x / clip.w + 1.0) * 0.5 * kSize, (clip.y / clip.w + 1.0) * 0.5 * kSize);
            };
            const glm::dvec2 pa = toPixel(a), pb = toPixel(bv);
            const glm::dvec2 dir = glm::normalize(pb - pa), nrm(-dir.y, dir.x);
            for (const glm::ivec2 p : coveredPixels(r, kSize, kSize)) {
                if (std::abs(glm::dot(glm::dvec2(p) + 0.5 - pa, nrm)) > 0.02) continue;
                ctx->clearFramebuffer(Renderer::kClearColour);
                r.beginFrame(cam);
                r.drawMesh(id, glm::mat4(1.0f), {1, 1, 1});
                nearestExceptPixel(p, kSize, kSize);
                b.beginFrame(FrameView::of(cam, kSize, kSize));
                b.beginBatch();
                const QueryId q = b.issue(volume);
                b.endBatch();
                const bool seen = b.wait(q, 10000.0) == QueryResult::Visible;
                b.release(q);
                r.endFrame();
                if (!seen) ++(margin == SnappingMargin::None ? missedWithout : margin == SnappingMargin::Ring ? missedRing : missedGrown);
                if (margin == SnappingMargin::None) ++pixels;
            }
        }
    }
    std::printf("%u triangle pixels near the shared edge: %u missed by the tight volume alone, %u with the snapping ring, %u with "
                "the box grown across the view\n",
                pixels, missedWithout, missedRing, missedGrown);
    EXPECT_GT(pixels, 100u);
    EXPECT_GT(missedWithout, 0u) << "the case the margin exists for should occur";
    EXPECT_EQ(missedRing, 0u);
    EXPECT_EQ(missedGrown, 0u);
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

// The default margin grows a box across the view direction (prepareVolume) by a disc whose
// radius scales with the box's farthest clip w. Its outline must then reach a pixel centre
// 0.006 px outside its exact outline (more than a snapping step, less than the margin),
// under a rotated perspective camera and an orthographic one, on every side of a
// non-square view; without a margin each such centre is missed, so the case is real.
TEST(VolumeSnapping, GrownBoxesReachPixelCentresJustOutsideTheirOutline) {
    constexpr int kWidth = 96, kHeight = 48;
    constexpr double kOutside = 0.006;  // pixels
    auto ctx = test::headless(kWidth, kHeight);
    ASSERT_TRUE(ctx);
    auto made = Renderer::create(*ctx);
    ASSERT_TRUE(made.ok()) << made.error().message;
    Renderer& r = **made;
    Camera perspective;
    perspective.position = {1.5f, -2.0f, 4.0f};
    perspective.target = {0.3f, 0.2f, -1.0f};
    perspective.up = glm::normalize(glm::vec3(0.3f, 1.0f, 0.1f));
    perspective.aspect = float(kWidth) / float(kHeight);
    perspective.nearPlane = 0.1f;
    perspective.farPlane = 100.0f;
    Camera orthographic = perspective;
    orthographic.orthoHeight = 3.0f;
    std::mt19937 rng(11);
    for (const Camera& cam : {perspective, orthographic}) {
        const glm::dmat4 toWorld = glm::inverse(glm::dmat4(cam.view()));
        const glm::dmat4 vp = cam.viewProjectionRelativeDouble();
        const glm::dvec2 size(kWidth, kHeight);
        auto pixelOf = [&](const glm::dvec3& viewPoint) {  // pixels, y up
            const glm::dvec4 clip = vp * glm::dvec4(glm::dvec3(toWorld * glm::dvec4(viewPoint, 1.0)) - glm::dvec3(cam.position), 1.0);
            return (glm::dvec2(clip) / clip.w + 1.0) * 0.5 * size;
        };
        // The view-space coordinate on `axis` at depth z whose image lies at pixel coordinate
        // `px` (the image is affine in it at a fixed depth).
        auto viewCoordAt = [&](int axis, double px, double z) {
            glm::dvec3 p0(0.0, 0.0, z), p1(0.0, 0.0, z);
            p1[axis] = 1.0;
            const double a = pixelOf(p0)[axis], b = pixelOf(p1)[axis];
            return (px - a) / (b - a);
        };
        std::uint32_t missed[3] = {0, 0, 0};
        const SnappingMargin margins[3] = {SnappingMargin::None, SnappingMargin::Ring, SnappingMargin::GrowBoxes};
        constexpr int kTrials = 40;
        for (int m = 0; m < 3; ++m) {
            GlQueryParams qp;
            qp.snapping = margins[m];
            auto backendOr = GlQueryBackend::create(*ctx, qp);
            ASSERT_TRUE(backendOr.ok()) << backendOr.error().message;
            GlQueryBackend& b = **backendOr;
            rng.seed(11);
            std::uniform_int_distribution<int> px(4, kWidth - 5), py(4, kHeight - 5);
            std::uniform_real_distribution<double> nearDepth(2.0, 6.0), deep(0.3, 2.0), wide(1.0, 6.0);
            for (int trial = 0; trial < kTrials; ++trial) {
                const glm::ivec2 p(px(rng), py(rng));
                const int axis = trial % 2, other = 1 - axis;
                const double zNear = -nearDepth(rng), zFar = zNear - deep(rng);
                // The box lies toward the view's centre from the pixel, with its edge on `axis`
                // just short of the pixel centre: for a perspective camera that edge of the
                // outline is the near face's.
                const glm::dvec2 centre = glm::dvec2(p) + 0.5;
                const double side = centre[axis] > 0.5 * size[axis] ? 1.0 : -1.0;
                const double edge = viewCoordAt(axis, centre[axis] - side * kOutside, zNear);
                const double inner = viewCoordAt(axis, centre[axis] - side * wide(rng), zNear);
                const double across0 = viewCoordAt(other, centre[other] - 3.0, zNear), across1 = viewCoordAt(other, centre[other] + 3.0, zNear);
                glm::dvec3 lo, hi;
                lo[axis] = std::min(edge, inner);
                hi[axis] = std::max(edge, inner);
                lo[other] = std::min(across0, across1);
                hi[other] = std::max(across0, across1);
                lo.z = zFar;
                hi.z = zNear;
                const QueryVolume volume = QueryVolume::fromTransformedBox(glm::mat4(toWorld), Aabb::fromMinMax(glm::vec3(lo), glm::vec3(hi)));

                ctx->clearFramebuffer(Renderer::kClearColour);
                r.beginFrame(cam);
                nearestExceptPixel(p, kWidth, kHeight);
                b.beginFrame(FrameView::of(cam, kWidth, kHeight));
                b.beginBatch();
                const QueryId q = b.issue(volume);
                b.endBatch();
                if (b.wait(q, 10000.0) != QueryResult::Visible) ++missed[m];
                b.release(q);
                r.endFrame();
            }
        }
        SCOPED_TRACE(cam.orthographic() ? "orthographic" : "perspective");
        EXPECT_EQ(missed[0], std::uint32_t(kTrials)) << "without a margin every centre just outside is missed";
        EXPECT_EQ(missed[1], 0u) << "the ring";
        EXPECT_EQ(missed[2], 0u) << "the box grown across the view";
    }
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

}  // namespace
}  // namespace dyncull
