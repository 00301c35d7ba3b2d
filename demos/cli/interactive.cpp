// Interactive viewer: input -> viewer state -> one culled frame -> node boxes and text.
#include "interactive.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace dyncull::cli {

InputFrame ScriptedInput::poll() {
    InputFrame f;
    for (const Hold& h : holds_)
        if (frame_ >= h.first && frame_ <= h.last) f.keysDown.set(static_cast<std::size_t>(h.key));
    for (const Press& p : presses_)
        if (p.frame == frame_) f.press(p.key);
    for (const Mouse& m : mouse_)
        if (m.frame == frame_) {
            f.mouseDelta += m.delta;
            f.buttonsDown[static_cast<std::size_t>(MouseButton::Right)] = m.right;
        }
    ++frame_;
    return f;
}

InteractiveViewer::InteractiveViewer(Engine& engine, DemoScene& scene, const InteractiveOptions& options)
    : engine_(engine), scene_(scene), options_(options) {
    state_.mode = options.params.mode;
    state_.boxes = options.boxes;
    state_.useHistory = options.params.features.useHistory;
    state_.useOccupancy = options.params.features.useOccupancyAccept;
    state_.useTight = options.params.features.useTightVolumes;
    for (CullMode m : {CullMode::Vfc, CullMode::Simple, CullMode::Queries, CullMode::TwoPhase})
        schedulers_[static_cast<int>(m)] = std::make_unique<QueryScheduler>(paramsFor(m));
}

SchedulerParams InteractiveViewer::paramsFor(CullMode mode) const {
    SchedulerParams p = options_.params;
    p.mode = mode;
    p.features.useHistory = state_.useHistory;
    p.features.useOccupancyAccept = state_.useOccupancy;
    p.features.useTightVolumes = state_.useTight;
    return p;
}

void InteractiveViewer::applyKeys(const InputFrame& in) {
    if (in.closeRequested || in.wasPressed(Key::Escape)) state_.quit = true;
    const bool ablation = in.wasPressed(Key::H) || in.wasPressed(Key::O) || in.wasPressed(Key::T);
    if (in.wasPressed(Key::Num1)) state_.mode = CullMode::Vfc;
    if (in.wasPressed(Key::Num2)) state_.mode = CullMode::Simple;
    if (in.wasPressed(Key::Num3)) state_.mode = CullMode::TwoPhase;
    if (in.wasPressed(Key::Num4)) state_.mode = CullMode::Queries;
    if (in.wasPressed(Key::B)) state_.boxes = !state_.boxes;
    if (in.wasPressed(Key::F)) state_.filter.frustumCulled = !state_.filter.frustumCulled;
    if (in.wasPressed(Key::I)) state_.filter.innerVisible = !state_.filter.innerVisible;
    if (in.wasPressed(Key::L)) state_.filter.parts = !state_.filter.parts;
    if (in.wasPressed(Key::H)) state_.useHistory = !state_.useHistory;
    if (in.wasPressed(Key::O)) state_.useOccupancy = !state_.useOccupancy;
    if (in.wasPressed(Key::T)) state_.useTight = !state_.useTight;
    if (in.wasPressed(Key::M)) {
        state_.mouseLook = !state_.mouseLook;  // runInteractive tells the input source
    }
    if (in.wasPressed(Key::Equal) || in.wasPressed(Key::KeypadAdd)) state_.speedScale *= 1.5f;
    if (in.wasPressed(Key::Minus) || in.wasPressed(Key::KeypadSubtract)) state_.speedScale /= 1.5f;
    if (in.wasPressed(Key::P)) {
        state_.followPath = !state_.followPath;
        if (!state_.followPath) {  // take off from where the path camera is, looking the same way
            const glm::vec3 f = state_.camera.forward();
            yaw_ = std::atan2(f.x, -f.z);
            pitch_ = std::asin(std::clamp(f.y, -1.0f, 1.0f));
        }
    }
    if (ablation)
        for (auto& s : schedulers_) s->setParams(paramsFor(s->params().mode));
}

void InteractiveViewer::fly(const InputFrame& in, double dt) {
    if (in.down(MouseButton::Right) || state_.mouseLook) {
        const float radiansPerPixel = 0.003f;
        yaw_ += in.mouseDelta.x * radiansPerPixel;
        pitch_ = std::clamp(pitch_ - in.mouseDelta.y * radiansPerPixel, -1.55f, 1.55f);  // never straight up: up vector
    }
    const glm::vec3 forward(std::cos(pitch_) * std::sin(yaw_), std::sin(pitch_), -std::cos(pitch_) * std::cos(yaw_));
    const glm::vec3 up(0.0f, 1.0f, 0.0f);
    const glm::vec3 right = glm::normalize(glm::cross(forward, up));
    glm::vec3 move(0.0f);
    if (in.down(Key::W) || in.down(Key::Up)) move += forward;
    if (in.down(Key::S) || in.down(Key::Down)) move -= forward;
    if (in.down(Key::D) || in.down(Key::Right)) move += right;
    if (in.down(Key::A) || in.down(Key::Left)) move -= right;
    if (in.down(Key::E) || in.down(Key::Space)) move += up;
    if (in.down(Key::Q) || in.down(Key::C)) move -= up;
    float speed = baseSpeed_ * state_.speedScale;
    if (in.down(Key::LeftShift) || in.down(Key::RightShift)) speed *= 4.0f;
    if (in.down(Key::LeftControl) || in.down(Key::RightControl)) speed *= 0.25f;
    if (glm::dot(move, move) > 0.0f) state_.camera.position += glm::normalize(move) * speed * static_cast<float>(dt);
    state_.camera.target = state_.camera.position + forward;
    state_.camera.up = up;
}

