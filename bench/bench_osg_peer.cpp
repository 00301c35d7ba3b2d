// OpenSceneGraph beside dyncull on the bunny swarm: one context, one framebuffer, the same
// triangles, motion and camera, the systems interleaved frame by frame (issue 21's peer).
//
// The program is a game that owns an OpenGL 4.5 compatibility context (OSG 3.6 as Debian
// builds it draws with the fixed-function pipeline) and an FBO. OSG renders into it as an
// embedded viewer (osgViewer::GraphicsWindowEmbedded, its default framebuffer set to the
// FBO); dyncull borrows it (GlContext::borrowCurrent), as any game embedding it would. OSG
// draws the bunny as loaded (holes capped: prepareBunnyMesh), one geometry shared by 300
// transforms; dyncull draws its local BSP's parts, whose split adds triangles. Variants:
//   osg          OSG as it comes: frustum culling (bounding spheres), its default headlight
//                (per-vertex lighting), both faces drawn: issue 21's "frustum culling only";
//   osg-cull     the same with GL_CULL_FACE on: what an OSG user who culls back faces gets;
//   osg-oqn      every bunny under an osg::OcclusionQueryNode, visible above 0 pixels
//                (its default: a query every 5 frames, from the node's bounding box);
//   vfc, full    dyncull's frustum-culled and default conservative modes (Engine::renderFrame).
// Every frame is timed from glFinish to glFinish. OSG runs single-threaded: its cull and
// draw share the render thread, as dyncull's traversal does.
//
// Usage: bench_osg_peer [--frames N] [--count 300] [--box 8] [--bunny-size 1] [--orbit 12]
//        [--speed 0.02] [--size 640x360] [--out DIR] [--mesh FILE] [--only a,b]
// Prints median and mean ms per variant, the triangles each drew, and each variant's time
// against `osg` (ratio of medians, and the median of the frames' own ratios); writes DIR/osg_peer.csv and the first measured frame of each as PNG.
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
#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>

// OSG's headers after epoxy's: osg/GL includes the system GL header, which epoxy's replace.
#include <osg/CullFace>
#include <osg/Geode>
#include <osg/Geometry>
#include <osg/MatrixTransform>
#include <osg/OcclusionQueryNode>
#include <osg/Switch>
#include <osgViewer/Viewer>

#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/engine/engine.hpp"
#include "dyncull/engine/gl_context.hpp"
#include "dyncull/engine/heap_tuning.hpp"
#include "dyncull/engine/image.hpp"
#include "dyncull/measure/png_writer.hpp"
#include "dyncull/objects/checked_write.hpp"
#include "dyncull/objects/mesh.hpp"
#include "swarm_bench.hpp"

namespace dyncull {
namespace {

using Clock = std::chrono::steady_clock;

[[noreturn]] void fail(const std::string& message) {
    std::fprintf(stderr, "bench_osg_peer: %s\n", message.c_str());
    std::exit(1);
}

// --- The game's context and framebuffer ----------------------------------------------------

void createCompatibilityContext() {
    EGLDisplay dpy = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, nullptr, nullptr)) fail("no EGL surfaceless display");
    eglBindAPI(EGL_OPENGL_API);
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                              EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT, EGL_NONE};
    EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
    if (ctx == EGL_NO_CONTEXT || !eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx))
        fail("no OpenGL 4.5 compatibility context");
}

struct Framebuffer {
    GLuint fbo = 0;
    int width = 0, height = 0;

    Framebuffer(int w, int h) : width(w), height(h) {
        GLuint colour = 0, depth = 0;
        glCreateRenderbuffers(1, &colour);
        glNamedRenderbufferStorage(colour, GL_RGBA8, w, h);
        glCreateRenderbuffers(1, &depth);
        glNamedRenderbufferStorage(depth, GL_DEPTH_COMPONENT32F, w, h);  // float: dyncull's reversed Z
        glCreateFramebuffers(1, &fbo);
        glNamedFramebufferRenderbuffer(fbo, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
        glNamedFramebufferRenderbuffer(fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
        if (glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) fail("framebuffer incomplete");
    }

    Image read() const {
        Image img;
        img.width = width;
        img.height = height;
        const std::size_t row = static_cast<std::size_t>(width) * 4;
        std::vector<std::uint8_t> bottomUp(row * static_cast<std::size_t>(height));
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, bottomUp.data());
        img.rgba.resize(bottomUp.size());
        for (int y = 0; y < height; ++y)
            std::copy_n(bottomUp.data() + static_cast<std::size_t>(height - 1 - y) * row, row,
                        img.rgba.data() + static_cast<std::size_t>(y) * row);
        return img;
    }
};

// --- OpenSceneGraph's scene: one geometry per model, one transform per bunny ---------------

// Counts the bunnies OSG draws: a geometry's draw callback runs once per drawn instance.
struct CountDraws : osg::Drawable::DrawCallback {
    mutable std::uint64_t draws = 0;
    void drawImplementation(osg::RenderInfo& info, const osg::Drawable* drawable) const override {
        ++draws;
        drawable->drawImplementation(info);
    }
};

class OsgScene {
public:
    enum Child : unsigned { Plain = 0, CullBack = 1, Queried = 2 };

