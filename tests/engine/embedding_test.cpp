// The Engine as a game embeds it (engine/frame_contract.hpp): it draws into the game's own
// framebuffer and viewport without clearing them, leaves every piece of GL state as it
// found it, fails at once on the wrong context or none, and reports the GL errors raised
// inside its calls.
#include <chrono>
#include <map>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "dyncull/engine/engine.hpp"
#include "engine/gl_test_util.hpp"
#include "engine/procedural_meshes.hpp"
#include "objects/transform_at.hpp"

namespace dyncull {
namespace {

using test::at;

constexpr int kGameW = 96, kGameH = 64;
const glm::u8vec4 kGameColour{255, 0, 255, 255};

/// A game's framebuffer: RGBA8 colour and 32-bit float depth, both renderbuffers.
struct GameFramebuffer {
    GLuint fbo = 0, colour = 0, depth = 0;
    GameFramebuffer() {
        glCreateRenderbuffers(1, &colour);
        glNamedRenderbufferStorage(colour, GL_RGBA8, kGameW, kGameH);
        glCreateRenderbuffers(1, &depth);
        glNamedRenderbufferStorage(depth, GL_DEPTH_COMPONENT32F, kGameW, kGameH);
        glCreateFramebuffers(1, &fbo);
        glNamedFramebufferRenderbuffer(fbo, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
        glNamedFramebufferRenderbuffer(fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    }
    ~GameFramebuffer() {
        glDeleteFramebuffers(1, &fbo);
        glDeleteRenderbuffers(1, &colour);
        glDeleteRenderbuffers(1, &depth);
    }
    /// The game's clear: magenta, depth at the far plane of the reversed-Z convention.
    void clear() const {
        // Clears obey the write masks and the scissor, which a game's state may have set.
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glDepthMask(GL_TRUE);
        glDisable(GL_SCISSOR_TEST);
        const float c[4] = {1, 0, 1, 1};
        const float far = 0.0f;
        glClearNamedFramebufferfv(fbo, GL_COLOR, 0, c);
        glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &far);
    }
    /// Colour and depth, bottom-up rows, read with default pack state.
    void read(std::vector<glm::u8vec4>& rgba, std::vector<float>& z) const {
        rgba.resize(std::size_t{kGameW} * kGameH);
        z.resize(rgba.size());
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
        glReadPixels(0, 0, kGameW, kGameH, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
        glReadPixels(0, 0, kGameW, kGameH, GL_DEPTH_COMPONENT, GL_FLOAT, z.data());
    }
};

/// Every piece of state the frame contract promises to restore, read independently of the
/// engine's own scope (so a state it forgot to save shows up here).
std::map<std::string, std::vector<double>> snapshot() {
    std::map<std::string, std::vector<double>> s;
    auto ints = [&](const char* name, GLenum e, int n = 1) {
        GLint v[4] = {};
        glGetIntegerv(e, v);
        s[name] = std::vector<double>(v, v + n);
    };
    auto floats = [&](const char* name, GLenum e, int n = 1) {
        GLfloat v[4] = {};
        glGetFloatv(e, v);
        s[name] = std::vector<double>(v, v + n);
    };
    auto enabled = [&](const char* name, GLenum e) { s[name] = {double(glIsEnabled(e))}; };
    ints("draw framebuffer", GL_DRAW_FRAMEBUFFER_BINDING);
    ints("read framebuffer", GL_READ_FRAMEBUFFER_BINDING);
    ints("viewport", GL_VIEWPORT, 4);
    ints("scissor box", GL_SCISSOR_BOX, 4);
    ints("program", GL_CURRENT_PROGRAM);
    ints("vertex array", GL_VERTEX_ARRAY_BINDING);
    ints("array buffer", GL_ARRAY_BUFFER_BINDING);
    ints("element buffer (of the vertex array)", GL_ELEMENT_ARRAY_BUFFER_BINDING);
    ints("storage buffer", GL_SHADER_STORAGE_BUFFER_BINDING);
    ints("pixel pack buffer", GL_PIXEL_PACK_BUFFER_BINDING);
    ints("pack alignment", GL_PACK_ALIGNMENT);
    ints("pack row length", GL_PACK_ROW_LENGTH);
    ints("pack skip rows", GL_PACK_SKIP_ROWS);
    ints("pack skip pixels", GL_PACK_SKIP_PIXELS);
    ints("depth func", GL_DEPTH_FUNC);
    ints("cull face mode", GL_CULL_FACE_MODE);
    ints("front face", GL_FRONT_FACE);
    ints("polygon mode", GL_POLYGON_MODE);
    ints("clip origin", GL_CLIP_ORIGIN);
    ints("clip depth mode", GL_CLIP_DEPTH_MODE);
    ints("blend src", GL_BLEND_SRC_RGB);
    ints("blend dst", GL_BLEND_DST_RGB);
    ints("depth write mask", GL_DEPTH_WRITEMASK);
    ints("colour write mask", GL_COLOR_WRITEMASK, 4);
    floats("depth range", GL_DEPTH_RANGE, 2);
    floats("polygon offset factor", GL_POLYGON_OFFSET_FACTOR);
    floats("polygon offset units", GL_POLYGON_OFFSET_UNITS);
    floats("clear colour", GL_COLOR_CLEAR_VALUE, 4);
    floats("clear depth", GL_DEPTH_CLEAR_VALUE);
    enabled("depth test", GL_DEPTH_TEST);
    enabled("blend", GL_BLEND);
    enabled("stencil test", GL_STENCIL_TEST);
    enabled("scissor test", GL_SCISSOR_TEST);
    enabled("depth clamp", GL_DEPTH_CLAMP);
    enabled("cull face", GL_CULL_FACE);
    enabled("polygon offset fill", GL_POLYGON_OFFSET_FILL);
    enabled("rasteriser discard", GL_RASTERIZER_DISCARD);
    for (GLuint binding : {0u, 1u}) {  // the batched raster test's and the part marks'
        GLint buffer = 0;
        glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, binding, &buffer);
        s["storage buffer binding " + std::to_string(binding)] = {double(buffer)};
    }
    return s;
}

/// A scene for both conservative modes: a wall at z = 0 hiding a sphere, and a sphere in
/// front of it; the camera on +Z sees them inside a viewport of the right half.
struct GameScene {
    std::unique_ptr<Engine> engine;
    ObjectHandle wall, hidden, front;

