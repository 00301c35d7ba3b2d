// `dyncull run SCENE`: play a scene's camera path with one culling mode, headless (EGL,
// the default) or in a window, writing per-frame stats (CSV) and screenshots.
#include <algorithm>
#include <cstdio>
#include <map>
#include <filesystem>
#include <fstream>
#include <optional>
#include <memory>
#include <sstream>
#include <string>

#include "cli_util.hpp"
#include "streaming_report.hpp"
#include "commands.hpp"
#include "crash_report.hpp"
#include "dyncull/viewer/window_context.hpp"
#include "dyncull/measure/png_writer.hpp"
#include "dyncull/demos/progress_bar.hpp"
#include "dyncull/objects/checked_write.hpp"
#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/engine/engine.hpp"
#include "dyncull/engine/image.hpp"
#include "interactive.hpp"
#include "report_writer.hpp"
#include "scene_options.hpp"

namespace dyncull::cli {
namespace {

struct RunOptions {
    std::string scene = "bunnies";
    std::string mode = "full";
    std::uint64_t frames = 0;  // 0: the scene's default path length
    std::string size = "1280x720";
    std::string out;  // default out/<scene>
    std::string stats;
    std::string screenshot;
    std::vector<std::uint64_t> shots;
    bool window = false;
    bool boxes = false;
    Shading shading = Shading::Vertex;
    SceneOptions sceneOptions;
    SchedulerFlags flags;
};

void writeCsvHeader(std::ofstream& f) { f << "frame," << frameStatsCsvHeader() << '\n'; }

void writeCsvRow(std::ofstream& f, std::uint64_t frame, const FrameStats& s) {
    f << frame << ',';
    writeFrameStatsCsv(f, s);
    f << '\n';
}

// Node-box view of a headless frame, for screenshots: boxes, stats line and legend.
void drawNodeBoxOverlay(NodeBoxView& view, Engine& engine, const FrameStats& s, const std::string& mode) {
    const std::size_t n = view.drawBoxes(engine, NodeBoxFilter{});
    char line[256];
    std::snprintf(line, sizeof line, "%s  %.2f ms  queries %u  occluded %u  parts %u  tris %s  boxes %zu", mode.c_str(),
                  s.frameMs, s.queriesIssued, s.queriesOccluded, s.partsDrawn,
                  compactCount(static_cast<double>(s.trianglesDrawn)).c_str(), n);
    view.drawText(engine, {line}, true);
}

void runRun(RunOptions o) {
    auto size = parseSize(o.size, "--size");
    if (!size) fail(size.error().message);
    auto mode = parseCullMode(o.mode);
    if (!mode) fail("--mode: " + mode.error().message);
    if (o.flags.volume != SchedulerFlags{}.volume && *mode != CullMode::TwoPhase && *mode != CullMode::Queries)
        fail("--volume: applies to --mode full and queries only");
    if (o.flags.errorBudget > 0.0 && *mode != CullMode::TwoPhase) fail("--error-budget: applies to --mode full only");
    setCrashPhase("scene set-up");
    auto made = makeScene(o.scene, o.sceneOptions);
    if (!made) fail(made.error().message);
    DemoScene& scene = **made;
    if (o.out.empty()) o.out = "out/" + scene.name();
    if (o.stats.empty()) o.stats = o.out + "/frames_" + o.mode + ".csv";
    const bool defaultScreenshot = o.screenshot.empty();
    if (defaultScreenshot) o.screenshot = o.out + "/last_" + o.mode + ".png";

    ContextOptions co;
    co.kind = o.window ? ContextKind::GlfwWindow : ContextKind::HeadlessEgl;
    co.width = size->x;
    co.height = size->y;
    co.title = "dyncull run " + o.scene;
    auto context = createContext(co);
    if (!context) fail(context.error().message);
    GlContext& ctx = **context;
    auto* window = dynamic_cast<WindowContext*>(&ctx);  // null when headless

    EngineOptions eo;
    eo.finishEachFrame = true;  // frame times include the GPU's work
    eo.scheduler = toParams(o.flags, *mode);
    eo.queries.visiblePixelThreshold = o.flags.pixelThreshold;
    auto engineOr = Engine::create(ctx, eo);
    if (!engineOr) fail(engineOr.error().message);
    Engine& engine = **engineOr;
    engine.renderer().setShading(o.shading);
    if (Status s = scene.populate(engine); !s) fail(s.message());
    std::printf("%s\n", scene.description().c_str());
    std::printf("context: %s, %s; set-up %.0f ms\n", ctx.platformName().c_str(), ctx.rendererName().c_str(), scene.setupMs());

    if (o.window) {  // interactive viewer: free flight, live mode switches, node boxes
        InteractiveOptions io;
        io.params = eo.scheduler;
        io.maxFrames = o.frames;
        io.boxes = o.boxes;
        ContextInput input(*window);
        InteractiveState last;
        auto n = runInteractive(ctx, engine, scene, input, io, &last);
        if (!n) fail(n.error().message);
        std::printf("summary scene=%s mode=%s frames=%llu\n", scene.name().c_str(), toString(last.mode),
                    static_cast<unsigned long long>(*n));
        return;
    }
    std::unique_ptr<NodeBoxView> boxView;
    if (o.boxes) boxView = std::make_unique<NodeBoxView>();

    const std::uint64_t frames = o.frames ? o.frames : scene.defaultFrames();
    if (Status s = ensureParentDirectory(o.stats); !s) fail(s.message());
    std::ofstream csv;
    if (Status s = openChecked(csv, o.stats); !s) fail(s.message());
    writeCsvHeader(csv);
    // An earlier run's picture at the default path would pass for this run's if it ends
    // early; only that file is removed (a path the user named is never deleted).
    std::error_code ec;
    if (defaultScreenshot && std::filesystem::is_regular_file(o.screenshot, ec)) std::filesystem::remove(o.screenshot, ec);

    double ms = 0, queries = 0, parts = 0, triangles = 0;
    StreamingSummary streaming;
    std::vector<std::string> written;
    const float aspect = static_cast<float>(size->x) / static_cast<float>(size->y);
    auto writeShot = [&](const std::string& path) {
        if (Status s = ensureParentDirectory(path); !s) fail(s.message());
        if (Status s = writePng(engine.renderer().readPixels(), path); !s) fail(s.message());
        written.push_back(path);
    };
    std::optional<ProgressBar> progress;
    if (!o.window) progress.emplace("run " + scene.name() + " " + o.mode, static_cast<double>(frames));
    setInterruptPolled(true);
    std::uint64_t frame = 0;
    for (; frame < frames && !(window && window->shouldClose()) && !interruptRequested(); ++frame) {
        setCrashFrame(frame, o.mode.c_str());
        if (Status s = scene.update(engine, frame); !s) fail(s.message());
        if (Status s = engine.setCamera(scene.camera(frame, aspect)); !s)
            fail(o.scene + ": frame " + std::to_string(frame) + ": the scene's camera path gives an unusable camera (" +
                 s.message() + ")" + (o.sceneOptions.bunny.orbit > 0.0f ? "; check --orbit" : ""));
        if (boxView) boxView->trace(engine.scheduler(), true);
        scene.beginFrame(engine.camera());
        ctx.clearFramebuffer(Renderer::kClearColour);
        auto rendered = engine.renderFrame();
        if (!rendered) fail("frame " + std::to_string(frame) + ": " + rendered.error().message);
        const FrameStats& st = *rendered;
        auto streamed = scene.endFrame();
        if (!streamed) fail("frame " + std::to_string(frame) + ": " + streamed.error().message);
        if (*streamed) streaming.add(frame, **streamed, st.frameMs);
        if (boxView) drawNodeBoxOverlay(*boxView, engine, st, o.mode);
        writeCsvRow(csv, frame, st);
        // Every row reaches the file as its frame ends, so an interrupted run keeps them.
        if (Status s = flushChecked(csv, o.stats); !s) fail(s.message());
        ms += st.frameMs;
        queries += st.queriesIssued;
        parts += st.partsDrawn;
        triangles += static_cast<double>(st.trianglesDrawn);
        const bool last = frame + 1 == frames;
        if (last) writeShot(o.screenshot);
        else if (std::find(o.shots.begin(), o.shots.end(), frame) != o.shots.end())
            writeShot(o.out + "/frame" + std::to_string(frame) + "_" + o.mode + ".png");
        if (o.window) ctx.present();
        if (progress) {
            char note[48];
            std::snprintf(note, sizeof note, "%.0f ms/frame", ms / static_cast<double>(frame + 1));
            progress->advance(1.0, note);
        }
    }
    setInterruptPolled(false);
    setCrashPhase("writing outputs");
    const bool interrupted = frame < frames && interruptRequested();
    // An interrupted run still leaves its last completed frame's picture.
    if (interrupted && frame > 0) writeShot(o.screenshot);
    if (progress && interrupted) progress->cancel();
    progress.reset();
    if (Status s = closeChecked(csv, o.stats); !s) fail(s.message());
    const double n = static_cast<double>(std::max<std::uint64_t>(frame, 1));
    if (ctx.checkErrors() != 0)
        std::fprintf(stderr, "warning: %llu GL errors\n", static_cast<unsigned long long>(ctx.glErrorCount()));
    if (interrupted)
        std::printf("interrupted after %llu of %llu frames; the files below hold those frames\n",
                    static_cast<unsigned long long>(frame), static_cast<unsigned long long>(frames));
    std::printf("stats: %s\n", o.stats.c_str());
    for (const std::string& p : written) std::printf("picture: %s\n", p.c_str());
    std::printf("summary scene=%s mode=%s volume=%s frames=%llu ms_per_frame=%.2f queries_per_frame=%.1f "
                "parts_per_frame=%.1f triangles_per_frame=%.0f\n",
                scene.name().c_str(), o.mode.c_str(), o.flags.volume.c_str(), static_cast<unsigned long long>(frame),
                ms / n, queries / n, parts / n, triangles / n);
    if (streaming.frames > 0) {
        const std::string path = o.out + "/streaming.csv";
        if (Status s = streaming.writeCsv(path); !s) fail(s.message());
        std::printf("streaming stats: %s\n%s\n", path.c_str(), streaming.line(o.sceneOptions.stream).c_str());
    }
    if (interrupted) throw CLI::RuntimeError(128 + interruptSignal());
}

}  // namespace

void registerRun(CLI::App& app) {
    auto o = std::make_shared<RunOptions>();
    CLI::App* cmd = app.add_subcommand("run", "Play a scene's camera path with one culling mode (headless by default)");
    cmd->add_option("scene", o->scene, "bunnies, powerplant, city, a directory of .ply/.obj parts, a .ply/.obj/.gltf/.glb file, or a .dsub file from dyncull subdivide")->capture_default_str();
    cmd->add_option("--mode", o->mode, "vfc, simple, queries (hardware queries) or full (two-phase, the default)")->capture_default_str();
    cmd->add_option("--frames", o->frames, "frames to run (default: the scene's camera path once)")
        ->check(wholeIn(1, kMaxFrames));
    cmd->add_option("--size", o->size, "framebuffer size WxH")->capture_default_str();
    cmd->add_option("--out", o->out, "output directory (default out/<scene>)");
    cmd->add_option("--stats", o->stats, "per-frame CSV (default <out>/frames_<mode>.csv)");
    cmd->add_option("--screenshot", o->screenshot, "PNG of the last frame (default <out>/last_<mode>.png)");
    cmd->add_option("--shots", o->shots, "also write PNGs of these frames")
        ->check(wholeIn(0, kMaxFrames))
        ->delimiter(',');
    cmd->add_flag("--window", o->window, "interactive GLFW window (fly, 1/2/3/4 modes, B node boxes; --frames limits it)");
    cmd->add_option("--shading", o->shading, "lighting per vertex (fast) or per pixel")
        ->transform(CLI::CheckedTransformer(std::map<std::string, Shading>{{"vertex", Shading::Vertex}, {"pixel", Shading::Pixel}}))
        ->default_str("vertex");
    cmd->add_flag("--boxes", o->boxes, "draw the node-box view (scheduler decisions) and stats over each frame");
    addBunnyOptions(*cmd, o->sceneOptions.bunny);
    addGeneratedSceneOptions(*cmd, o->sceneOptions);
    addSchedulerOptions(*cmd, o->flags);
    cmd->callback([o] { runRun(*o); });
}

}  // namespace dyncull::cli