    /// `mesh`: the bunny in the swarm's object space, as loaded (before dyncull's split).
    OsgScene(Mesh mesh, const SceneObjects& objs) {
        if (mesh.normals.size() != mesh.positions.size()) computeNormals(mesh);
        osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
        g->setUseDisplayList(false);
        g->setUseVertexBufferObjects(true);
        osg::ref_ptr<osg::Vec3Array> positions = new osg::Vec3Array(mesh.positions.size());
        osg::ref_ptr<osg::Vec3Array> normals = new osg::Vec3Array(osg::Array::BIND_PER_VERTEX, mesh.normals.size());
        for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
            (*positions)[i].set(mesh.positions[i].x, mesh.positions[i].y, mesh.positions[i].z);
            (*normals)[i].set(mesh.normals[i].x, mesh.normals[i].y, mesh.normals[i].z);
        }
        g->setVertexArray(positions);
        g->setNormalArray(normals);
        g->addPrimitiveSet(new osg::DrawElementsUInt(GL_TRIANGLES, mesh.indices.begin(), mesh.indices.end()));
        g->setDrawCallback(counter_);
        model_ = new osg::Geode;
        model_->addDrawable(g);
        triangles_ = mesh.indices.size() / 3;
        osg::ref_ptr<osg::Group> plain = new osg::Group, culled = new osg::Group, queried = new osg::Group;
        culled->getOrCreateStateSet()->setAttributeAndModes(new osg::CullFace(osg::CullFace::BACK), osg::StateAttribute::ON);
        for (std::uint32_t o = 0; o < objs.slotCount(); ++o) {
            if (!objs.alive(o)) continue;
            osg::ref_ptr<osg::MatrixTransform> t = new osg::MatrixTransform;
            t->addChild(model_);
            plain->addChild(t);
            culled->addChild(t);  // shared: the two groups differ only in their state
            osg::ref_ptr<osg::OcclusionQueryNode> q = new osg::OcclusionQueryNode;
            q->setVisibilityThreshold(0);
            q->addChild(t);
            queried->addChild(q);
            transforms_.push_back({o, t});
        }
        root_ = new osg::Switch;
        root_->addChild(plain, true);
        root_->addChild(culled, false);
        root_->addChild(queried, false);
    }

    osg::Switch* root() const { return root_.get(); }

    /// Copies every bunny's object-to-world matrix (glm's column-major floats are OSG's
    /// memory layout: OSG multiplies row vectors by the transpose).
    void update(const SceneObjects& objs) {
        for (auto& [o, t] : transforms_) t->setMatrix(osg::Matrixd(glm::value_ptr(objs.matrix(o))));
    }

    void select(Child c) { root_->setSingleChildOn(c); }

    /// Triangles of the bunnies drawn since the last call.
    std::uint64_t takeTriangles() {
        const std::uint64_t t = counter_->draws * triangles_;
        counter_->draws = 0;
        return t;
    }

private:
    osg::ref_ptr<CountDraws> counter_ = new CountDraws;
    osg::ref_ptr<osg::Geode> model_;
    std::uint64_t triangles_ = 0;
    std::vector<std::pair<std::uint32_t, osg::ref_ptr<osg::MatrixTransform>>> transforms_;
    osg::ref_ptr<osg::Switch> root_;
};

/// The camera as OSG states it: a right-handed look-at and OpenGL's [-1, 1] depth, near and
/// far fixed (not computed from the scene's bounds, which would differ from dyncull's).
void setOsgCamera(osgViewer::Viewer& viewer, const Camera& c) {
    osg::Camera* cam = viewer.getCamera();
    cam->setViewMatrix(osg::Matrixd::lookAt(osg::Vec3d(c.position.x, c.position.y, c.position.z),
                                            osg::Vec3d(c.target.x, c.target.y, c.target.z), osg::Vec3d(c.up.x, c.up.y, c.up.z)));
    cam->setProjectionMatrixAsPerspective(osg::RadiansToDegrees(double(c.fovYRadians)), double(c.aspect), double(c.nearPlane),
                                          double(c.farPlane));
}

}  // namespace
}  // namespace dyncull