    explicit GameScene(GlContext& ctx) {
        auto e = Engine::create(ctx);
        EXPECT_TRUE(e.ok()) << (e.ok() ? "" : e.error().message);
        if (!e) return;
        engine = e.take();
        const ModelId quad = *engine->addModel(test::quadMesh(1.0f));
        const ModelId ball = *engine->addModel(test::sphereMesh(0.3f));
        wall = *engine->addObject(quad, at({0, 0, 0}));
        hidden = *engine->addObject(ball, at({0, 0, -1.5f}));
        front = *engine->addObject(ball, at({0.3f, 0.3f, 1.0f}));
        Camera cam = test::cameraOnZ(3.0f);
        cam.aspect = float(kGameW / 2) / float(kGameH);
        EXPECT_TRUE(engine->setCamera(cam).ok());
    }
};

/// Sets a game's state: everything different from both GL's defaults and what dyncull uses.
struct GameState {
    GLuint vao = 0, buffer = 0, storage = 0;
    explicit GameState(const GameFramebuffer& fb, GLuint readFbo) {
        glCreateBuffers(1, &buffer);
        glNamedBufferData(buffer, 256, nullptr, GL_STATIC_DRAW);
        glCreateBuffers(1, &storage);
        glNamedBufferData(storage, 256, nullptr, GL_STATIC_DRAW);
        glCreateVertexArrays(1, &vao);
        glVertexArrayElementBuffer(vao, buffer);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fb.fbo);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, readFbo);
        glViewport(kGameW / 2, 0, kGameW / 2, kGameH);
        glScissor(1, 2, 3, 4);
        glBindVertexArray(vao);
        glBindBuffer(GL_ARRAY_BUFFER, buffer);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, storage);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, storage);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffer);  // the generic binding differs from bindings 0 and 1
        glBindBuffer(GL_PIXEL_PACK_BUFFER, buffer);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glPixelStorei(GL_PACK_ROW_LENGTH, 7);
        glPixelStorei(GL_PACK_SKIP_ROWS, 1);
        glPixelStorei(GL_PACK_SKIP_PIXELS, 2);
        glDepthFunc(GL_LEQUAL);
        glCullFace(GL_FRONT);
        glFrontFace(GL_CW);
        glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
        glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE);
        glDepthMask(GL_FALSE);
        glColorMask(GL_TRUE, GL_FALSE, GL_TRUE, GL_FALSE);
        glDepthRange(0.25, 0.75);
        glPolygonOffset(2.0f, 3.0f);
        glClearColor(0.1f, 0.2f, 0.3f, 0.4f);
        glClearDepth(0.5);
        glDisable(GL_DEPTH_TEST);
        glEnable(GL_STENCIL_TEST);
        glEnable(GL_DEPTH_CLAMP);
        glEnable(GL_CULL_FACE);
        glEnable(GL_POLYGON_OFFSET_FILL);
    }
    /// Back to defaults for the test's own readback.
    static void reset() {
        glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glPixelStorei(GL_PACK_ROW_LENGTH, 0);
        glPixelStorei(GL_PACK_SKIP_ROWS, 0);
        glPixelStorei(GL_PACK_SKIP_PIXELS, 0);
    }
    ~GameState() {
        glDeleteVertexArrays(1, &vao);
        glDeleteBuffers(1, &buffer);
        glDeleteBuffers(1, &storage);
    }
};