std::vector<std::string> InteractiveViewer::statsLines() const {
    const FrameStats& s = state_.last;
    char a[256], b[256];
    std::snprintf(a, sizeof a, "%s  fps %.1f  %.2f ms  queries %u  occluded %u  parts %u  tris %s", toString(state_.mode),
                  state_.fps, s.frameMs, s.queriesIssued, s.queriesOccluded, s.partsDrawn,
                  compactCount(static_cast<double>(s.trianglesDrawn)).c_str());
    const auto onOff = [](bool v) { return v ? "on" : "off"; };
    std::snprintf(b, sizeof b, "history %s  occupancy %s  tight %s  boxes %s (%zu)  camera %s", onOff(state_.useHistory),
                  onOff(state_.useOccupancy), onOff(state_.useTight), onOff(state_.boxes), state_.boxesDrawn,
                  state_.followPath ? "path" : "free");
    return {a, b};
}

Status InteractiveViewer::step(const InputFrame& input, double dtSeconds) {
    applyKeys(input);
    if (state_.quit) return {};
    if (Status s = scene_.update(engine_, state_.sceneFrame); !s) return s;
    if (state_.framesRendered == 0) {
        // Flight speed from the scene's size: crossing it takes about ten seconds.
        engine_.updateSceneTree();
        const TwoLevelTree tree(engine_.sceneTree(), engine_.objects());
        const Aabb bounds = tree.worldBox(tree.root());
        const float diag = bounds.empty() ? 0.0f : glm::length(bounds.extent());
        baseSpeed_ = diag > 0.0f && std::isfinite(diag) ? 0.1f * diag : 1.0f;
    }
    const glm::ivec2 size = engine_.context().size();
    const float aspect = static_cast<float>(std::max(size.x, 1)) / static_cast<float>(std::max(size.y, 1));
    if (state_.followPath) {
        const std::uint64_t pathLength = std::max<std::uint64_t>(scene_.defaultFrames(), 1);
        state_.camera = scene_.camera(state_.pathFrame % pathLength, aspect);
        ++state_.pathFrame;
    } else {
        state_.camera.aspect = aspect;
        fly(input, dtSeconds);
    }
    if (Status s = engine_.setCamera(state_.camera); !s) return s;

    QueryScheduler& scheduler = *schedulers_[static_cast<int>(state_.mode)];
    view_.trace(scheduler, state_.boxes);
    engine_.context().clearFramebuffer(Renderer::kClearColour);
    auto rendered = engine_.renderFrame(scheduler);
    if (!rendered) return Error{rendered.error().message};
    state_.last = *rendered;
    view_.trace(scheduler, false);
    state_.boxesDrawn = state_.boxes ? view_.drawBoxes(engine_, state_.filter) : 0;
    if (options_.text) {
        view_.drawText(engine_, statsLines(), state_.boxes,
                       "1/2/3/4 vfc/simple/full/queries  P path/fly  B boxes  F/I/L box filters  H/O/T ablation\n"
                       "WASD+QE fly  RMB or M look  Shift/Ctrl/+/- speed  Esc quit");
    }
    if (dtSeconds > 0.0) {
        const double instant = 1.0 / dtSeconds;
        state_.fps = state_.fps > 0.0 ? 0.9 * state_.fps + 0.1 * instant : instant;  // smooth the display
    }
    ++state_.framesRendered;
    ++state_.sceneFrame;
    return {};
}

Expected<std::uint64_t> runInteractive(GlContext& context, Engine& engine, DemoScene& scene, InputSource& input,
                                       const InteractiveOptions& options, InteractiveState* finalState) {
    InteractiveViewer viewer(engine, scene, options);
    using Clock = std::chrono::steady_clock;
    auto last = Clock::now();
    double dt = 0.0;
    while (options.maxFrames == 0 || viewer.state().framesRendered < options.maxFrames) {
        const InputFrame in = input.poll();
        const bool mouseLook = viewer.state().mouseLook;
        if (Status s = viewer.step(in, dt); !s) return s.error();
        if (viewer.state().mouseLook != mouseLook) input.setCursorCaptured(viewer.state().mouseLook);
        if (viewer.state().quit) break;
        context.present();
        const auto now = Clock::now();
        dt = std::chrono::duration<double>(now - last).count();
        last = now;
    }
    input.setCursorCaptured(false);
    if (finalState) *finalState = viewer.state();
    return viewer.state().framesRendered;
}

}  // namespace dyncull::cli
