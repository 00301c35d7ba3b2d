// A static model subdivided into objects (issue 8): the soup of a built-in scene, a
// directory or a model file is cut by p-HBVO, D-BVS or an octree (dyncull/bsp/
// subdivision.hpp), on the fly or read from a `dyncull subdivide` file, and every leaf
// becomes one static object of the global loose BSP, culled by the same scheduler as
// dynamic objects. Static objects never relink.
// Paper: Scene subdivision for occlusion culling, sections 2-3.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/loaders/loaders.hpp"
#include "dyncull/objects/surface_orientation.hpp"
#include "generators.hpp"

namespace dyncull {
namespace {

Scene toScene(GeneratedScene&& g) {
    Scene s;
    s.meshes = std::move(g.meshes);
    for (const PlacedObject& o : g.objects) s.instances.push_back({o.model, o.transform.matrix(), {}});
    return s;
}

std::string stem(const std::string& source) {
    if (source == "powerplant" || source == "city") return source;
    const std::filesystem::path p(source);
    return p.has_stem() ? p.stem().string() : p.filename().string();
}

class SubdividedScene final : public DemoScene {
public:
    SubdividedScene(std::string source, std::string file, const SceneOptions& options)
        : source_(std::move(source)), file_(std::move(file)), options_(options) {
        if (!file_.empty()) name_ = std::filesystem::path(file_).stem().string();
        else name_ = stem(source_) + "_" + options_.subdivide.method;
    }

    std::string name() const override { return name_; }
    std::string description() const override { return description_; }

    Status populate(Engine& engine) override {
        const auto t0 = std::chrono::steady_clock::now();
        std::vector<LocalBsp> leaves;
        std::size_t triangles = 0;
        SubdivisionStats stats;
        SubdivisionParams params;
        {  // the soup is freed at the end of this block, before the leaves are uploaded
            auto model = file_.empty() ? subdivideStaticScene(source_, options_) : readSubdivisionFile(file_);
            if (!model) return Error{model.error().message};
            source_ = model->source;
            if (builtinHash(source_, options_) != model->sourceHash)
                return Error{file_ + ": made from '" + source_ +
                             "' with other generator options; pass the --plant-*/--city-* options it was made with"};
            bounds_ = model->mesh.bounds();
            if (!builtinCameraScene(source_, options_)) walkthrough_ = staticModelWalkthrough(model->mesh);
            // The whole model's surface decides (one leaf alone is an open piece); shells
            // wound inwards were flipped before subdividing (subdivideStaticScene).
            const SurfaceReport surface = model->surface ? *model->surface : analyseSurface(model->mesh);
            leaves = subdivisionLeafModels(model->mesh, model->subdivision, surface.mode);
            surface_ = surface.summary();
            triangles = model->mesh.triangleCount();
            stats = model->subdivision.stats;
            params = model->params;
        }
        camera_ = builtinCameraScene(source_, options_);
        for (LocalBsp& leaf : leaves) {
            auto id = engine.addModel(std::move(leaf));
            if (!id) return Error{id.error().message};
            auto h = engine.addObject(*id, Transform{}, true);
            if (!h) return Error{h.error().message};
        }
        char line[512];
        std::snprintf(line, sizeof line,
                      "%s subdivided by %s (at most %u triangles per leaf, depth %u%s)%s: %zu triangles, %u nodes "
                      "(%u inner, %u leaves = objects), deepest leaf %u, largest leaf %u, built in %.0f ms\n"
                      "subdivision method=%s nodes=%u inner=%u leaves=%u depth=%u build_ms=%.1f triangles=%zu",
                      source_.c_str(), toString(params.method), params.maxLeafTriangles, params.maxDepth,
                      params.collapseTo ? (", collapsed to " + std::to_string(params.collapseTo) + "-ary").c_str() : "",
                      file_.empty() ? "" : (" (read from " + file_ + ")").c_str(), triangles, stats.nodes, stats.inner,
                      stats.leaves, stats.depth, stats.largestLeaf, stats.buildMs, toString(params.method), stats.nodes,
                      stats.inner, stats.leaves, stats.depth, stats.buildMs, triangles);
        description_ = std::string(line) + "\nsurface: " + surface_;
        setupMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        return {};
    }