TEST(Embedding, GameStateAndFramebufferAreUntouchedByAFrame) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    GameScene scene(*ctx);
    ASSERT_TRUE(scene.engine);
    Engine& engine = *scene.engine;
    ASSERT_EQ(engine.scheduler().params().mode, CullMode::TwoPhase);
    GameFramebuffer fb;
    SchedulerParams queries;
    queries.mode = CullMode::Queries;
    QueryScheduler queryScheduler(queries);
    SchedulerParams alwaysTest;  // two-phase testing every frame (the cost model would pause)
    alwaysTest.features.useCostModel = false;
    QueryScheduler testingScheduler(alwaysTest);
    SchedulerParams triangles = alwaysTest;  // and on the parts' own triangles, draws marked
    triangles.features.useTriangleTests = true;
    QueryScheduler triangleScheduler(triangles);

    // Frames of the default mode, of two-phase with its depth readback and batched raster
    // test every frame (then with triangle tests too), and of hardware queries, each against
    // the game's state and framebuffer.
    std::vector<glm::u8vec4> firstFrame;  // every mode must draw the same image (conservative, static scene)
    for (int frame = 0; frame < 12; ++frame) {
        GameState::reset();
        fb.clear();
        std::vector<glm::u8vec4> rgba;
        std::vector<float> depth;
        GameState game(fb, ctx->framebuffer());
        const auto before = snapshot();
        auto st = frame % 4 == 0   ? engine.renderFrame()
                  : frame % 4 == 1 ? engine.renderFrame(testingScheduler)
                  : frame % 4 == 2 ? engine.renderFrame(triangleScheduler)
                                   : engine.renderFrame(queryScheduler);
        ASSERT_TRUE(st.ok()) << st.error().message;
        const auto after = snapshot();
        for (const auto& [name, value] : before) EXPECT_EQ(after.at(name), value) << name << ", frame " << frame;
        EXPECT_EQ(engine.callerGlErrors(), 0u);
        EXPECT_EQ(ctx->checkErrors(), 0u);

        GameState::reset();
        fb.read(rgba, depth);
        // Left half, outside the viewport: the game's pixels. Right half: the game's colour
        // where nothing was drawn (no clear), the wall and the front sphere where they are.
        std::uint64_t drawn = 0;
        for (int y = 0; y < kGameH; ++y)
            for (int x = 0; x < kGameW; ++x) {
                const std::size_t i = std::size_t(y) * kGameW + x;
                if (x < kGameW / 2) {
                    ASSERT_EQ(rgba[i], kGameColour) << x << "," << y << " outside the viewport, frame " << frame;
                    ASSERT_EQ(depth[i], 0.0f);
                } else if (rgba[i] != kGameColour) {
                    ++drawn;
                    EXPECT_GT(depth[i], 0.0f);
                } else {
                    EXPECT_EQ(depth[i], 0.0f);
                }
            }
        EXPECT_GT(drawn, 200u) << "frame " << frame;
        if (frame == 0) firstFrame = rgba;
        std::uint64_t differ = 0;
        for (std::size_t i = 0; i < rgba.size(); ++i) differ += rgba[i] != firstFrame[i];
        EXPECT_EQ(differ, 0u) << "pixels unlike frame 0's, frame " << frame;
        EXPECT_LT(drawn, std::uint64_t{kGameW / 2} * kGameH) << "the game's background must survive, frame " << frame;
    }
}

