// Any PLY/OBJ/glTF file as a static scene through the same pipeline as dynamic ones:
// one local BSP per mesh, one static object per instance, an automatic camera path.
#include <unistd.h>

#include <chrono>
#include <filesystem>

#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/loaders/loaders.hpp"
#include "dyncull/objects/motion.hpp"
#include "file_camera.hpp"

namespace dyncull {

Camera staticModelCamera(const Aabb& bounds, bool walkthrough, std::uint64_t frame, float aspect) {
    Camera c = Camera::framing(bounds, aspect);
    const glm::vec3 centre = bounds.center();
    const glm::vec3 e = bounds.extent();
    const float radius = 0.5f * glm::length(e);
    if (walkthrough) {
        const WalkAxes w = walkAxes(bounds);
        const std::vector<glm::vec3> targets = {w.base + 0.2f * w.along, w.base + 0.7f * w.along - w.side,
                                                w.base + 1.2f * w.along, w.base + 2.0f * w.along + w.side};
        CameraPath(walkEyes(bounds), targets, kStaticModelFrames / 3, false).apply(frame, c);
        c.nearPlane = 1e-3f * radius;
        c.farPlane = 3.0f * radius;
    } else {
        CameraPath::orbit(centre, 1.6f * radius / std::sin(0.5f * c.fovYRadians) * 0.6f, 0.35f * radius, kStaticModelFrames)
            .apply(frame, c);
        c.nearPlane = 1e-2f * radius;
        c.farPlane = 6.0f * radius;
    }
    return c;
}

bool staticModelWalkthrough(const Mesh& soup) {
    Scene scene;
    scene.meshes.push_back(soup);
    scene.instances.push_back({0, glm::mat4(1.0f), {}});
    return chooseFileCamera(scene, soup.bounds()).walkthrough;
}

namespace {

class FileScene final : public DemoScene {
public:
    explicit FileScene(std::string path) : path_(std::move(path)) {}

    std::string name() const override { return std::filesystem::path(path_).stem().string(); }
    std::string description() const override { return description_; }

    Status populate(Engine& engine) override {
        const auto t0 = std::chrono::steady_clock::now();
        auto scene = loadScene(path_);
        if (!scene) return Error{scene.error().message};
        std::vector<ModelId> models;
        // Before anything reaches the engine: a model no camera can frame is bad input.
        if (Status s = checkFramable(scene->worldBounds()); !s) return Error{path_ + ": cannot frame the model: " + s.message()};
        std::size_t after = 0;
        for (const Mesh& m : scene->meshes) {
            auto id = engine.addModel(m);
            if (!id) return Error{path_ + ": " + id.error().message};
            models.push_back(*id);
            after += engine.model(*id).stats.trianglesAfter;
        }
        for (const Instance& inst : scene->instances) {
            if (Status s = validateMatrix(inst.transform); !s) return Error{path_ + ": instance '" + inst.name + "': " + s.message()};
            auto h = engine.addObject(models[inst.mesh], Transform::fromMatrix(inst.transform), true);
            if (!h) return Error{path_ + ": " + h.error().message};
        }
        bounds_ = scene->worldBounds();
        const FileCameraChoice choice = chooseFileCamera(*scene, bounds_);
        walkthrough_ = choice.walkthrough;
        description_ = path_ + ": " + std::to_string(scene->instances.size()) + " objects, " +
                       std::to_string(scene->meshes.size()) + " meshes, " +
                       std::to_string(scene->instancedTriangleCount()) + " triangles drawn (" +
                       std::to_string(after) + " after local-BSP splitting per mesh); camera: " +
                       (walkthrough_ ? "walkthrough" : "orbit") +
                       (choice.elongated ? " (elongated; " + std::to_string(int(100.0 * choice.enclosedFraction + 0.5)) +
                                               "% of rays from the walk path meet a front face)"
                                         : std::string(" (compact)"));
        setupMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        return {};
    }

    Status update(Engine&, std::uint64_t) override { return {}; }

    Camera camera(std::uint64_t frame, float aspect) const override {
        return staticModelCamera(bounds_, walkthrough_, frame, aspect);
    }

    std::uint64_t defaultFrames() const override { return kStaticModelFrames; }

private:
    std::string path_;
    std::string description_;
    Aabb bounds_;
    bool walkthrough_ = false;
};

}  // namespace

std::unique_ptr<DemoScene> makeFileScene(const std::string& path) { return std::make_unique<FileScene>(path); }

std::vector<std::string> builtinSceneNames() { return {"bunnies", "powerplant", "city"}; }

Expected<std::unique_ptr<DemoScene>> makeScene(const std::string& nameOrPath, const BunnySwarmOptions& bunny) {
    SceneOptions options;
    options.bunny = bunny;
    return makeScene(nameOrPath, options);
}

Expected<std::unique_ptr<DemoScene>> makeScene(const std::string& nameOrPath, const SceneOptions& options) {
    // Before the built-in names: --subdivide applies to the power plant and the city too.
    if (std::filesystem::path(nameOrPath).extension() == ".dsub") return makeSubdivisionFileScene(nameOrPath, options);
    if (std::filesystem::path(nameOrPath).extension() == ".dnodes") {
        if (options.stream.memoryMb == 0 && !options.stream.inCore)
            return Error{nameOrPath + ": a streamed model needs --memory-mb N (or --in-core to read it whole)", ErrorCode::BadArgument};
        return makeStreamedScene(nameOrPath, options);
    }
    if (options.stream.memoryMb > 0) {
        if (nameOrPath != "powerplant" && nameOrPath != "city")
            return Error{"--memory-mb streams powerplant, city or a .dnodes file from `dyncull subdivide --memory-mb`",
                         ErrorCode::BadArgument};
        char exe[4096];
        const ssize_t n = ::readlink("/proc/self/exe", exe, sizeof exe - 1);
        if (n <= 0) return Error{"cannot find this program to preprocess " + nameOrPath, ErrorCode::Io};
        exe[n] = '\0';
        return makeStreamedBuiltin(nameOrPath, options, exe);
    }
    if (!options.subdivide.method.empty()) {
        if (nameOrPath == "bunnies") return Error{"--subdivide: the bunny swarm is dynamic; subdivide a static scene"};
        if (!std::filesystem::exists(nameOrPath) && nameOrPath != "powerplant" && nameOrPath != "city")
            return Error{nameOrPath + ": not a built-in scene and no such file"};
        return makeSubdividedScene(nameOrPath, options);
    }
    if (nameOrPath == "bunnies") return makeBunnySwarm(options.bunny);
    if (nameOrPath == "powerplant" && !options.sceneDir.empty()) {
        if (!std::filesystem::is_directory(options.sceneDir)) return Error{options.sceneDir + ": --scene-dir is not a directory"};
        return makeSceneDir(options.sceneDir);
    }
    if (nameOrPath == "powerplant") {
        PowerPlantOptions plant = options.plant;
        plant.cache = options.cache;
        return makePowerPlant(plant);
    }
    if (nameOrPath == "city") {
        CityOptions city = options.city;
        city.cache = options.cache;
        return makeCity(city);
    }
    if (std::filesystem::is_directory(nameOrPath)) return makeSceneDir(nameOrPath);
    if (std::filesystem::exists(nameOrPath)) return makeFileScene(nameOrPath);
    std::string names;
    for (const std::string& n : builtinSceneNames()) names += (names.empty() ? "" : ", ") + n;
    return Error{nameOrPath + ": not a built-in scene (" + names + ") and no such file"};
}

}  // namespace dyncull
