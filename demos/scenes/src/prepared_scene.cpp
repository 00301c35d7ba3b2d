// Local-BSP preprocessing of generated scenes on worker threads, and the load-or-build
// path through the on-disk cache.
#include "prepared_scene.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <optional>
#include <thread>

#include "scene_cache.hpp"

namespace dyncull {

namespace fs = std::filesystem;

std::size_t GeneratedScene::instancedTriangles() const {
    std::size_t n = 0;
    for (const PlacedObject& o : objects) n += meshes[o.model].triangleCount();
    return n;
}

std::size_t PreparedScene::instancedTriangles() const {
    std::size_t n = 0;
    for (const PlacedObject& o : objects) n += models[o.model].mesh.triangleCount();
    return n;
}

Expected<PreparedScene> prepareScene(GeneratedScene scene, unsigned threads, ProgressBar* progress) {
    const std::size_t n = scene.meshes.size();
    for (const PlacedObject& o : scene.objects)
        if (o.model >= n) return Error{"generated scene: object refers to mesh " + std::to_string(o.model) + " of " + std::to_string(n)};
    // Largest first, so the two threads finish together instead of one ending on a giant.
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        return scene.meshes[a].triangleCount() > scene.meshes[b].triangleCount();
    });
    std::vector<std::optional<LocalBsp>> built(n);
    std::vector<std::string> errors(n);
    std::atomic<std::size_t> next{0};
    auto work = [&] {
        for (std::size_t k; (k = next.fetch_add(1)) < n;) {
            const std::uint32_t i = order[k];
            const double tris = static_cast<double>(scene.meshes[i].triangleCount());
            auto bsp = buildLocalBsp(scene.meshes[i]);
            if (bsp) built[i] = bsp.take();
            else errors[i] = scene.meshes[i].name + ": " + bsp.error().message;
            scene.meshes[i] = Mesh{};  // free the input as we go (peak memory)
            if (progress) progress->advance(tris);
        }
    };
    threads = std::max(1u, threads);
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
    for (const std::string& e : errors)
        if (!e.empty()) return Error{e};
    PreparedScene out;
    out.models.reserve(n);
    for (auto& b : built) out.models.push_back(std::move(*b));
    out.objects = std::move(scene.objects);
    return out;
}

Status populateEngine(Engine& engine, PreparedScene scene) {
    std::vector<ModelId> ids;
    ids.reserve(scene.models.size());
    for (LocalBsp& bsp : scene.models) {
        auto id = engine.addModel(std::move(bsp));
        if (!id) return Error{id.error().message};
        ids.push_back(*id);
    }
    for (const PlacedObject& o : scene.objects) {
        if (o.model >= ids.size()) return Error{"scene: object refers to model " + std::to_string(o.model)};
        auto h = engine.addObject(ids[o.model], o.transform, o.isStatic);
        if (!h) return Error{h.error().message};
    }
    return {};
}

fs::path cacheDirectory(const SceneCacheOptions& options) {
    if (!options.dir.empty()) return options.dir;
    const char* env = std::getenv("DYNCULL_CACHE");
    if (env && *env) return env;
    return fs::path("out") / "cache";
}

Expected<PreparedScene> loadOrPrepare(const SceneCacheOptions& cache, const std::string& fileName,
                                      std::uint64_t paramsHash, unsigned threads,
                                      const std::function<Expected<GeneratedScene>(ProgressBar&)>& generate,
                                      std::string* log) {
    const fs::path file = cacheDirectory(cache) / fileName;
    if (cache.enabled) {
        std::error_code ec;
        if (fs::exists(file, ec)) {
            const auto t0 = std::chrono::steady_clock::now();
            auto loaded = readSceneCache(file, paramsHash);
            if (loaded) {
                if (log)
                    *log = "cache: loaded " + file.string() + " in " +
                           std::to_string(static_cast<int>(std::chrono::duration<double, std::milli>(
                                                               std::chrono::steady_clock::now() - t0)
                                                               .count())) +
                           " ms";
                return loaded;
            }
            std::fprintf(stderr, "%s; rebuilding\n", loaded.error().message.c_str());
        }
    }
    ProgressBar progress("generating " + fileName, 1.0);
    auto generated = generate(progress);
    if (!generated) return generated.error();
    std::size_t tris = 0;
    for (const Mesh& m : generated->meshes) tris += m.triangleCount();
    progress.restart("local BSPs (" + std::to_string(threads) + " threads)", static_cast<double>(tris));
    auto prepared = prepareScene(generated.take(), threads, &progress);
    progress.finish();
    if (!prepared) return prepared.error();
    if (cache.enabled) {
        std::error_code ec;
        fs::create_directories(file.parent_path(), ec);
        if (Status s = writeSceneCache(file, *prepared, paramsHash); !s)
            std::fprintf(stderr, "warning: %s\n", s.message().c_str());
        else if (log)
            *log = "cache: wrote " + file.string();
    } else if (log) {
        *log = "cache: disabled";
    }
    return prepared;
}

Status GeneratedDemoScene::populate(Engine& engine) {
    const auto t0 = std::chrono::steady_clock::now();
    std::string log;
    auto prepared = loadOrPrepare(cacheOptions(), cacheFileName(), paramsHash(), threads(),
                                  [this](ProgressBar& p) { return generate(p); }, &log);
    if (!prepared) return Error{prepared.error().message};
    objectCount_ = prepared->objects.size();
    modelCount_ = prepared->models.size();
    triangles_ = prepared->instancedTriangles();
    std::size_t generated = 0, culledModels = 0;
    for (const PlacedObject& o : prepared->objects) generated += prepared->models[o.model].stats.trianglesBefore;
    for (const LocalBsp& m : prepared->models) culledModels += m.faces == FaceMode::CullBack;
    if (Status s = populateEngine(engine, prepared.take()); !s) return s;
    description_ = name() + ": " + std::to_string(objectCount_) + " objects, " + std::to_string(modelCount_) +
                   " meshes, " + std::to_string(generated) + " triangles (" + std::to_string(triangles_) +
                   " after local-BSP splitting); " + std::to_string(culledModels) + " of " +
                   std::to_string(modelCount_) + " meshes closed and drawn with back faces culled, the rest two-sided; " + log;
    setupMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return {};
}

}  // namespace dyncull
