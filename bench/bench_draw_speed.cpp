// Draw speed against a speed-of-light reference, interleaved per frame on the bunny swarm.
//
// `sol` draws the same triangles (each bunny's split mesh) as fast as this context allows:
// a position-only shader writing a constant colour, back faces culled, one draw per
// bunny, no traversal. Every other variant is dyncull's own frame (Engine::renderFrame in
// vfc mode) with one setting changed, so the table splits the renderer's cost into its
// parts: shading per vertex or per pixel, culled back faces, triangle order in the parts.
// `*-discard` variants run the same frame with GL_RASTERIZER_DISCARD: vertex work and
// per-draw overhead only, so total minus discard is the rasterisation and fragment cost.
// `parts*` and `test-*` draw or test every part in view through the part renderer, to
// weigh the two-phase mode's draw marks and triangle tests against drawing. `full` is the
// default conservative mode's whole frame (culling, tests and draws, its history carried
// from frame to frame), for issue 21's ratio of `full` to `sol` measured in one run.
//
// Usage: bench_draw_speed [--frames N] [--count 300] [--box 8] [--bunny-size 1]
//        [--orbit 12] [--speed 0.02] [--size 640x360] [--out DIR] [--mesh FILE]
// Prints a table (median ms, triangles, ns per triangle, ratio to sol) and writes
// DIR/draw_speed.csv plus the first frame of each variant as DIR/<variant>.png.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>

#include "dyncull/measure/png_writer.hpp"
#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/engine/engine.hpp"
#include "dyncull/engine/gl_context.hpp"
#include "dyncull/engine/heap_tuning.hpp"
#include "dyncull/engine/image.hpp"
#include "dyncull/measure/image_compare.hpp"
#include "dyncull/objects/checked_write.hpp"
#include "swarm_bench.hpp"
#include "shader_program.hpp"  // engine-internal: the engine's own compile-and-link

namespace dyncull {
namespace {

using Clock = std::chrono::steady_clock;

const char* const kSolVertex = R"(#version 450 core
layout(location = 0) in vec3 aPosition;
uniform mat4 uViewProj;
uniform mat4 uModel;
void main() { gl_Position = uViewProj * (uModel * vec4(aPosition, 1.0)); }
)";
const char* const kSolFragment = R"(#version 450 core
out vec4 fragColour;
void main() { fragColour = vec4(0.8, 0.7, 0.6, 1.0); }
)";

