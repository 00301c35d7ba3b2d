// A directory of PLY/OBJ parts (e.g. the UNC Power Plant's sections) as one static scene:
// each file becomes one mesh and one object, in sorted order so runs are reproducible.
#include <algorithm>
#include <chrono>
#include <filesystem>

#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/loaders/loaders.hpp"
#include "dyncull/objects/file_extension.hpp"
#include "dyncull/objects/motion.hpp"
#include "generators.hpp"

namespace dyncull {
namespace {

namespace fs = std::filesystem;

bool isPart(const fs::path& p) {
    const std::string ext = lowercaseExtension(p);
    return ext == ".ply" || ext == ".obj";
}

/// Merges every instance of a loaded file into one world-space mesh.
Mesh flatten(const Scene& scene, const std::string& name) {
    Mesh out;
    out.name = name;
    for (const Instance& inst : scene.instances) {
        const Mesh& m = scene.meshes[inst.mesh];
        const std::uint32_t base = static_cast<std::uint32_t>(out.positions.size());
        const glm::mat3 normalMatrix = glm::transpose(glm::inverse(glm::mat3(inst.transform)));
        for (std::size_t i = 0; i < m.positions.size(); ++i) {
            out.positions.push_back(glm::vec3(inst.transform * glm::vec4(m.positions[i], 1.0f)));
            const glm::vec3 n = m.normals.empty() ? glm::vec3(0, 0, 1) : normalMatrix * m.normals[i];
            const float len = glm::length(n);
            out.normals.push_back(len > 0.0f && std::isfinite(len) ? n / len : glm::vec3(0, 0, 1));
        }
        for (std::uint32_t idx : m.indices) out.indices.push_back(base + idx);
    }
    return out;
}

class SceneDir final : public DemoScene {
public:
    explicit SceneDir(std::string dir) : dir_(std::move(dir)) {}

    std::string name() const override {
        const fs::path p = fs::path(dir_).lexically_normal();
        const std::string n = (p.has_filename() ? p.filename() : p.parent_path().filename()).string();
        return n.empty() ? "scene_dir" : n;
    }
    std::string description() const override { return description_; }

    Status populate(Engine& engine) override {
        const auto t0 = std::chrono::steady_clock::now();
        ProgressBar progress("loading " + dir_, 1.0);
        auto generated = loadSceneDir(dir_, &progress);
        if (!generated) return Error{generated.error().message};
        std::size_t tris = 0;
        for (const Mesh& m : generated->meshes) tris += m.triangleCount();
        for (const PlacedObject& o : generated->objects) {
            const Aabb b = generated->meshes[o.model].bounds();
            bounds_.extend(b);
        }
        const std::size_t files = generated->objects.size();
        progress.restart("local BSPs (2 threads)", static_cast<double>(tris));
        auto prepared = prepareScene(generated.take(), 2, &progress);
        progress.finish();
        if (!prepared) return Error{prepared.error().message};
        const std::size_t after = prepared->instancedTriangles();
        if (Status s = populateEngine(engine, prepared.take()); !s) return s;
        description_ = dir_ + ": " + std::to_string(files) + " files as objects, " + std::to_string(tris) + " triangles (" +
                       std::to_string(after) + " after local-BSP splitting)";
        setupMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        return {};
    }

    Status update(Engine&, std::uint64_t) override { return {}; }

    Camera camera(std::uint64_t frame, float aspect) const override {
        Camera c = Camera::framing(bounds_, aspect);
        const glm::vec3 centre = bounds_.center();
        const float radius = std::max(0.5f * glm::length(bounds_.extent()), 1e-3f);
        // Orbit outside, slightly above, close enough that the parts fill the view.
        CameraPath::orbit(centre, 1.3f * radius, 0.3f * radius, kFrames).apply(frame, c);
        c.nearPlane = 1e-3f * radius;
        c.farPlane = 4.0f * radius;
        return c;
    }

    std::uint64_t defaultFrames() const override { return kFrames; }

private:
    static constexpr std::uint32_t kFrames = 240;
    std::string dir_;
    std::string description_;
    Aabb bounds_;
};

}  // namespace

Expected<GeneratedScene> loadSceneDir(const std::string& dir, ProgressBar* progress) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) return Error{dir + ": not a directory"};
    std::vector<fs::path> files;
    for (fs::recursive_directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec), end; !ec && it != end;
         it.increment(ec))
        if (it->is_regular_file(ec) && isPart(it->path())) files.push_back(it->path());
    if (ec) return Error{dir + ": cannot list: " + ec.message()};
    if (files.empty()) return Error{dir + ": no .ply or .obj files"};
    std::sort(files.begin(), files.end(), [&](const fs::path& a, const fs::path& b) {
        return a.lexically_relative(dir).generic_string() < b.lexically_relative(dir).generic_string();
    });
    GeneratedScene out;
    for (const fs::path& f : files) {
        auto scene = loadScene(f);
        if (!scene) return Error{scene.error().message};
        Mesh m = flatten(*scene, f.lexically_relative(dir).generic_string());
        if (std::string why = validateMesh(m); !why.empty()) return Error{f.string() + ": " + why};
        out.objects.push_back({static_cast<std::uint32_t>(out.meshes.size()), Transform{}, true});
        out.meshes.push_back(std::move(m));
        if (progress) progress->advance(1.0 / static_cast<double>(files.size()));
    }
    return out;
}

std::unique_ptr<DemoScene> makeSceneDir(const std::string& dir) { return std::make_unique<SceneDir>(dir); }

}  // namespace dyncull