TEST(Embedding, WrongOrNoContextIsAnErrorAtOnce) {
    auto a = test::headless();
    auto b = test::headless();  // current now
    ASSERT_TRUE(a && b);
    GameScene onB(*b);
    ASSERT_TRUE(onB.engine);
    a->makeCurrent();
    GameScene onA(*a);
    ASSERT_TRUE(onA.engine);
    a->clearFramebuffer(Renderer::kClearColour);
    ASSERT_TRUE(onA.engine->renderFrame().ok());
    const Image reference = onA.engine->renderer().readPixels();

    // B's engine with A current: an error naming the cause, at once, and A untouched.
    const auto t0 = std::chrono::steady_clock::now();
    auto st = onB.engine->renderFrame();
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.error().code, ErrorCode::WrongContext);
    EXPECT_NE(st.error().message.find("not the one"), std::string::npos) << st.error().message;
    auto model = onB.engine->addModel(test::cubeMesh(0.5f));
    ASSERT_FALSE(model.ok());
    EXPECT_EQ(model.error().code, ErrorCode::WrongContext);
    EXPECT_EQ(onB.engine->objects().modelCount(), 2u) << "a failed addModel registers nothing";
    auto created = Engine::create(*b);
    ASSERT_FALSE(created.ok());
    EXPECT_EQ(created.error().code, ErrorCode::WrongContext);
    // Destroying B's engine with A current must not delete A's objects of the same names.
    onB.engine.reset();
    a->clearFramebuffer(Renderer::kClearColour);
    ASSERT_TRUE(onA.engine->renderFrame().ok());
    EXPECT_EQ(onA.engine->renderer().readPixels().rgba, reference.rgba);

    // No context current at all.
    a->releaseCurrent();
    EXPECT_FALSE(a->isCurrent());
    auto none = onA.engine->renderFrame();
    ASSERT_FALSE(none.ok());
    EXPECT_EQ(none.error().code, ErrorCode::WrongContext);
    auto borrowed = GlContext::borrowCurrent();
    ASSERT_FALSE(borrowed.ok());
    EXPECT_EQ(borrowed.error().code, ErrorCode::WrongContext);
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);

    a->makeCurrent();
    a->clearFramebuffer(Renderer::kClearColour);
    ASSERT_TRUE(onA.engine->renderFrame().ok());
    EXPECT_EQ(onA.engine->renderer().readPixels().rgba, reference.rgba);
    EXPECT_EQ(a->checkErrors(), 0u);
}

TEST(Embedding, GlErrorsRaisedInsideAFrameComeBackAsErrors) {
    // Not a debug context: a debug one would print the deliberate errors.
    ContextOptions quiet;
    quiet.width = test::kW;
    quiet.height = test::kH;
    auto made = GlContext::create(quiet);
    ASSERT_TRUE(made.ok()) << made.error().message;
    std::unique_ptr<GlContext> ctx = made.take();
    GameScene scene(*ctx);
    ASSERT_TRUE(scene.engine);
    Engine& engine = *scene.engine;

    // Errors the game left pending are the game's: taken aside, not reported as dyncull's.
    glEnable(0xBEEF);
    ctx->clearFramebuffer(Renderer::kClearColour);
    auto ok = engine.renderFrame();
    ASSERT_TRUE(ok.ok()) << ok.error().message;
    EXPECT_EQ(engine.callerGlErrors(), 1u);

    // An error raised inside the frame (here by the game's own draw callback) is an error.
    engine.setDrawCallback([](ObjectHandle, ModelId, std::uint32_t, std::uint32_t, const glm::mat4&) { glEnable(0xDEAD); });
    ctx->clearFramebuffer(Renderer::kClearColour);
    auto bad = engine.renderFrame();
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().code, ErrorCode::GlError);
    EXPECT_NE(bad.error().message.find("GL_INVALID_ENUM"), std::string::npos) << bad.error().message;
    engine.setDrawCallback(nullptr);
    ctx->clearFramebuffer(Renderer::kClearColour);
    EXPECT_TRUE(engine.renderFrame().ok());
    (void)ctx->checkErrors();  // the deliberate errors were counted
}

