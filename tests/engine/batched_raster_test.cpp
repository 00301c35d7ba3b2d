// The batched raster test (GlQueryBackend::testVolumes) against its oracle, one hardware
// query per volume: the same answer for every volume of a random scene, volumes reaching
// the near plane answered Visible undrawn, and the GL state left as it was found.
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
        r.beginFrame(cam);
        // Occluders: spheres and tilted quads scattered between the volumes.
        std::uniform_real_distribution<float> pos(-1.5f, 1.5f), z(-1.0f, 1.5f), s(0.2f, 0.9f);
        for (int k = 0; k < 8; ++k) {
            glm::mat4 m = glm::translate(glm::mat4(1.0f), {pos(rng), pos(rng), z(rng)});
            m = glm::scale(glm::rotate(m, pos(rng), glm::vec3(1, 0, 0)), glm::vec3(s(rng)));
            r.drawMesh(k % 2 ? sphere : quad, m, {0.5f, 0.5f, 0.5f});
        }
        b.beginFrame(cam, 160, 120);
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
    r.beginFrame(cam);
    r.drawMesh(wall, glm::mat4(1.0f), {0.5f, 0.5f, 0.5f});
    b.beginFrame(cam, test::kW, test::kH);

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

}  // namespace
}  // namespace dyncull