// The reference: the model's split mesh (positions only) drawn whole per object.
class SpeedOfLight {
public:
    explicit SpeedOfLight(const Engine& engine) {
        std::string log;
        program_ = detail::buildProgram(kSolVertex, kSolFragment, log);
        if (!program_) {
            std::fprintf(stderr, "bench_draw_speed: shader: %s\n", log.c_str());
            std::exit(1);
        }
        locViewProj_ = glGetUniformLocation(program_, "uViewProj");
        locModel_ = glGetUniformLocation(program_, "uModel");
        const SceneObjects& objs = engine.objects();
        for (ModelId m = 0; m < objs.modelCount(); ++m) {
            const Mesh& mesh = objs.model(m).mesh;
            Gpu g;
            g.count = static_cast<GLsizei>(mesh.indices.size());
            g.box = objs.model(m).root().box;
            glCreateBuffers(1, &g.vbo);
            glNamedBufferStorage(g.vbo, static_cast<GLsizeiptr>(mesh.positions.size() * sizeof(glm::vec3)),
                                 mesh.positions.data(), 0);
            glCreateBuffers(1, &g.ibo);
            glNamedBufferStorage(g.ibo, static_cast<GLsizeiptr>(mesh.indices.size() * 4), mesh.indices.data(), 0);
            glCreateVertexArrays(1, &g.vao);
            glVertexArrayVertexBuffer(g.vao, 0, g.vbo, 0, sizeof(glm::vec3));
            glVertexArrayElementBuffer(g.vao, g.ibo);
            glEnableVertexArrayAttrib(g.vao, 0);
            glVertexArrayAttribFormat(g.vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
            glVertexArrayAttribBinding(g.vao, 0, 0);
            models_.push_back(g);
        }
    }
    ~SpeedOfLight() {
        for (Gpu& g : models_) {
            glDeleteVertexArrays(1, &g.vao);
            glDeleteBuffers(1, &g.vbo);
            glDeleteBuffers(1, &g.ibo);
        }
        glDeleteProgram(program_);
    }

    /// Draws every object whose box meets the frustum, nearest first when `sorted` (as
    /// vfc's front-to-back traversal: hidden fragments then fail the early depth test);
    /// returns triangles drawn. `culled` GL_FRONT_AND_BACK culls every triangle: what a
    /// triangle that is never rasterised still costs (a back face's price).
    std::uint64_t draw(Engine& engine, bool cullBackFaces, bool sorted = true, GLenum culled = GL_BACK) {
        Renderer& r = engine.renderer();
        engine.context().clearFramebuffer(Renderer::kClearColour);
        r.beginFrame(engine.camera());  // the depth convention of a frame
        glUseProgram(program_);
        glUniformMatrix4fv(locViewProj_, 1, GL_FALSE, glm::value_ptr(engine.camera().viewProjectionRelative()));
        if (cullBackFaces) glEnable(GL_CULL_FACE);
        glCullFace(culled);
        const Frustum frustum = Frustum::fromCamera(engine.camera());
        const SceneObjects& objs = engine.objects();
        order_.clear();
        for (std::uint32_t o = 0; o < objs.slotCount(); ++o) {
            if (!objs.alive(o)) continue;
            const Aabb box = transformAabb(objs.matrix(o), models_[objs.modelOf(o)].box);
            if (frustum.outside(box)) continue;
            order_.push_back({sorted ? glm::length(box.center() - engine.camera().position) : 0.0f, o});
        }
        std::stable_sort(order_.begin(), order_.end());
        std::uint64_t triangles = 0;
        for (const auto& [distance, o] : order_) {
            const Gpu& g = models_[objs.modelOf(o)];
            const glm::mat4& m = objs.matrix(o);
            glUniformMatrix4fv(locModel_, 1, GL_FALSE, glm::value_ptr(engine.camera().relativeModel(m)));
            glBindVertexArray(g.vao);
            glDrawElements(GL_TRIANGLES, g.count, GL_UNSIGNED_INT, nullptr);
            triangles += static_cast<std::uint64_t>(g.count) / 3;
        }
        glDisable(GL_CULL_FACE);
        glCullFace(GL_BACK);
        r.endFrame();
        return triangles;
    }

private:
    struct Gpu {
        GLuint vao = 0, vbo = 0, ibo = 0;
        GLsizei count = 0;
        Aabb box;
    };
    GLuint program_ = 0;
    GLint locViewProj_ = -1, locModel_ = -1;
    std::vector<Gpu> models_;
    std::vector<std::pair<float, std::uint32_t>> order_;  // (distance, object slot)
};

[[noreturn]] void fail(const std::string& message) {
    std::fprintf(stderr, "bench_draw_speed: %s\n", message.c_str());
    std::exit(1);
}

// The parts of every bunny in view, nearest bunny first, each part drawn or tested alone
// through the part renderer: what the two-phase mode's triangle tests cost beside drawing
// the same parts. Marked draws and tests store into a storage buffer at the marks' binding
// point, read back at the end (the answers in hand).
class PartLoop {
public:
    enum class Kind { Draw, DrawClusters, DrawMarked, TestVisible, TestHidden };
    PartLoop() { glCreateBuffers(1, &marks_); }
    ~PartLoop() { glDeleteBuffers(1, &marks_); }