// Without the part renderer nothing is uploaded, a frame without a draw callback is
// refused, and with one the game draws exactly the parts dyncull reports visible.
TEST(Embedding, WithoutThePartRendererTheGameDrawsThePartsItIsTold) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    EngineOptions eo;
    eo.partRenderer = false;
    auto made = Engine::create(*ctx, eo);
    ASSERT_TRUE(made.ok()) << made.error().message;
    Engine& engine = **made;
    EXPECT_FALSE(engine.hasRenderer());
    const ModelId ball = *engine.addModel(test::sphereMesh(0.3f));
    const ObjectHandle a = *engine.addObject(ball, at({-0.5f, 0, 0}));
    const ObjectHandle b = *engine.addObject(ball, at({0.5f, 0, 0}));
    const ObjectHandle gone = *engine.addObject(ball, at({50, 0, 0}));  // outside the frustum
    ASSERT_TRUE(engine.setCamera(test::cameraOnZ(3.0f)).ok());

    auto refused = engine.renderFrame();
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.error().code, ErrorCode::BadArgument);
    EXPECT_TRUE(engine.visibleParts().empty());

    std::vector<ObjectHandle> drawn;
    engine.setDrawCallback([&](ObjectHandle o, ModelId, std::uint32_t, std::uint32_t, const glm::mat4&) { drawn.push_back(o); });
    ctx->clearFramebuffer(Renderer::kClearColour);
    auto st = engine.renderFrame();
    ASSERT_TRUE(st.ok()) << st.error().message;
    EXPECT_EQ(drawn.size(), engine.visibleParts().size());
    EXPECT_TRUE(engine.isVisible(a));
    EXPECT_TRUE(engine.isVisible(b));
    EXPECT_FALSE(engine.isVisible(gone));
    EXPECT_EQ(engine.visibleObjects().size(), 2u);
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

