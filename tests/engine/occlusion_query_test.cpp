// Sanity of the occlusion-query path the scheduler relies on: a box behind an occluder
// yields no samples, a box in front does, and the proxy leaves the image untouched.
#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "dyncull/engine/gl_query_backend.hpp"
#include "gl_test_util.hpp"
#include "procedural_meshes.hpp"

namespace dyncull {
namespace {

// Box volumes through the query backend, the path the scheduler takes: behind a wall
// they are occluded, in front visible, and the test writes no colour.
TEST(OcclusionQuery, HiddenBoxZeroVisibleBoxOne) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    auto made = Renderer::create(*ctx);
    ASSERT_TRUE(made.ok()) << made.error().message;
    Renderer& r = **made;
    auto backendOr = GlQueryBackend::create(*ctx);
    ASSERT_TRUE(backendOr.ok()) << backendOr.error().message;
    GlQueryBackend& b = **backendOr;
    const Camera cam = test::cameraOnZ(3.0f);
    const MeshId wall = *r.upload(test::quadMesh(5.0f));  // fills the whole view at z = 0
    ctx->clearFramebuffer(Renderer::kClearColour);
    r.beginFrame(cam);
    r.drawMesh(wall, glm::mat4(1.0f), {0.5f, 0.5f, 0.5f});
    const glm::u8vec4 before = r.readPixels().at(32, 32);

    b.beginFrame(FrameView::of(cam, test::kW, test::kH));
    b.beginBatch();
    const QueryId behind = b.issue(QueryVolume::fromAabb(Aabb::fromMinMax({-0.5f, -0.5f, -2.0f}, {0.5f, 0.5f, -1.0f})));
    const QueryId inFront = b.issue(QueryVolume::fromAabb(Aabb::fromMinMax({-0.5f, -0.5f, 1.0f}, {0.5f, 0.5f, 2.0f})));
    // Object-space box moved in front of the wall by the object's matrix.
    const glm::mat4 model = glm::translate(glm::mat4(1.0f), {0, 0, 3.0f});
    const QueryId moved =
        b.issue(QueryVolume::fromTransformedBox(model, Aabb::fromMinMax({-0.2f, -0.2f, -2.0f}, {0.2f, 0.2f, -1.5f})));
    // A flat box lying exactly on the wall counts as visible (ties pass): conservative.
    const QueryId onWall = b.issue(QueryVolume::fromAabb(Aabb::fromMinMax({-0.2f, -0.2f, 0.0f}, {0.2f, 0.2f, 0.0f})));
    b.endBatch();
    EXPECT_EQ(b.wait(behind, 10000.0), QueryResult::Occluded);
    EXPECT_EQ(b.wait(inFront, 10000.0), QueryResult::Visible);
    EXPECT_EQ(b.wait(moved, 10000.0), QueryResult::Visible);
    EXPECT_EQ(b.wait(onWall, 10000.0), QueryResult::Visible);
    for (QueryId id : {behind, inFront, moved, onWall}) b.release(id);
    r.endFrame();