    Status update(Engine&, std::uint64_t) override { return {}; }

    Camera camera(std::uint64_t frame, float aspect) const override {
        return camera_ ? camera_->camera(frame, aspect) : staticModelCamera(bounds_, walkthrough_, frame, aspect);
    }

    std::uint64_t defaultFrames() const override {
        if (camera_) return camera_->defaultFrames();
        if (auto builtin = builtinCameraScene(source_, options_)) return builtin->defaultFrames();
        return kStaticModelFrames;
    }

private:
    std::string source_, file_, name_, description_, surface_;
    SceneOptions options_;
    std::unique_ptr<DemoScene> camera_;
    Aabb bounds_;
    bool walkthrough_ = false;
};

}  // namespace

std::unique_ptr<DemoScene> builtinCameraScene(const std::string& source, const SceneOptions& o) {
    if (source == "powerplant") return makePowerPlant(o.plant);
    if (source == "city") return makeCity(o.city);
    return nullptr;
}

std::uint64_t builtinHash(const std::string& source, const SceneOptions& o) {
    if (source == "powerplant") return powerPlantParamsHash(o.plant);
    if (source == "city") return cityParamsHash(o.city);
    return 0;
}

Expected<StaticSoup> loadStaticSoup(const std::string& nameOrPath, const SceneOptions& options) {
    StaticSoup out;
    out.source = nameOrPath;
    out.sourceHash = builtinHash(nameOrPath, options);
    Expected<Scene> scene = Error{""};
    if (nameOrPath == "powerplant" || nameOrPath == "city") {
        ProgressBar progress("generating " + nameOrPath, 1.0);
        auto g = nameOrPath == "powerplant" ? generatePowerPlant(options.plant, &progress) : generateCity(options.city, &progress);
        progress.finish();
        if (!g) return g.error();
        scene = toScene(g.take());
    } else if (std::filesystem::is_directory(nameOrPath)) {
        auto g = loadSceneDir(nameOrPath, nullptr);
        if (!g) return g.error();
        scene = toScene(g.take());
    } else {
        scene = loadScene(nameOrPath);
        if (!scene) return scene.error();
    }
    out.mesh = flattenScene(*scene, stem(nameOrPath));
    return out;
}

Expected<SubdivisionParams> toSubdivisionParams(const SubdivideOptions& o) {
    auto method = parseSubdivisionMethod(o.method);
    if (!method) return Error{"--method: " + method.error().message};
    SubdivisionParams p;
    p.method = *method;
    p.maxLeafTriangles = o.maxTriangles;
    p.maxDepth = o.maxDepth;
    p.collapseTo = o.collapseTo;
    p.threads = o.threads;
    if (Status s = validateSubdivisionParams(p); !s) return Error{"subdivide: " + s.message()};
    return p;
}

Expected<SubdividedModel> subdivideStaticScene(const std::string& nameOrPath, const SceneOptions& options) {
    auto params = toSubdivisionParams(options.subdivide);
    if (!params) return params.error();
    auto soup = loadStaticSoup(nameOrPath, options);
    if (!soup) return soup.error();
    SubdividedModel m;
    m.mesh = std::move(soup->mesh);
    m.surface = orientSurface(m.mesh);  // before subdividing: the model file keeps the oriented triangles
    m.source = soup->source;
    m.sourceHash = soup->sourceHash;
    m.params = *params;
    auto sub = subdivide(m.mesh, m.params);
    if (!sub) return Error{nameOrPath + ": " + sub.error().message};
    m.subdivision = sub.take();
    applyTriangleOrder(m.mesh, m.subdivision);
    return m;
}

std::unique_ptr<DemoScene> makeSubdividedScene(const std::string& nameOrPath, const SceneOptions& options) {
    return std::make_unique<SubdividedScene>(nameOrPath, std::string(), options);
}

std::unique_ptr<DemoScene> makeSubdivisionFileScene(const std::string& path, const SceneOptions& options) {
    return std::make_unique<SubdividedScene>(std::string(), path, options);
}

}  // namespace dyncull