// Two views of one scene and a second engine side by side, in three viewports of one
// framebuffer: each view has its own camera, history and visible lists, and each
// viewport holds exactly what its view draws alone.
TEST(Embedding, TwoViewsAndTwoEnginesDrawSideBySide) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    GameScene scene(*ctx), other(*ctx);
    ASSERT_TRUE(scene.engine && other.engine);
    Engine& engine = *scene.engine;
    constexpr int kThird = kGameW / 3;
    SchedulerParams queries;  // hardware queries: a box wholly behind the wall is culled at once
    queries.mode = CullMode::Queries;
    ASSERT_TRUE(engine.setSchedulerParams(queries).ok());
    Camera front = test::cameraOnZ(3.0f), behind = test::cameraOnZ(-3.0f);  // either side of the wall
    front.aspect = behind.aspect = float(kThird) / float(kGameH);
    ASSERT_TRUE(engine.setCamera(front).ok());
    auto second = engine.addView(behind, queries);
    ASSERT_TRUE(second.ok()) << second.error().message;
    const ViewId back = *second;
    SchedulerParams invalid = queries;
    invalid.tuning.maxQueriesInFlight = 0;
    EXPECT_FALSE(engine.addView(behind, invalid).ok());
    Camera aside = front;  // the second engine's scene from higher up
    aside.position = {1.0f, 2.0f, 3.0f};
    ASSERT_TRUE(other.engine->setCamera(aside).ok());

    struct Slot {
        Engine* engine;
        ViewId view;
    };
    const Slot slots[3] = {{&engine, kMainView}, {&engine, back}, {other.engine.get(), kMainView}};
    GameFramebuffer fb;
    auto draw = [&](int slot) {
        glBindFramebuffer(GL_FRAMEBUFFER, fb.fbo);
        glViewport(slot * kThird, 0, kThird, kGameH);
        EXPECT_TRUE(slots[slot].engine->renderView(slots[slot].view).ok());
    };
    std::vector<glm::u8vec4> alone[3], all;
    std::vector<float> depth;
    for (int pass = 0; pass < 4; ++pass)  // histories settle; the last pass is the reference
        for (int slot = 0; slot < 3; ++slot) {
            fb.clear();
            draw(slot);
            fb.read(alone[slot], depth);
        }
    fb.clear();
    for (int slot = 0; slot < 3; ++slot) draw(slot);
    fb.read(all, depth);
    for (int slot = 0; slot < 3; ++slot) {
        std::uint64_t differ = 0, drawn = 0;
        for (int y = 0; y < kGameH; ++y)
            for (int x = slot * kThird; x < (slot + 1) * kThird; ++x) {
                const std::size_t i = std::size_t(y) * kGameW + x;
                differ += all[i] != alone[slot][i];
                drawn += all[i] != kGameColour;
            }
        EXPECT_EQ(differ, 0u) << "viewport " << slot;
        EXPECT_GT(drawn, 100u) << "viewport " << slot;
    }
    // Each view of the first engine sees its own side of the wall.
    EXPECT_TRUE(engine.isVisible(scene.front, kMainView));
    EXPECT_FALSE(engine.isVisible(scene.hidden, kMainView));
    EXPECT_TRUE(engine.isVisible(scene.hidden, back));
    EXPECT_FALSE(engine.isVisible(scene.front, back));
    EXPECT_EQ(engine.camera(back).position, behind.position);

    ASSERT_TRUE(engine.removeView(back).ok());
    EXPECT_FALSE(engine.renderView(back).ok());
    EXPECT_FALSE(engine.removeView(back).ok());
    EXPECT_FALSE(engine.removeView(kMainView).ok());
    EXPECT_TRUE(engine.visibleParts(back).empty());
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

// Lifecycle between frames: an object changes model (new handle), a model is removed once
// unused, and the viewport shrinks; every frame of the default mode still draws what vfc
// draws.
TEST(Embedding, ModelsChangeAndTheViewportResizesBetweenFrames) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    GameScene scene(*ctx);
    ASSERT_TRUE(scene.engine);
    Engine& engine = *scene.engine;
    SchedulerParams vfcParams;
    vfcParams.mode = CullMode::Vfc;
    QueryScheduler vfc(vfcParams);
    GameFramebuffer fb;
    // The main view (two-phase) and vfc into the same viewport must give the same picture.
    auto expectLikeVfc = [&](int w, int h, const char* when) {
        Camera cam = engine.camera();
        cam.aspect = float(w) / float(h);
        ASSERT_TRUE(engine.setCamera(cam).ok());
        std::vector<glm::u8vec4> full, reference;
        std::vector<float> depth;
        for (int frame = 0; frame < 3; ++frame) {
            fb.clear();
            glBindFramebuffer(GL_FRAMEBUFFER, fb.fbo);
            glViewport(0, 0, w, h);
            auto st = engine.renderFrame();
            ASSERT_TRUE(st.ok()) << st.error().message;
        }
        fb.read(full, depth);
        fb.clear();
        glBindFramebuffer(GL_FRAMEBUFFER, fb.fbo);
        glViewport(0, 0, w, h);
        ASSERT_TRUE(engine.renderFrame(vfc).ok());
        fb.read(reference, depth);
        EXPECT_EQ(full, reference) << when;
    };
    expectLikeVfc(kGameW, kGameH, "at first");

    const ModelId box = *engine.addModel(test::cubeMesh(0.25f));
    const ModelId ball = engine.objects().modelOf(scene.front.index);
    auto moved = engine.setModel(scene.front, box);
    ASSERT_TRUE(moved.ok()) << moved.error().message;
    EXPECT_FALSE(engine.objects().alive(scene.front));
    const Status inUse = engine.removeModel(ball);
    EXPECT_FALSE(inUse.ok());
    EXPECT_EQ(inUse.code(), ErrorCode::BadArgument);
    auto hiddenMoved = engine.setModel(scene.hidden, box);
    ASSERT_TRUE(hiddenMoved.ok());
    ASSERT_TRUE(engine.removeModel(ball).ok());
    EXPECT_FALSE(engine.addObject(ball, at({0, 0, 0})).ok());
    expectLikeVfc(kGameW, kGameH, "after the model changes");
    EXPECT_TRUE(engine.isVisible(*moved));
    EXPECT_FALSE(engine.isVisible(scene.front));  // stale handle

    expectLikeVfc(kGameW / 2, kGameH / 2, "after the viewport shrank");
    expectLikeVfc(kGameW, kGameH, "after it grew back");
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

