// Generated scenes before and after preprocessing, and the pipeline between them:
// generate meshes + placements -> build one local BSP per mesh on worker threads ->
// (cache on disk) -> upload into an Engine. Shared by the power plant and the city.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "dyncull/bsp/local_bsp.hpp"
#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/objects/mesh.hpp"
#include "dyncull/objects/transform.hpp"
#include "dyncull/demos/progress_bar.hpp"

namespace dyncull {

/// One object: an index into the scene's meshes/models and its object-to-world transform.
struct PlacedObject {
    std::uint32_t model = 0;
    Transform transform;
    bool isStatic = true;
};

/// Output of a generator: owns the meshes (object space, metres, Y up) and placements.
struct GeneratedScene {
    std::vector<Mesh> meshes;
    std::vector<PlacedObject> objects;
    std::size_t instancedTriangles() const;  ///< sum over objects of their mesh's triangles
};

/// A generated scene with its local BSPs built (what the cache stores).
struct PreparedScene {
    std::vector<LocalBsp> models;
    std::vector<PlacedObject> objects;
    std::size_t instancedTriangles() const;  ///< after local-BSP splitting
};

/// Builds every mesh's local BSP (default parameters) on `threads` worker threads, largest
/// meshes first; consumes `scene.meshes`. Reports triangles done to `progress` (may be null).
Expected<PreparedScene> prepareScene(GeneratedScene scene, unsigned threads, ProgressBar* progress);

/// Moves the models into `engine` and adds every object. Errors on a bad placement.
Status populateEngine(Engine& engine, PreparedScene scene);

/// The cache directory: `dir` if set, else $DYNCULL_CACHE, else out/cache.
std::filesystem::path cacheDirectory(const SceneCacheOptions& options);

/// Reads `<cache dir>/<fileName>` when enabled and valid for `paramsHash`; otherwise (with
/// one line on stderr saying why, unless the file was simply absent) runs `generate`,
/// prepares the scene and writes the cache. `log` receives "cache: loaded/wrote ..." text.
Expected<PreparedScene> loadOrPrepare(const SceneCacheOptions& cache, const std::string& fileName,
                                      std::uint64_t paramsHash, unsigned threads,
                                      const std::function<Expected<GeneratedScene>(ProgressBar&)>& generate,
                                      std::string* log);

/// Base of the generated demo scenes: populate() loads or generates, then uploads.
class GeneratedDemoScene : public DemoScene {
public:
    std::string description() const override { return description_; }
    Status populate(Engine& engine) override;
    Status update(Engine&, std::uint64_t) override { return {}; }

protected:
    virtual std::string cacheFileName() const = 0;
    virtual std::uint64_t paramsHash() const = 0;
    virtual const SceneCacheOptions& cacheOptions() const = 0;
    virtual unsigned threads() const = 0;
    virtual Expected<GeneratedScene> generate(ProgressBar& progress) const = 0;

    std::string description_;
    std::size_t objectCount_ = 0, modelCount_ = 0, triangles_ = 0;
};

}  // namespace dyncull