    std::uint64_t run(Engine& engine, Kind kind) {
        Renderer& r = engine.renderer();
        engine.context().clearFramebuffer(Renderer::kClearColour);
        // A test against a cleared depth buffer: every fragment passes (visible). Against depth
        // 1, the nearest value in reversed Z: every fragment fails (hidden behind a wall).
        if (kind == Kind::TestHidden) {
            glClearDepth(1.0);
            glClear(GL_DEPTH_BUFFER_BIT);
            glClearDepth(0.0);
        }
        const Camera& camera = engine.camera();
        r.beginFrame(FrameView::of(camera, engine.context().size().x, engine.context().size().y));
        const bool test = kind == Kind::TestVisible || kind == Kind::TestHidden;
        if (test) {
            glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
            glDepthMask(GL_FALSE);
        }
        const SceneObjects& objs = engine.objects();
        const Frustum frustum = Frustum::fromCamera(camera);
        order_.clear();
        for (std::uint32_t o = 0; o < objs.slotCount(); ++o) {
            if (!objs.alive(o) || frustum.outside(objs.worldBox(o))) continue;
            order_.push_back({glm::length(objs.worldBox(o).center() - camera.position), o});
        }
        std::stable_sort(order_.begin(), order_.end());
        std::uint32_t slots = 0;
        for (const auto& [distance, o] : order_)
            for (const LocalBspNode& n : objs.model(objs.modelOf(o)).nodes) slots += n.isLeaf() ? 1u : 0u;
        if (kind != Kind::Draw && kind != Kind::DrawClusters) {
            glNamedBufferData(marks_, std::max<GLsizeiptr>(4, GLsizeiptr{4} * slots), nullptr, GL_STREAM_READ);
            const std::uint32_t zero = 0;
            glClearNamedBufferData(marks_, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kMarksBinding, marks_);
        }
        std::uint64_t triangles = 0;
        std::uint32_t slot = 0;
        for (const auto& [distance, o] : order_) {
            const MeshId mesh = engine.meshOf(objs.modelOf(o));
            const LocalBsp& model = objs.model(objs.modelOf(o));
            for (std::uint32_t i = 0; i < model.nodes.size(); ++i) {
                const LocalBspNode& n = model.nodes[i];
                if (!n.isLeaf()) continue;
                if (kind == Kind::DrawClusters) {
                    if (slot == 0) ranges = parts = 0;
                    ++parts;
                    ranges_.clear();
                    for (const LeafCluster& c : model.clusters.ofSubtree(i, 1)) ranges_.push_back({c.firstIndex, c.indexCount});
                    r.drawRanges(mesh, ranges_, objs.matrix(o), colourForId(o));
                    ranges += ranges_.size();
                } else if (test)
                    r.testRange(mesh, n.firstIndex, n.indexCount, objs.matrix(o), slot);
                else
                    r.drawRange(mesh, n.firstIndex, n.indexCount, objs.matrix(o), colourForId(o),
                                kind == Kind::DrawMarked ? slot : Renderer::kNoMark);
                ++slot;
                triangles += n.indexCount / 3;
            }
        }
        r.endFrame();
        if (test) {
            glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
            glDepthMask(GL_TRUE);
        }
        if (kind != Kind::Draw && kind != Kind::DrawClusters) {
            answers_.resize(slots);
            glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
            glGetNamedBufferSubData(marks_, 0, GLsizeiptr{4} * slots, answers_.data());
            const auto visible = static_cast<std::uint32_t>(std::count(answers_.begin(), answers_.end(), 1u));
            if ((kind == Kind::TestHidden && visible != 0) || (kind == Kind::TestVisible && visible == 0))
                fail("triangle test answered " + std::to_string(visible) + " of " + std::to_string(slots) + " parts visible");
        }
        return triangles;
    }

private:
    GLuint marks_ = 0;
    std::vector<std::pair<float, std::uint32_t>> order_;
    std::vector<std::uint32_t> answers_;
    std::vector<IndexRange> ranges_;

public:
    std::uint64_t ranges = 0, parts = 0;  // of the last DrawClusters frame
};

struct Swarm {
    std::unique_ptr<DemoScene> scene;
    std::unique_ptr<Engine> engine;
    QueryScheduler vfc{[] {
        SchedulerParams p;
        p.mode = CullMode::Vfc;
        return p;
    }()};
    /// The default conservative mode (two-phase), the same with early parts drawn whole, and
    /// with the early clusters chosen by their fragments' marks instead of their boxes.
    QueryScheduler full{SchedulerParams{}};
    QueryScheduler fullNoClusterHistory{[] {
        SchedulerParams p;
        p.features.useClusterHistory = false;
        return p;
    }()};
    QueryScheduler fullMarkClusterHistory{[] {
        SchedulerParams p;
        p.features.useClusterMarks = true;
        return p;
    }()};
};

Swarm makeSwarm(GlContext& ctx, BunnySwarmOptions options) {
    Swarm s;
    s.scene = makeBunnySwarm(options);
    EngineOptions eo;
    eo.finishEachFrame = true;
    auto engine = Engine::create(ctx, eo);
    if (!engine) fail(engine.error().message);
    s.engine = engine.take();
    if (Status st = s.scene->populate(*s.engine); !st) fail(st.message());
    return s;
}

}  // namespace
}  // namespace dyncull

