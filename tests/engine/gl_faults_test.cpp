// GL faults reported cleanly (issue 9, item 5): a lost context and failed buffer
// allocations come back as errors from the engine calls, never as a crash, garbage or a
// stream of GL errors, and a failed allocation leaves the engine as it was. llvmpipe
// neither loses contexts nor runs out of memory on these sizes, so the faults are
// injected through GlContext::faultInjectionForTesting(); everything after the injection
// point (error paths, clean-up, later calls) is the production code.
#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include "dyncull/engine/engine.hpp"
#include "engine/gl_test_util.hpp"
#include "engine/procedural_meshes.hpp"
#include "objects/transform_at.hpp"

namespace dyncull {
namespace {

using test::cameraOnZ;
using test::headless;
using test::isClear;

using test::at;

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// A quad in front of a cube (hidden behind it), Simple OC so every node in the frustum
// gets exactly one query: normally the quad is drawn and the cube culled.
struct FaultRig : ::testing::Test {
    std::unique_ptr<GlContext> ctx = headless();
    std::unique_ptr<Engine> engine;
    ModelId quadModel = 0, cubeModel = 0;

    void SetUp() override {
        ASSERT_TRUE(ctx);
        EngineOptions eo;
        eo.scheduler.mode = CullMode::Simple;
        auto e = Engine::create(*ctx, eo);
        ASSERT_TRUE(e.ok()) << e.error().message;
        engine = e.take();
        auto quad = engine->addModel(test::quadMesh(1.0f));
        auto cube = engine->addModel(test::cubeMesh(0.4f));
        ASSERT_TRUE(quad.ok() && cube.ok());
        quadModel = *quad;
        cubeModel = *cube;
        ASSERT_TRUE(engine->addObject(quadModel, at({0, 0, 0})).ok());
        ASSERT_TRUE(engine->addObject(cubeModel, at({0, 0, -2})).ok());  // right behind the quad
        ASSERT_TRUE(engine->setCamera(cameraOnZ(3.0f)).ok());
    }

