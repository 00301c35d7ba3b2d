// The interactive viewer driven by scripted input, headless: mode switches, box toggle,
// path/free-flight toggle, quitting; the scene keeps animating every frame.
#include <gtest/gtest.h>

#include "gl_test_util.hpp"
#include "interactive.hpp"
#include "procedural_meshes.hpp"

namespace dyncull::cli {
namespace {

// Eight cubes on a line, the first moving each frame; camera path along +Z looking at them.
class TinyScene final : public DemoScene {
public:
    std::string name() const override { return "tiny"; }
    std::string description() const override { return "8 cubes"; }
    Status populate(Engine& e) override {
        auto model = e.addModel(test::cubeMesh(0.4f));
        if (!model) return model.error();
        for (int i = 0; i < 8; ++i) {
            Transform t;
            t.translation = {0.0f, 0.0f, -1.5f * static_cast<float>(i)};
            auto h = e.addObject(*model, t);
            if (!h) return h.error();
            handles_.push_back(*h);
        }
        return {};
    }
    Status update(Engine& e, std::uint64_t frame) override {
        lastFrame = frame;
        Transform t;
        t.translation = {0.1f * static_cast<float>(frame % 10), 0.0f, 0.0f};
        return e.setTransform(handles_[0], t);
    }
    Camera camera(std::uint64_t frame, float aspect) const override {
        Camera c;
        c.position = {0.0f, 0.2f, 4.0f + 0.01f * static_cast<float>(frame)};
        c.target = {0.0f, 0.0f, -5.0f};
        c.aspect = aspect;
        c.nearPlane = 0.1f;
        c.farPlane = 100.0f;
        return c;
    }
    std::uint64_t defaultFrames() const override { return 20; }
    std::uint64_t lastFrame = 0;

private:
    std::vector<ObjectHandle> handles_;
};

TEST(InteractiveViewer, ScriptedKeysSwitchModesBoxesAndCamera) {
    auto ctx = test::headless(160, 120);
    ASSERT_TRUE(ctx);
    {
        auto engine = Engine::create(*ctx);
        ASSERT_TRUE(engine.ok()) << engine.error().message;
        TinyScene scene;
        ASSERT_TRUE(scene.populate(**engine).ok());

        ScriptedInput input;
        input.pressAt(1, Key::Num2);  // simple
        input.pressAt(2, Key::Num4);  // queries
        input.pressAt(3, Key::Num3);  // full
        input.pressAt(4, Key::B);     // boxes on
        input.pressAt(5, Key::H);     // history off
        input.pressAt(6, Key::P);     // free flight
        input.holdDuring(7, 9, Key::W);
        InteractiveOptions o;
        o.params.mode = CullMode::Vfc;
        o.maxFrames = 12;
        InteractiveState st;
        auto n = runInteractive(*ctx, **engine, scene, input, o, &st);
        ASSERT_TRUE(n.ok()) << n.error().message;
        EXPECT_EQ(*n, 12u);
        EXPECT_EQ(st.framesRendered, 12u);
        EXPECT_EQ(st.mode, CullMode::TwoPhase);
        EXPECT_TRUE(st.boxes);
        EXPECT_GT(st.boxesDrawn, 0u);
        EXPECT_FALSE(st.useHistory);
        EXPECT_FALSE(st.followPath);
        EXPECT_EQ(st.pathFrame, 6u);  // frames 0..5 followed the path; P acts before frame 6
        EXPECT_EQ(scene.lastFrame, 11u);       // the scene animated every frame
        EXPECT_GT(st.last.partsDrawn, 0u);
        // W held for 3 frames moved the free camera forward (towards -Z) from where the path left it.
        EXPECT_LT(st.camera.position.z, scene.camera(5, 1.0f).position.z);
    }
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

TEST(InteractiveViewer, ViewerStepsOneFrameAtATimeAndEscapeQuits) {
    auto ctx = test::headless(160, 120);
    ASSERT_TRUE(ctx);
    {
        auto engine = Engine::create(*ctx);
        ASSERT_TRUE(engine.ok()) << engine.error().message;
        TinyScene scene;
        ASSERT_TRUE(scene.populate(**engine).ok());
        InteractiveViewer viewer(**engine, scene, InteractiveOptions{});
        EXPECT_EQ(viewer.state().mode, CullMode::TwoPhase);  // full, the default
        ASSERT_TRUE(viewer.step(InputFrame{}, 0.016).ok());
        EXPECT_EQ(viewer.state().framesRendered, 1u);
        InputFrame four;
        four.press(Key::Num4);
        ASSERT_TRUE(viewer.step(four, 0.016).ok());
        EXPECT_EQ(viewer.state().mode, CullMode::Queries);
        EXPECT_GT(viewer.baseSpeed(), 0.0f);
        InputFrame one;
        one.press(Key::Num1);
        ASSERT_TRUE(viewer.step(one, 0.016).ok());
        EXPECT_EQ(viewer.state().mode, CullMode::Vfc);
        EXPECT_EQ(viewer.state().last.queriesIssued, 0u);  // vfc issues no queries
        EXPECT_EQ(viewer.state().framesRendered, 3u);
        InputFrame esc;
        esc.press(Key::Escape);
        ASSERT_TRUE(viewer.step(esc, 0.016).ok());
        EXPECT_TRUE(viewer.state().quit);
        EXPECT_EQ(viewer.state().framesRendered, 3u);  // quitting renders nothing more
    }
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

}  // namespace
}  // namespace dyncull::cli