int main(int argc, char** argv) {
    using namespace dyncull;
    keepFreedHeapMemory();  // as the dyncull program does: every variant draws through the same heap
    CLI::App app{"Draw speed of dyncull's renderer against a speed-of-light reference (bunny swarm)"};
    BunnySwarmOptions o = bench::issue21Swarm();
    bench::SwarmRun run;
    run.out = "out/bench_draw_speed";
    std::string size = "640x360";
    bench::addSwarmOptions(app, o, run, size);
    app.add_option("--leaf-tris", o.leafTriangles, "local-BSP leaf size")->check(CLI::Range(1u, 100000000u))->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    if (!bench::parseSize(size, run)) fail("--size: expected WxH, e.g. 640x360");
    const std::uint32_t frames = run.frames, first = run.first;
    const int width = run.width, height = run.height;
    const std::string& out = run.out;

    ContextOptions co;
    co.width = width;
    co.height = height;
    auto ctx = GlContext::create(co);
    if (!ctx) fail(ctx.error().message);

    // One engine per way of building the model; variants that differ only in renderer
    // settings share one.
    Swarm tuned = makeSwarm(**ctx, o);
    BunnySwarmOptions loadOrder = o;
    loadOrder.optimizeOrder = false;
    Swarm unordered = makeSwarm(**ctx, loadOrder);
    BunnySwarmOptions cacheOrder = o;
    cacheOrder.clusterOrder = false;
    Swarm noMeshlets = makeSwarm(**ctx, cacheOrder);
    const bool culls = tuned.engine->model(0).faces == FaceMode::CullBack;
    std::unique_ptr<Swarm> forced;  // FacePolicy::CullBack when Auto keeps the mesh two-sided
    if (!culls) {
        BunnySwarmOptions f = o;
        f.faces = FacePolicy::CullBack;
        forced = std::make_unique<Swarm>(makeSwarm(**ctx, f));
    }
    std::printf("%s\ncontext: %s, %s; %dx%d; the model is drawn %s\n", tuned.scene->description().c_str(),
                (*ctx)->platformName().c_str(), (*ctx)->rendererName().c_str(), width, height,
                culls ? "with back faces culled (closed and outward)" : "two-sided (FacePolicy::Auto: not closed)");
    SpeedOfLight sol(*tuned.engine);

    std::vector<bench::Variant> variants;
    auto finished = [](auto&& draw) {
        return [draw]() -> std::uint64_t {
            glFinish();
            const std::uint64_t t = draw();
            glFinish();
            return t;
        };
    };
    auto vfcFrame = [](Swarm& s, Shading shading, bool cull, bool discard, bool clusters = true) {
        return [&s, shading, cull, discard, clusters]() -> std::uint64_t {
            SchedulerParams p = s.vfc.params();
            p.features.useClusters = clusters;
            s.vfc.setParams(p);
            s.engine->renderer().setShading(shading);
            s.engine->renderer().setBackFaceCulling(cull);
            s.engine->renderer().setRasteriserDiscard(discard);
            s.engine->context().clearFramebuffer(Renderer::kClearColour);
            auto st = s.engine->renderFrame(s.vfc);
            s.engine->renderer().setRasteriserDiscard(false);
            s.engine->renderer().setShading(Shading::Vertex);
            s.engine->renderer().setBackFaceCulling(true);
            if (!st) fail(st.error().message);
            return st->trianglesDrawn;
        };
    };
    variants.push_back({"sol", "trivial shader, back faces culled, one draw per bunny",
                        finished([&] { return sol.draw(*tuned.engine, true); }), {}, 0, {}});
    variants.push_back({"sol-unsorted", "sol in object order instead of front to back",
                        finished([&] { return sol.draw(*tuned.engine, true, false); }), {}, 0, {}});
    variants.push_back({"sol-all-culled", "sol with every face culled: vertex work and triangle set-up only",
                        finished([&] { return sol.draw(*tuned.engine, true, true, GL_FRONT_AND_BACK); }), {}, 0, {}});
    variants.push_back({"sol-discard", "sol with rasteriser discard: vertex work only",
                        finished([&] {
                            glEnable(GL_RASTERIZER_DISCARD);
                            const auto t = sol.draw(*tuned.engine, true);
                            glDisable(GL_RASTERIZER_DISCARD);
                            return t;
                        }),
                        {}, 0, {}});
    variants.push_back({"vfc", "dyncull vfc: per-vertex lighting, faces as decided, parts in cache order",
                        vfcFrame(tuned, Shading::Vertex, true, false), {}, 0, {}});
    variants.push_back({"vfc-noclusters", "vfc drawing whole parts (no cluster tests)",
                        vfcFrame(tuned, Shading::Vertex, true, false, false), {}, 0, {}});
    variants.push_back({"vfc-cache-order", "vfc with the parts in cache and overdraw order, not meshlets (clusters cut from it)",
                        vfcFrame(noMeshlets, Shading::Vertex, true, false), {}, 0, {}});
    variants.push_back({"vfc-discard", "vfc with rasteriser discard: traversal, draws, vertex work",
                        vfcFrame(tuned, Shading::Vertex, true, true), {}, 0, {}});
    variants.push_back({"vfc-pixel", "vfc with per-pixel lighting", vfcFrame(tuned, Shading::Pixel, true, false), {}, 0, {}});
    variants.push_back({"vfc-pixel-discard", "vfc-pixel with rasteriser discard",
                        vfcFrame(tuned, Shading::Pixel, true, true), {}, 0, {}});
    if (culls)
        variants.push_back({"vfc-two-sided", "vfc drawing both sides", vfcFrame(tuned, Shading::Vertex, false, false), {}, 0, {}});
    else
        variants.push_back({"vfc-cull", "vfc with back faces culled anyway (FacePolicy::CullBack: holes show through)",
                            vfcFrame(*forced, Shading::Vertex, true, false), {}, 0, {}});
    variants.push_back({"vfc-load-order", "vfc with the parts' triangles in load order",
                        vfcFrame(unordered, Shading::Vertex, true, false), {}, 0, {}});
    PartLoop parts;
    auto partFrame = [&](PartLoop::Kind kind) { return finished([&parts, &tuned, kind] { return parts.run(*tuned.engine, kind); }); };
    variants.push_back({"parts", "every part in view drawn alone, nearest bunny first, no traversal", partFrame(PartLoop::Kind::Draw), {}, 0, {}});
    variants.push_back({"parts-clusters", "parts, each drawn as its clusters' ranges in one multi-draw (nothing culled): the cost of a range",
                        partFrame(PartLoop::Kind::DrawClusters), {}, 0, {}});
    variants.push_back({"parts-cache-order", "parts, in cache and overdraw order instead of meshlets",
                        finished([&parts, &noMeshlets] { return parts.run(*noMeshlets.engine, PartLoop::Kind::Draw); }), {}, 0, {}});
    variants.push_back({"parts-marked", "parts, each draw marking whether it showed a sample (two-phase's draw marks)",
                        partFrame(PartLoop::Kind::DrawMarked), {}, 0, {}});
    variants.push_back({"test-visible", "every part tested on its own triangles, every fragment passing",
                        partFrame(PartLoop::Kind::TestVisible), {}, 0, {}});
    variants.push_back({"test-hidden", "every part tested on its own triangles behind a wall (every fragment fails)",
                        partFrame(PartLoop::Kind::TestHidden), {}, 0, {}});
    auto cullFrame = [](Swarm& s, QueryScheduler& scheduler) {
        return [&s, &scheduler]() -> std::uint64_t {
            s.engine->context().clearFramebuffer(Renderer::kClearColour);
            auto st = s.engine->renderFrame(scheduler);
            if (!st) fail(st.error().message);
            return st->trianglesDrawn;
        };
    };
    variants.push_back({"full", "dyncull's default conservative mode (two-phase, cluster history), its own history from frame to frame",
                        cullFrame(tuned, tuned.full), {}, 0, {}});
    variants.push_back({"full-noclusterhist", "full with early parts drawn with all their clusters",
                        cullFrame(tuned, tuned.fullNoClusterHistory), {}, 0, {}});
    variants.push_back({"full-markclusterhist", "full with the early clusters chosen by their fragments' marks, not by their boxes",
                        cullFrame(tuned, tuned.fullMarkClusterHistory), {}, 0, {}});
    variants.push_back({"vfc-before", "the renderer before issue 21: per-pixel, two-sided, load order, whole parts",
                        vfcFrame(unordered, Shading::Pixel, false, false, false), {}, 0, {}});

    if (!bench::keepOnly(variants, run.only)) fail("--only: no such variant in '" + run.only + "'");
    std::vector<Swarm*> swarms{&tuned, &unordered, &noMeshlets};
    if (forced) swarms.push_back(forced.get());
    const float aspect = static_cast<float>(width) / static_cast<float>(height);
    // Frame -1 is a warm-up: llvmpipe compiles shader and state variants on first use,
    // which would add hundreds of milliseconds to whichever variant meets them first.
    for (std::int64_t f = -1; f < static_cast<std::int64_t>(frames); ++f) {
        const std::uint64_t frame = first + static_cast<std::uint64_t>(std::max<std::int64_t>(f, 0));
        for (Swarm* s : swarms) {
            if (Status st = s->scene->update(*s->engine, frame); !st) fail(st.message());
            if (Status st = s->engine->setCamera(s->scene->camera(frame, aspect)); !st) fail(st.message());
            s->engine->updateSceneTree();
        }
        // Rotate the order every frame so no variant always runs right after the same one.
        for (std::size_t k = 0; k < variants.size(); ++k) {
            bench::Variant& v = variants[(k + static_cast<std::size_t>(f + 1)) % variants.size()];
            const auto t0 = Clock::now();
            v.triangles = v.frame();
            const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
            if (f < 0) continue;
            v.ms.push_back(ms);
            if (f == 0 && v.name.find("discard") == std::string::npos && v.name.rfind("test", 0) != 0) v.first = tuned.engine->renderer().readPixels();
        }
        if (f >= 0) std::fprintf(stderr, "\rframe %lld/%u", static_cast<long long>(f + 1), frames);
    }
    std::fprintf(stderr, "\n");

    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    std::ofstream csv;
    const std::filesystem::path csvPath = std::filesystem::path(out) / "draw_speed.csv";
    if (Status s = openChecked(csv, csvPath); !s) fail(s.message());
    csv << "variant,median_ms,mean_ms,frames,triangles,ns_per_triangle,vs_sol\n";
    const double solMs = bench::median(variants[0].ms);
    std::printf("%-18s %9s %9s %11s %8s %7s  %s\n", "variant", "median_ms", "mean_ms", "triangles", "ns/tri", "vs_sol",
                "what");
    for (const bench::Variant& v : variants) {
        const double med = bench::median(v.ms);
        double mean = 0;
        for (double x : v.ms) mean += x / static_cast<double>(v.ms.size());
        const double nsPerTri = v.triangles ? 1e6 * med / static_cast<double>(v.triangles) : 0.0;
        std::printf("%-18s %9.1f %9.1f %11llu %8.1f %7.2f  %s\n", v.name.c_str(), med, mean,
                    static_cast<unsigned long long>(v.triangles), nsPerTri, med / solMs, v.what.c_str());
        csv << v.name << ',' << med << ',' << mean << ',' << v.ms.size() << ',' << v.triangles << ',' << nsPerTri << ','
            << med / solMs << '\n';
        if (!v.first.rgba.empty())
            if (Status s = writePng(v.first, std::filesystem::path(out) / (v.name + ".png")); !s) fail(s.message());
    }
    if (Status s = closeChecked(csv, csvPath); !s) fail(s.message());
    // Culling back faces of a closed surface and reordering triangles inside a part must
    // not change the picture (depth ties aside); per-pixel lighting changes it slightly.
    // What one more range of a multi-draw costs: drawing every part as its clusters'
    // ranges against drawing it as one range, the same triangles.
    const auto named = [&](const char* n) {
        return std::find_if(variants.begin(), variants.end(), [&](const bench::Variant& v) { return v.name == n; });
    };
    if (named("parts") != variants.end() && named("parts-clusters") != variants.end() && parts.ranges > parts.parts)
        std::printf("a range of a multi-draw costs %.2f us (parts-clusters against parts, %llu ranges for %llu parts)\n",
                    1000.0 * (bench::median(named("parts-clusters")->ms) - bench::median(named("parts")->ms)) / double(parts.ranges - parts.parts),
                    static_cast<unsigned long long>(parts.ranges), static_cast<unsigned long long>(parts.parts));
    const auto vfc = std::find_if(variants.begin(), variants.end(), [](const bench::Variant& v) { return v.name == "vfc"; });
    const Image& ref = vfc != variants.end() ? vfc->first : variants[0].first;
    for (const bench::Variant& v : variants)
        if (!v.first.rgba.empty() && &v.first != &ref && v.name.rfind("sol", 0) != 0)
            if (auto d = compareImages(ref, v.first))
                std::printf("pixels differing from vfc, frame %u: %-16s %llu (%.3f%%)\n", first, v.name.c_str(),
                            static_cast<unsigned long long>(d->differingPixels), d->percentDiffering);
    std::printf("wrote %s and the first frame of each variant as PNG in %s\n", csvPath.c_str(), out.c_str());
    return 0;
}