// Drawing handed to the GPU in chunks (EngineOptions::submitTriangles) changes when the
// GPU starts, never what it draws: after every draw, never, and by the default, the
// two-phase frames and vfc draw the same images, and a frame counts its submits.
TEST(Embedding, DrawingSubmittedInChunksDrawsTheSameImage) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    GameScene scene(*ctx);
    ASSERT_TRUE(scene.engine);
    Engine& engine = *scene.engine;
    EXPECT_EQ(engine.submitTriangles(), EngineOptions{}.submitTriangles);
    SchedulerParams vfcParams;
    vfcParams.mode = CullMode::Vfc;
    QueryScheduler vfc(vfcParams);
    GameFramebuffer fb;
    std::vector<float> depth;
    auto draw = [&](QueryScheduler* s, std::vector<glm::u8vec4>& rgba) -> std::uint32_t {
        fb.clear();
        glBindFramebuffer(GL_FRAMEBUFFER, fb.fbo);
        glViewport(0, 0, kGameW, kGameH);
        auto st = s ? engine.renderFrame(*s) : engine.renderFrame();
        EXPECT_TRUE(st.ok()) << st.error().message;
        fb.read(rgba, depth);
        return st ? st->drawSubmits : 0u;
    };
    std::vector<glm::u8vec4> reference, image;
    engine.setSubmitTriangles(0);
    EXPECT_EQ(draw(&vfc, reference), 0u);
    for (const std::uint32_t every : {0u, 1u, EngineOptions{}.submitTriangles}) {
        engine.setSubmitTriangles(every);
        for (int frame = 0; frame < 3; ++frame) {
            const std::uint32_t submits = draw(nullptr, image);
            EXPECT_EQ(image, reference) << "every " << every << " triangles, frame " << frame;
            // Each part drawn is at least one draw (two with cluster history's passes).
            if (every == 1) {
                EXPECT_GE(submits, engine.visibleParts().size());
            } else if (every == 0) {
                EXPECT_EQ(submits, 0u);
            }
        }
        EXPECT_EQ(draw(&vfc, image), every == 1 ? engine.visibleParts().size() : 0u) << every;
        EXPECT_EQ(image, reference) << "vfc, every " << every << " triangles";
    }
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

