// A model larger than memory as a scene (issue 16): a .dnodes file from `dyncull subdivide
// --memory-mb`, or the power plant / city preprocessed out of core on first use, drawn by
// StreamedObjects under the main-memory and GL-buffer budgets of StreamOptions.
// Paper: Out-of-core interactive display of large meshes using an oriented bounding
// box-based hardware depth query, sections 4-5.
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/engine/heap_tuning.hpp"
#include "generators.hpp"
#include "prepared_scene.hpp"

namespace dyncull {
namespace {

class StreamedScene final : public DemoScene {
public:
    StreamedScene(std::string path, const SceneOptions& options) : path_(std::move(path)), options_(options) {
        name_ = std::filesystem::path(path_).stem().string();
    }

    std::string name() const override { return name_; }
    std::string description() const override { return description_; }

    Status populate(Engine& engine) override {
        const auto t0 = std::chrono::steady_clock::now();
        const StreamOptions& so = options_.stream;
        auto late = parseStreamLate(so.late);
        if (!late) return Error{"--stream-late: " + late.error().message, ErrorCode::BadArgument};
        StreamingOptions opts;
        opts.memoryBytes = so.inCore ? 0 : std::size_t{so.memoryMb} << 20;
        opts.gpuBytes = so.inCore ? 0 : std::size_t{so.gpuMemoryMb} << 20;
        opts.late = late_ = *late;
        auto objects = StreamedObjects::create(engine, path_, opts);
        if (!objects) return objects.error();
        objects_ = objects.take();
        const StreamedModel& m = objects_->model();
        const std::string cameraSource = so.cameraOf.empty() ? m.source : so.cameraOf;
        if (so.cameraOf.empty() && builtinHash(m.source, options_) != m.sourceHash)
            return Error{path_ + ": made from '" + m.source + "' with other generator options; pass the --plant-*/--city-* "
                         "options it was made with"};
        camera_ = builtinCameraScene(cameraSource, options_);
        if (!so.cameraOf.empty() && !camera_) return Error{"--camera-of: '" + so.cameraOf + "' is not powerplant or city"};
        bounds_ = m.nodes[0].box;
        char line[512];
        std::snprintf(line, sizeof line,
                      "%s: %llu triangles in %zu leaves (objects), %.1f MB of geometry streamed from %s; budgets %s, "
                      "late leaves: %s; camera: %s",
                      path_.c_str(), static_cast<unsigned long long>(m.triangles()), m.leaves.size(),
                      static_cast<double>(m.geometryBytes) / (1024.0 * 1024.0), m.geometryPath.c_str(),
                      so.inCore ? "none (in core: every leaf read at start)"
                                : (std::to_string(so.memoryMb) + " MB main memory, " +
                                   (so.gpuMemoryMb ? std::to_string(so.gpuMemoryMb) + " MB" : std::string("unlimited")) +
                                   " GL buffers")
                                      .c_str(),
                      toString(opts.late), camera_ ? cameraSource.c_str() : "automatic orbit of the bounds");
        description_ = line;
        setupMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        return {};
    }

    Status update(Engine&, std::uint64_t) override { return {}; }
    void beginFrame(const Camera& camera) override { objects_->beginFrame(camera); }
    void setReferencePass(bool on) override { objects_->setLate(on ? StreamLate::Wait : late_); }
    bool referencePassLoads() const override { return true; }
    Expected<std::optional<StreamingFrameStats>> endFrame() override {
        auto s = objects_->endFrame();
        // The dyncull program keeps freed heap memory for llvmpipe's sake; the leaves this
        // frame evicted would stay resident in it (docs/BENCHMARKS.md, out of core).
        returnFreedHeapMemory();
        if (!s) return s.error();
        return std::optional<StreamingFrameStats>(*s);
    }

    std::function<bool(std::uint32_t, Mesh&)> truthGeometry() override {
        return [this](std::uint32_t slot, Mesh& out) {
            const auto leaf = objects_->leafOfSlot(slot);
            // A leaf that does not read is drawn as its box: the frame's own draw reports it.
            return leaf && objects_->readLeaf(*leaf, out).ok();
        };
    }

    Camera camera(std::uint64_t frame, float aspect) const override {
        return camera_ ? camera_->camera(frame, aspect) : staticModelCamera(bounds_, false, frame, aspect);
    }
    std::uint64_t defaultFrames() const override { return camera_ ? camera_->defaultFrames() : kStaticModelFrames; }

private:
    std::string path_, name_, description_;
    SceneOptions options_;
    std::unique_ptr<StreamedObjects> objects_;
    StreamLate late_ = StreamLate::Wait;
    std::unique_ptr<DemoScene> camera_;
    Aabb bounds_;
};

}  // namespace

std::unique_ptr<DemoScene> makeStreamedScene(const std::string& nodePath, const SceneOptions& options) {
    return std::make_unique<StreamedScene>(nodePath, options);
}

Expected<std::unique_ptr<DemoScene>> makeStreamedBuiltin(const std::string& name, const SceneOptions& options,
                                                          const std::string& exe) {
    const std::uint64_t hash = builtinHash(name, options);
    if (hash == 0) return Error{"--memory-mb streams powerplant, city or a .dnodes file, not '" + name + "'", ErrorCode::BadArgument};
    char file[96];
    std::snprintf(file, sizeof file, "%s_%016llx_%u.dnodes", name.c_str(), static_cast<unsigned long long>(hash),
                  options.subdivide.maxTriangles);
    const std::filesystem::path path = cacheDirectory(options.cache) / file;
    std::error_code ec;
    if (!options.cache.enabled || !std::filesystem::exists(path, ec) || !readStreamedModel(path)) {
        std::filesystem::create_directories(path.parent_path(), ec);
        // A child process preprocesses, so this one never holds the generated model.
        std::vector<std::string> args = {exe, "subdivide", name, "--memory-mb", "512", "--out", path.string(),
                                          "--max-tris", std::to_string(options.subdivide.maxTriangles),
                                          "--plant-seed", std::to_string(options.plant.seed),
                                          "--plant-size", std::to_string(options.plant.size),
                                          "--plant-detail", std::to_string(options.plant.detail),
                                          "--city-seed", std::to_string(options.city.seed),
                                          "--city-blocks", std::to_string(options.city.blocksX)};
        std::fprintf(stderr, "streaming %s: preprocessing once into %s\n", name.c_str(), path.c_str());
        std::fflush(stderr);
        std::vector<char*> argv;
        for (std::string& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        const pid_t pid = ::fork();
        if (pid < 0) return Error{"cannot start the preprocessing process", ErrorCode::Io};
        if (pid == 0) {
            ::execv(exe.c_str(), argv.data());
            ::_exit(127);
        }
        int status = 0;
        while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
        }
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
            return Error{"preprocessing " + name + " for streaming failed (" + exe + " subdivide exited with " +
                         std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status)) + ")"};
    }
    SceneOptions o = options;
    return makeStreamedScene(path.string(), o);
}

}  // namespace dyncull
