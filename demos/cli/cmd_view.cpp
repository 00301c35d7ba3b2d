// `dyncull view FILE`: load a scene, frame it, render one lit frame (headless by default)
// and write a PNG, reporting what was loaded and how long each step took.
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "cli_util.hpp"
#include "commands.hpp"
#include "scene_options.hpp"
#include "dyncull/viewer/window_context.hpp"
#include "dyncull/measure/png_writer.hpp"
#include "dyncull/engine/gl_context.hpp"
#include "dyncull/engine/image.hpp"
#include "dyncull/engine/renderer.hpp"
#include "dyncull/objects/camera.hpp"
#include "dyncull/loaders/loaders.hpp"

namespace dyncull::cli {

namespace {

struct ViewOptions {
    std::string file;
    std::string size = "1280x720";
    std::string screenshot = "out/view.png";
    bool window = false;
    bool debug = false;
    int frames = 0;
};

void drawScene(Renderer& renderer, const Scene& scene, const std::vector<MeshId>& ids, const Camera& camera) {
    renderer.context().clearFramebuffer(Renderer::kClearColour);
    renderer.beginFrame(camera);
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        renderer.drawMesh(ids[inst.mesh], inst.transform, colourForId(static_cast<std::uint32_t>(i)));
    }
    renderer.endFrame();
}

// True if every pixel has the renderer's clear colour.
bool isBlank(const Image& image) {
    const glm::u8vec4 clear(glm::round(Renderer::kClearColour * 255.0f), 255);
    for (std::size_t i = 0; i + 3 < image.rgba.size(); i += 4) {
        // One unit of tolerance per channel: the clear colour's float-to-8-bit rounding.
        for (int c = 0; c < 3; ++c)
            if (std::abs(int(image.rgba[i + c]) - int(clear[c])) > 1) return false;
    }
    return true;
}

void runView(const ViewOptions& o) {
    auto size = parseSize(o.size, "--size");
    if (!size) fail(size.error().message);

    Stopwatch sw;
    auto loaded = loadScene(o.file);
    if (!loaded) fail(loaded.error().message);
    const Scene scene = loaded.take();
    const double loadMs = sw.lap();
    std::printf("loaded %s: %zu instances, %zu meshes, %zu unique triangles, %zu instanced triangles\n",
                o.file.c_str(), scene.instances.size(), scene.meshes.size(), scene.uniqueTriangleCount(),
                scene.instancedTriangleCount());
    if (scene.origin != glm::dvec3(0.0))
        std::printf("instances are relative to the scene origin (%.17g, %.17g, %.17g)\n", scene.origin.x, scene.origin.y,
                    scene.origin.z);

    ContextOptions co;
    co.kind = o.window ? ContextKind::GlfwWindow : ContextKind::HeadlessEgl;
    co.width = size->x;
    co.height = size->y;
    co.debug = o.debug;
    co.title = "dyncull view " + o.file;
    auto context = createContext(co);
    if (!context) fail(context.error().message);
    GlContext& ctx = **context;
    auto* window = dynamic_cast<WindowContext*>(&ctx);  // null when headless
    auto made = Renderer::create(ctx);
    if (!made) fail(made.error().message);
    Renderer& renderer = **made;
    const double contextMs = sw.lap();
    std::printf("context: %s, %s, GL %s\n", ctx.platformName().c_str(), ctx.rendererName().c_str(),
                ctx.versionString().c_str());

    std::vector<MeshId> ids;
    ids.reserve(scene.meshes.size());
    for (const Mesh& m : scene.meshes) {
        auto id = renderer.upload(m);
        if (!id) fail(o.file + ": " + id.error().message);
        ids.push_back(*id);
    }
    renderer.finish();
    const double uploadMs = sw.lap();

    const Aabb bounds = scene.worldBounds();
    if (Status s = checkFramable(bounds); !s) fail(o.file + ": cannot make a picture: " + s.message());
    Camera camera = Camera::framing(bounds, static_cast<float>(ctx.size().x) / static_cast<float>(ctx.size().y));
    drawScene(renderer, scene, ids, camera);
    renderer.finish();
    const double renderMs = sw.lap();

    const Image image = renderer.readPixels();
    const double readbackMs = sw.lap();
    // A model with triangles that covers no pixel is a failure, not a picture.
    if (scene.instancedTriangleCount() > 0 && isBlank(image))
        fail(o.file + ": the picture is blank: " + std::to_string(scene.instancedTriangleCount()) +
             " triangles drew no pixel (degenerate, or too thin to cover a pixel centre); nothing written");

    const Status dir = ensureParentDirectory(o.screenshot);
    if (!dir) fail(dir.message());
    const Status png = writePng(image, o.screenshot);
    if (!png) fail(png.message());
    const double pngMs = sw.lap();

    std::printf("rendered %llu draws, %llu triangles at %dx%d; wrote %s\n",
                static_cast<unsigned long long>(renderer.stats().drawCalls),
                static_cast<unsigned long long>(renderer.stats().triangles), image.width, image.height,
                o.screenshot.c_str());
    std::printf("timings (ms): load %.1f, context %.1f, upload %.1f, render %.1f, readback %.1f, png %.1f\n", loadMs,
                contextMs, uploadMs, renderMs, readbackMs, pngMs);

    if (o.window) {
        // Keep showing the framed scene until the window is closed (or --frames is reached).
        for (int frame = 0; !window->shouldClose() && (o.frames <= 0 || frame < o.frames); ++frame) {
            ctx.present();
            camera.aspect = static_cast<float>(ctx.size().x) / static_cast<float>(ctx.size().y);
            drawScene(renderer, scene, ids, camera);
        }
    }
    if (ctx.checkErrors() != 0)
        std::fprintf(stderr, "warning: %llu GL errors\n", static_cast<unsigned long long>(ctx.glErrorCount()));
}

}  // namespace

void registerView(CLI::App& app) {
    auto opts = std::make_shared<ViewOptions>();
    CLI::App* cmd = app.add_subcommand("view", "Render one framed, lit picture of a scene file (.ply .obj .gltf .glb)");
    cmd->add_option("file", opts->file, "Scene file")->required();
    cmd->add_option("--size", opts->size, "Image size WxH in pixels")->capture_default_str();
    cmd->add_option("--screenshot", opts->screenshot, "PNG to write (directories are created)")->capture_default_str();
    cmd->add_flag("--window", opts->window, "Show a GLFW window instead of rendering headless");
    cmd->add_option("--frames", opts->frames, "With --window: stop after N frames (0 = until closed)")
        ->check(wholeIn(0, kMaxFrames));
    cmd->add_flag("--debug", opts->debug, "Debug GL context: report GL errors via KHR_debug");
    cmd->callback([opts] { runView(*opts); });
}

}  // namespace dyncull::cli