    Expected<FrameStats> frame() {
        ctx->clearFramebuffer(Renderer::kClearColour);
        return engine->renderFrame();
    }
};

TEST_F(FaultRig, HealthyContextReportsNoReset) {
    // Robustness is requested on every platform; llvmpipe may or may not grant reset
    // notification, but a healthy context never reports a reset either way.
    std::printf("reset notification (LOSE_CONTEXT_ON_RESET): %s\n", ctx->resetNotification() ? "yes" : "no");
    EXPECT_EQ(glGetGraphicsResetStatus(), static_cast<GLenum>(GL_NO_ERROR));
    EXPECT_TRUE(ctx->checkReset().ok());
    EXPECT_FALSE(ctx->lost());
    auto st = frame();
    ASSERT_TRUE(st.ok()) << st.error().message;
    EXPECT_EQ(st->partsDrawn, 1u);  // the quad; the cube is occluded
    EXPECT_EQ(st->queriesOccluded, 1u);
}

TEST_F(FaultRig, FailedUploadLeavesTheEngineAsBefore) {
    const std::size_t models = engine->objects().modelCount();
    const std::size_t meshes = engine->renderer().meshCount();
    const std::size_t bytes = engine->renderer().uploadedBytes();

    Mesh sphere = test::sphereMesh(0.5f);
    sphere.name = "sphere";
    for (std::uint32_t before : {0u, 1u}) {  // vertex buffer fails, then index buffer fails
        ctx->faultInjectionForTesting().allocationsBeforeFailure = before;
        ctx->faultInjectionForTesting().failBufferAllocations = 1;
        // Buffer names are handed out in increasing order: the names between two probes
        // are the failed upload's, and none of them may still be a buffer.
        GLuint probe[2] = {0, 0};
        glCreateBuffers(1, &probe[0]);
        auto id = engine->addModel(sphere);
        glCreateBuffers(1, &probe[1]);
        glDeleteBuffers(2, probe);
        EXPECT_EQ(probe[1] - probe[0] - 1, before + 1) << "buffers the failed upload created";
        for (GLuint n = probe[0] + 1; n < probe[1]; ++n) EXPECT_FALSE(glIsBuffer(n)) << "buffer " << n << " leaked";
        ASSERT_FALSE(id.ok()) << "allocation " << before << " should have failed";
        EXPECT_TRUE(contains(id.error().message, "out of GPU memory uploading mesh 'sphere' (")) << id.error().message;
        EXPECT_TRUE(contains(id.error().message, " bytes)")) << id.error().message;
        EXPECT_EQ(engine->objects().modelCount(), models);
        EXPECT_EQ(engine->renderer().meshCount(), meshes);
        EXPECT_EQ(engine->renderer().uploadedBytes(), bytes);
    }
    EXPECT_EQ(ctx->faultInjectionForTesting().failBufferAllocations, 0u);

    // Earlier models still draw.
    auto st = frame();
    ASSERT_TRUE(st.ok()) << st.error().message;
    EXPECT_EQ(st->partsDrawn, 1u);
    EXPECT_FALSE(isClear(engine->renderer().readPixels().at(test::kW / 2, test::kH / 2)));

    // A later upload succeeds and gets the next model id.
    auto id = engine->addModel(sphere);
    ASSERT_TRUE(id.ok()) << id.error().message;
    EXPECT_EQ(*id, static_cast<ModelId>(models));
    EXPECT_EQ(engine->renderer().meshCount(), meshes + 1);
    ASSERT_TRUE(engine->addObject(*id, at({0, 0, 1})).ok());  // in front of the quad
    st = frame();
    ASSERT_TRUE(st.ok()) << st.error().message;
    EXPECT_GE(st->partsDrawn, 2u);
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

TEST_F(FaultRig, QueryBufferOutOfMemoryCountsEveryQueryVisibleForOneFrame) {
    ASSERT_TRUE(frame().ok());
    ASSERT_EQ(engine->visibleParts().size(), 1u);
    // The frame's first allocation is the orphaning of the volume vertex buffer.
    ctx->faultInjectionForTesting().failBufferAllocations = 1;
    auto st = frame();
    ASSERT_FALSE(st.ok());
    EXPECT_TRUE(contains(st.error().message, "query backend: out of GPU memory orphaning the query volume vertex buffer ("))
        << st.error().message;
    EXPECT_TRUE(contains(st.error().message, "queries counted visible")) << st.error().message;
    EXPECT_EQ(engine->visibleParts().size(), 2u);  // nothing culled: the hidden cube is drawn too
    EXPECT_FALSE(engine->queryBackend().frameStatus().ok());
    // The next frame allocates again and culls as before.
    st = frame();
    ASSERT_TRUE(st.ok()) << st.error().message;
    EXPECT_EQ(st->partsDrawn, 1u);
    EXPECT_EQ(st->queriesOccluded, 1u);
    EXPECT_TRUE(engine->queryBackend().frameStatus().ok());
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

TEST(GlFaults, EngineCreationReportsQueryBufferAllocationFailure) {
    auto ctx = headless();
    ASSERT_TRUE(ctx);
    for (std::uint32_t before = 0; before < 2; ++before) {
        ctx->faultInjectionForTesting().allocationsBeforeFailure = before;
        ctx->faultInjectionForTesting().failBufferAllocations = 1;
        auto e = Engine::create(*ctx);
        ASSERT_FALSE(e.ok());
        const char* which[] = {"query volume index buffer (", "query volume vertex buffer ("};
        EXPECT_TRUE(contains(e.error().message, std::string("query backend: out of GPU memory creating the ") + which[before]))
            << e.error().message;
    }
    auto e = Engine::create(*ctx);
    EXPECT_TRUE(e.ok());
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

TEST_F(FaultRig, ContextLostBetweenFramesIsAnErrorFromThenOn) {
    ASSERT_TRUE(frame().ok());
    ctx->faultInjectionForTesting().simulateReset = ResetKind::Innocent;
    auto st = frame();
    ASSERT_FALSE(st.ok());
    const std::string message = st.error().message;
    EXPECT_EQ(message, "OpenGL context lost (innocent reset: another context caused it); recreate the GlContext and the Engine");
    EXPECT_EQ(engine->visibleParts().size(), 0u);  // refused before any GL work
    EXPECT_TRUE(ctx->lost());
    // Sticky even if the driver stopped saying so: every later GL-using call gives the same error.
    ctx->faultInjectionForTesting().simulateReset = ResetKind::None;
    st = frame();
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.error().message, message);
    ctx->clearFramebuffer(Renderer::kClearColour);
    auto parts = engine->renderParts({});
    ASSERT_FALSE(parts.ok());
    EXPECT_EQ(parts.error().message, message);
    const std::size_t models = engine->objects().modelCount();
    auto id = engine->addModel(test::cubeMesh(0.2f));
    ASSERT_FALSE(id.ok());
    EXPECT_EQ(id.error().message, message);
    EXPECT_EQ(engine->objects().modelCount(), models);
    EXPECT_EQ(ctx->checkErrors(), 0u);  // no GL error spam
    // Destruction (engine, then context) is clean: the ASan/LSan build runs this test too.
}

TEST_F(FaultRig, ContextLostDuringAFrameFailsThatFrame) {
    // The reset "happens" while the first part is drawn: the frame's image and query
    // results are undefined, so the frame itself reports it.
    int drawn = 0;
    engine->setDrawCallback([&](ObjectHandle, ModelId, std::uint32_t, std::uint32_t, const glm::mat4&) {
        if (drawn++ == 0) ctx->faultInjectionForTesting().simulateReset = ResetKind::Guilty;
    });
    auto st = frame();
    ASSERT_FALSE(st.ok());
    EXPECT_TRUE(contains(st.error().message, "OpenGL context lost (guilty reset")) << st.error().message;
    EXPECT_GE(drawn, 1);
    const int drawnBefore = drawn;
    st = frame();
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(drawn, drawnBefore);  // nothing drawn any more
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

TEST(GlFaults, UnknownResetMessage) {
    auto ctx = headless();
    ASSERT_TRUE(ctx);
    ctx->faultInjectionForTesting().simulateReset = ResetKind::Unknown;
    const Status s = ctx->checkReset();
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.message(), "OpenGL context lost (unknown reset: the driver gives no cause); recreate the GlContext and the Engine");
    EXPECT_TRUE(ctx->lost());
    // No Engine on a lost context.
    auto e = Engine::create(*ctx);
    ASSERT_FALSE(e.ok());
    EXPECT_EQ(e.error().message, s.message());
}

}  // namespace
}  // namespace dyncull