    EXPECT_EQ(r.readPixels().at(32, 32), before) << "query volumes must not write colour";
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

/// A convex mesh volume: the octahedron with vertices centre +- half.x/y/z along the axes.
QueryVolume octahedron(const glm::vec3& centre, const glm::vec3& half) {
    QueryVolume v;
    v.vertexCount = 6;
    for (int a = 0; a < 3; ++a) {
        glm::vec3 d(0.0f);
        d[a] = half[a];
        v.vertices[2 * a] = centre - d;
        v.vertices[2 * a + 1] = centre + d;
    }
    // Faces: one vertex from each axis pair, wound either way (the backend orients them).
    v.triangleCount = 8;
    for (int f = 0; f < 8; ++f) {
        v.indices[3 * f] = static_cast<std::uint8_t>(0 + ((f >> 0) & 1));
        v.indices[3 * f + 1] = static_cast<std::uint8_t>(2 + ((f >> 1) & 1));
        v.indices[3 * f + 2] = static_cast<std::uint8_t>(4 + ((f >> 2) & 1));
    }
    return v;
}

TEST(OcclusionQuery, BackendMeshVolumesAndVolumesReachingTheNearPlane) {
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
    b.beginBatch();
    const QueryId behind = b.issue(octahedron({0, 0, -1.0f}, glm::vec3(0.5f)));
    const QueryId inFront = b.issue(octahedron({0, 0, 1.0f}, glm::vec3(0.5f)));
    // Behind the wall but long enough to reach past the near plane: clipped there it
    // might miss the samples in front of the wall, so it must answer Visible undrawn.
    const QueryId throughNear = b.issue(octahedron({0, 0, 0.0f}, {0.1f, 0.1f, 2.95f}));
    b.endBatch();
    EXPECT_EQ(b.poll(throughNear), QueryResult::Visible);  // answered at once
    EXPECT_EQ(b.samples(throughNear), 0u);
    EXPECT_EQ(b.wait(behind, 10000.0), QueryResult::Occluded);
    EXPECT_EQ(b.wait(inFront, 10000.0), QueryResult::Visible);
    for (QueryId id : {behind, inFront, throughNear}) b.release(id);
    r.endFrame();
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

// The backend draws front faces only, so it must find them itself: a volume whose faces
// are all wound inward, or mixed, covers exactly the samples of the outward one. A wall
// through the volume's middle hides its back half, which wrongly wound faces would draw.
TEST(OcclusionQuery, VolumesCoverTheSameSamplesWhateverTheirWinding) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    auto backendOr = GlQueryBackend::create(*ctx, {.visiblePixelThreshold = 1});
    ASSERT_TRUE(backendOr.ok()) << backendOr.error().message;
    GlQueryBackend& b = **backendOr;
    const Camera cam = test::cameraOnZ(3.0f);
    auto made = Renderer::create(*ctx);
    ASSERT_TRUE(made.ok()) << made.error().message;
    Renderer& r = **made;
    const MeshId wall = *r.upload(test::quadMesh(5.0f));  // fills the whole view at z = 0
    ctx->clearFramebuffer(Renderer::kClearColour);
    r.beginFrame(cam);
    r.drawMesh(wall, glm::mat4(1.0f), {0.5f, 0.5f, 0.5f});
    b.beginFrame(FrameView::of(cam, test::kW, test::kH));
    const QueryVolume mixed = octahedron({0.2f, -0.1f, 0.0f}, {0.6f, 0.4f, 0.5f});
    QueryVolume outward = mixed, inward = mixed;
    for (std::uint32_t t = 0; t < mixed.triangleCount; ++t) {
        const glm::vec3 a = mixed.vertices[mixed.indices[3 * t]], bb = mixed.vertices[mixed.indices[3 * t + 1]],
                        c = mixed.vertices[mixed.indices[3 * t + 2]];
        const bool out = glm::dot(a - glm::vec3(0.2f, -0.1f, 0.0f), glm::cross(bb - a, c - a)) > 0.0f;
        std::swap(outward.indices[3 * t + 1], outward.indices[3 * t + (out ? 1 : 2)]);
        std::swap(inward.indices[3 * t + 1], inward.indices[3 * t + (out ? 2 : 1)]);
    }
    b.beginBatch();
    const QueryId ids[3] = {b.issue(outward), b.issue(inward), b.issue(mixed)};
    b.endBatch();
    std::uint64_t samples[3];
    for (int i = 0; i < 3; ++i) {
        ASSERT_EQ(b.wait(ids[i], 10000.0), QueryResult::Visible);
        samples[i] = b.samples(ids[i]);
        b.release(ids[i]);
    }
    EXPECT_GT(samples[0], 200u);  // of 64x64 pixels
    EXPECT_EQ(samples[1], samples[0]);
    EXPECT_EQ(samples[2], samples[0]);
    r.endFrame();
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

// A released query object is begun again only after a query begun after its release has
// answered: Mesa llvmpipe may still be signalling the fence the object holds when the
// answer first shows (docs/RELIABILITY.md, "Heap corruption in llvmpipe").
TEST(OcclusionQuery, ReleasedQueryObjectWaitsForALaterAnswerBeforeReuse) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    auto made = Renderer::create(*ctx);
    ASSERT_TRUE(made.ok()) << made.error().message;
    Renderer& r = **made;
    auto backendOr = GlQueryBackend::create(*ctx);
    ASSERT_TRUE(backendOr.ok()) << backendOr.error().message;
    GlQueryBackend& b = **backendOr;
    const Camera cam = test::cameraOnZ(3.0f);
    ctx->clearFramebuffer(Renderer::kClearColour);
    r.beginFrame(cam);  // binds and clears the framebuffer: every volume is visible
    auto stopAndWait = [&] {  // Simple OC's pattern: issue, wait, release
        b.beginBatch();
        const QueryId q = b.issue(octahedron({0, 0, 0.0f}, glm::vec3(0.5f)));
        b.endBatch();
        EXPECT_EQ(b.wait(q, 10000.0), QueryResult::Visible);
        b.release(q);
        return q;
    };
    b.beginFrame(FrameView::of(cam, test::kW, test::kH));
    const QueryId first = stopAndWait();
    EXPECT_EQ(b.poolSize(), 1u);
    // `first` was released, but no query begun since has answered: a second object.
    const QueryId second = stopAndWait();
    EXPECT_NE(second, first);
    EXPECT_EQ(b.poolSize(), 2u);
    // `second` answered after `first`'s release: `first` is reused, and so on, round robin.
    for (int i = 0; i < 10; ++i) {
        const QueryId q = stopAndWait();
        EXPECT_EQ(q, i % 2 == 0 ? first : second) << "round " << i;
    }
    EXPECT_EQ(b.poolSize(), 2u);
    EXPECT_EQ(b.inUse(), 0u);
    // Queries released unanswered do not count as answers for each other.
    b.beginBatch();
    const QueryId a = b.issue(octahedron({0, 0, 0.0f}, glm::vec3(0.5f)));
    const QueryId c = b.issue(octahedron({0, 0, 0.0f}, glm::vec3(0.5f)));
    b.endBatch();
    b.release(a);
    b.release(c);
    b.beginBatch();
    const QueryId d = b.issue(octahedron({0, 0, 0.0f}, glm::vec3(0.5f)));
    b.endBatch();
    EXPECT_NE(d, a);
    EXPECT_NE(d, c);
    // a took the older loop object; c and d each needed a new one (the newer loop object
    // waits for an answer begun after its release).
    EXPECT_EQ(b.poolSize(), 4u);
    EXPECT_EQ(b.wait(d, 10000.0), QueryResult::Visible);
    b.release(d);
    r.endFrame();
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

}  // namespace
}  // namespace dyncull