// Objects given by their bounds only: the game draws each whole when dyncull says it is
// visible. One behind the wall costing a million triangles is tested and culled (the
// cost model counts what its draw costs, not its box's 12 triangles); one in front is
// drawn. (The part renderer draws the wall and, for the bounds objects, their boxes.)
TEST(Embedding, BoundsOnlyObjectsAreCulledAndDrawnWhole) {
    auto ctx = test::headless();
    ASSERT_TRUE(ctx);
    auto made = Engine::create(*ctx);
    ASSERT_TRUE(made.ok()) << made.error().message;
    Engine& engine = **made;
    const ModelId quad = *engine.addModel(test::quadMesh(1.0f));
    auto heavyModel = engine.addBoundsModel(Aabb::fromMinMax(glm::vec3(-0.3f), glm::vec3(0.3f)), 1000000);
    ASSERT_TRUE(heavyModel.ok()) << heavyModel.error().message;
    EXPECT_FALSE(engine.addBoundsModel(Aabb{}, 10).ok());
    EXPECT_FALSE(engine.addBoundsModel(Aabb::fromMinMax(glm::vec3(0), glm::vec3(1)), 0).ok());
    ASSERT_TRUE(engine.addObject(quad, at({0, 0, 0})).ok());
    const ObjectHandle behind = *engine.addObject(*heavyModel, at({0, 0, -1.5f}));
    const ObjectHandle inFront = *engine.addObject(*heavyModel, at({0.4f, 0.4f, 1.0f}));
    ASSERT_TRUE(engine.setCamera(test::cameraOnZ(3.0f)).ok());
    for (int frame = 0; frame < 6; ++frame) {
        ctx->clearFramebuffer(Renderer::kClearColour);
        auto st = engine.renderFrame();
        ASSERT_TRUE(st.ok()) << st.error().message;
    }
    EXPECT_TRUE(engine.isVisible(inFront));
    EXPECT_FALSE(engine.isVisible(behind));
    std::uint32_t wholeDraws = 0;
    for (const VisiblePart& p : engine.visibleParts())
        if (engine.objects().modelOf(p.part.object) == *heavyModel) {
            ++wholeDraws;
            EXPECT_EQ(p.object, inFront);
            EXPECT_EQ(p.firstIndex, 0u);
            EXPECT_EQ(p.indexCount, 36u);  // the box's range: a game draws its own object instead
        }
    EXPECT_EQ(wholeDraws, 1u);
}

// A game's own context, wrapped: two engines (split screen) draw into its framebuffer side
// by side, and dropping the wrapper leaves the game's context working.
TEST(Embedding, TwoEnginesOnABorrowedContextDrawSideBySide) {
    auto game = test::headless();  // stands for the game's context, current
    ASSERT_TRUE(game);
    auto wrapped = GlContext::borrowCurrent();
    ASSERT_TRUE(wrapped.ok()) << wrapped.error().message;
    EXPECT_EQ((*wrapped)->kind(), ContextKind::Borrowed);
    EXPECT_TRUE((*wrapped)->isCurrent());
    GameFramebuffer fb;
    std::vector<glm::u8vec4> alone, both;
    std::vector<float> depth;
    {
        GameScene left(**wrapped), right(**wrapped);
        ASSERT_TRUE(left.engine && right.engine);
        ASSERT_TRUE(right.engine->setTransform(right.front, at({-0.3f, -0.3f, 1.0f})).ok());
        glBindFramebuffer(GL_FRAMEBUFFER, fb.fbo);
        glViewport(0, 0, kGameW / 2, kGameH);
        fb.clear();
        ASSERT_TRUE(left.engine->renderFrame().ok());
        fb.read(alone, depth);
        fb.clear();
        for (int frame = 0; frame < 3; ++frame) {
            glBindFramebuffer(GL_FRAMEBUFFER, fb.fbo);
            glViewport(0, 0, kGameW / 2, kGameH);
            ASSERT_TRUE(left.engine->renderFrame().ok());
            glViewport(kGameW / 2, 0, kGameW / 2, kGameH);
            ASSERT_TRUE(right.engine->renderFrame().ok());
        }
        fb.read(both, depth);
    }
    // The left half is exactly what the left engine draws alone; the right half holds the
    // other view (its front sphere elsewhere), drawn over the game's background.
    std::uint64_t leftDiffers = 0, halvesDiffer = 0, rightDrawn = 0;
    for (int y = 0; y < kGameH; ++y)
        for (int x = 0; x < kGameW / 2; ++x) {
            const std::size_t l = std::size_t(y) * kGameW + x, r = l + kGameW / 2;
            leftDiffers += both[l] != alone[l];
            halvesDiffer += both[l] != both[r];
            rightDrawn += both[r] != kGameColour;
        }
    EXPECT_EQ(leftDiffers, 0u);
    EXPECT_GT(halvesDiffer, 50u);
    EXPECT_GT(rightDrawn, 200u);
    wrapped->reset();
    EXPECT_TRUE(game->isCurrent()) << "the game's context must survive its wrapper";
    EXPECT_EQ(game->checkErrors(), 0u);
}

}  // namespace
}  // namespace dyncull