int main(int argc, char** argv) {
    using namespace dyncull;
    keepFreedHeapMemory();  // one process: OSG's frames draw through the same heap as dyncull's
    CLI::App app{"OpenSceneGraph beside dyncull on the bunny swarm, interleaved per frame in one context"};
    BunnySwarmOptions o = bench::issue21Swarm();
    bench::SwarmRun run;
    run.out = "out/bench_osg_peer";
    std::string size = "640x360";
    bench::addSwarmOptions(app, o, run, size);
    CLI11_PARSE(app, argc, argv);
    if (!bench::parseSize(size, run)) fail("--size: expected WxH, e.g. 640x360");
    const std::uint32_t frames = run.frames, first = run.first;
    const int width = run.width, height = run.height;
    const std::string& out = run.out;

    createCompatibilityContext();
    const Framebuffer target(width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, target.fbo);
    glViewport(0, 0, width, height);

    // dyncull, embedded as a game embeds it.
    auto borrowed = GlContext::borrowCurrent();
    if (!borrowed) fail(borrowed.error().message);
    auto engineOr = Engine::create(**borrowed, EngineOptions{});
    if (!engineOr) fail(engineOr.error().message);
    std::unique_ptr<Engine> engine = engineOr.take();
    std::unique_ptr<DemoScene> scene = makeBunnySwarm(o);
    if (Status st = scene->populate(*engine); !st) fail(st.message());
    QueryScheduler vfc{[] {
        SchedulerParams p;
        p.mode = CullMode::Vfc;
        return p;
    }()};
    QueryScheduler full{SchedulerParams{}};

    // OpenSceneGraph, embedded in the same context, drawing into the same FBO.
    auto bunny = prepareBunnyMesh(o);
    if (!bunny) fail(bunny.error().message);
    OsgScene osgScene(std::move(bunny->mesh), engine->objects());
    osgViewer::Viewer viewer;
    viewer.setThreadingModel(osgViewer::Viewer::SingleThreaded);
    osgViewer::GraphicsWindowEmbedded* window = viewer.setUpViewerAsEmbeddedInWindow(0, 0, width, height);
    window->setDefaultFboId(target.fbo);
    viewer.getCamera()->setComputeNearFarMode(osg::CullSettings::DO_NOT_COMPUTE_NEAR_FAR);
    viewer.getCamera()->setClearColor(osg::Vec4(Renderer::kClearColour.r, Renderer::kClearColour.g, Renderer::kClearColour.b, 1.0f));
    viewer.setSceneData(osgScene.root());
    viewer.setCameraManipulator(nullptr);
    viewer.realize();

    std::printf("%s\ncontext: EGL surfaceless, %s, %s; %dx%d\n", scene->description().c_str(),
                reinterpret_cast<const char*>(glGetString(GL_VERSION)), reinterpret_cast<const char*>(glGetString(GL_RENDERER)),
                width, height);

    auto osgFrame = [&](OsgScene::Child child) {
        return [&, child]() -> std::uint64_t {
            osgScene.select(child);
            osgScene.takeTriangles();
            viewer.frame();
            return osgScene.takeTriangles();
        };
    };
    auto dyncullFrame = [&](QueryScheduler& scheduler) {
        return [&]() -> std::uint64_t {
            // The game clears in dyncull's depth convention (reversed Z: depth 0 is far).
            glBindFramebuffer(GL_FRAMEBUFFER, target.fbo);
            glViewport(0, 0, width, height);
            glClearColor(Renderer::kClearColour.r, Renderer::kClearColour.g, Renderer::kClearColour.b, 1.0f);
            glClearDepth(0.0);
            glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            glClearDepth(1.0);
            auto st = engine->renderFrame(scheduler);
            if (!st) fail(st.error().message);
            return st->trianglesDrawn;
        };
    };
    std::vector<bench::Variant> variants;
    variants.push_back({"osg", "OpenSceneGraph 3.6: frustum culling, both faces, per-vertex headlight",
                        osgFrame(OsgScene::Plain), {}, 0, {}});
    variants.push_back({"osg-cull", "osg with back faces culled", osgFrame(OsgScene::CullBack), {}, 0, {}});
    variants.push_back({"osg-oqn", "osg with an OcclusionQueryNode per bunny, threshold 0 pixels",
                        osgFrame(OsgScene::Queried), {}, 0, {}});
    variants.push_back({"vfc", "dyncull vfc", dyncullFrame(vfc), {}, 0, {}});
    variants.push_back({"full", "dyncull's default conservative mode, its history from frame to frame", dyncullFrame(full), {}, 0, {}});
    if (!bench::keepOnly(variants, run.only)) fail("--only: no such variant in '" + run.only + "'");

    const float aspect = static_cast<float>(width) / static_cast<float>(height);
    // Frame -1 is a warm-up: llvmpipe compiles shader and state variants on first use.
    for (std::int64_t f = -1; f < static_cast<std::int64_t>(frames); ++f) {
        const std::uint64_t frame = first + static_cast<std::uint64_t>(std::max<std::int64_t>(f, 0));
        if (Status st = scene->update(*engine, frame); !st) fail(st.message());
        const Camera camera = scene->camera(frame, aspect);
        if (Status st = engine->setCamera(camera); !st) fail(st.message());
        engine->updateSceneTree();
        osgScene.update(engine->objects());
        setOsgCamera(viewer, camera);
        // Rotate the order every frame so no variant always runs right after the same one.
        for (std::size_t k = 0; k < variants.size(); ++k) {
            bench::Variant& v = variants[(k + static_cast<std::size_t>(f + 1)) % variants.size()];
            glFinish();
            const auto t0 = Clock::now();
            v.triangles = v.frame();
            glFinish();
            const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
            if (f < 0) continue;
            v.ms.push_back(ms);
            if (f == 0) v.first = target.read();
        }
        if (f >= 0) std::fprintf(stderr, "\rframe %lld/%u", static_cast<long long>(f + 1), frames);
    }
    std::fprintf(stderr, "\n");
    if (const GLenum e = glGetError(); e != GL_NO_ERROR) fail("GL error " + std::to_string(e) + " after the run");

    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    std::ofstream csv;
    const std::filesystem::path csvPath = std::filesystem::path(out) / "osg_peer.csv";
    if (Status s = openChecked(csv, csvPath); !s) fail(s.message());
    csv << "variant,median_ms,mean_ms,frames,triangles,vs_osg,per_frame_vs_osg\n";
    const auto osgIt = std::find_if(variants.begin(), variants.end(), [](const bench::Variant& v) { return v.name == "osg"; });
    const double osgMs = osgIt != variants.end() ? bench::median(osgIt->ms) : 0.0;
    std::printf("%-9s %9s %9s %11s %7s %9s  %s\n", "variant", "median_ms", "mean_ms", "triangles", "vs_osg", "per_frame",
                "what");
    for (const bench::Variant& v : variants) {
        const double med = bench::median(v.ms);
        double mean = 0;
        for (double x : v.ms) mean += x / static_cast<double>(v.ms.size());
        const double ratio = osgMs > 0 ? med / osgMs : 0.0;
        // The median of each frame's ratio: the two ran seconds apart, so drift cancels.
        std::vector<double> perFrame;
        if (osgIt != variants.end())
            for (std::size_t i = 0; i < v.ms.size(); ++i) perFrame.push_back(v.ms[i] / osgIt->ms[i]);
        const double frameRatio = perFrame.empty() ? 0.0 : bench::median(perFrame);
        std::printf("%-9s %9.1f %9.1f %11llu %7.3f %9.3f  %s\n", v.name.c_str(), med, mean,
                    static_cast<unsigned long long>(v.triangles), ratio, frameRatio, v.what.c_str());
        csv << v.name << ',' << med << ',' << mean << ',' << v.ms.size() << ',' << v.triangles << ',' << ratio << ','
            << frameRatio << '\n';
        if (Status s = writePng(v.first, std::filesystem::path(out) / (v.name + ".png")); !s) fail(s.message());
    }
    if (Status s = closeChecked(csv, csvPath); !s) fail(s.message());
    // The same scene: the pixels covered (not the clear colour) in the first frame must agree
    // between OSG and dyncull; the shading differs by design.
    const auto vfcIt = std::find_if(variants.begin(), variants.end(), [](const bench::Variant& v) { return v.name == "vfc"; });
    if (osgIt != variants.end() && vfcIt != variants.end()) {
        const glm::u8vec4 clear(glm::round(Renderer::kClearColour * 255.0f), 255);
        std::uint64_t covered = 0, differ = 0;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const bool a = osgIt->first.at(x, y) != clear, b = vfcIt->first.at(x, y) != clear;
                covered += a ? 1 : 0;
                differ += a != b ? 1 : 0;
            }
        std::printf("coverage, frame %u: osg covers %llu pixels, vfc differs from it in %llu\n", first,
                    static_cast<unsigned long long>(covered), static_cast<unsigned long long>(differ));
    }
    std::printf("wrote %s and the first frame of each variant as PNG in %s\n", csvPath.c_str(), out.c_str());
    return 0;
}
