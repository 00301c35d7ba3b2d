// The 300-bunny swarm: the dynamic test scene of the two-level BSP paper (section 4):
// N copies of one mesh with one shared local BSP, placed densely in a box, moving on
// straight lines with seeded velocities and interpenetrating freely; the camera flies a
// fixed path through and around the swarm.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/objects/hole_capping.hpp"
#include "dyncull/loaders/loaders.hpp"
#include "dyncull/objects/loop_subdivision.hpp"
#include "dyncull/objects/motion.hpp"

namespace dyncull {
namespace {

namespace fs = std::filesystem;

std::string fmt(float v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", static_cast<double>(v));
    return buf;
}

/// Centres the mesh on the origin and scales it so its longest side is `size`.
void normalise(Mesh& mesh, float size) {
    const Aabb b = mesh.bounds();
    const float longest = std::max({b.extent().x, b.extent().y, b.extent().z});
    const float s = longest > 0.0f ? size / longest : 1.0f;
    const glm::vec3 c = b.center();
    for (glm::vec3& p : mesh.positions) p = (p - c) * s;
}

class BunnySwarm final : public DemoScene {
public:
    explicit BunnySwarm(const BunnySwarmOptions& o)
        : o_(o),
          motion_(o.count, Aabb::fromMinMax(glm::vec3(-0.5f * o.box), glm::vec3(0.5f * o.box)), o.speed,
                  // Margin: half the bunny's longest side keeps every bunny's centre far enough
                  // from the walls that it stays (mostly) inside the box.
                  0.5f * o.bunnySize, o.seed),
          path_(makePath(o)) {}

    std::string name() const override { return "bunnies"; }
    std::string description() const override { return description_; }

    Status populate(Engine& engine) override {
        const auto t0 = std::chrono::steady_clock::now();
        auto bunny = prepareBunnyMesh(o_);
        if (!bunny) return Error{bunny.error().message};
        LocalBspParams bspParams;
        bspParams.maxLeafTriangles = o_.leafTriangles;
        bspParams.faces = o_.faces;
        bspParams.optimizeOrder = o_.optimizeOrder;
        bspParams.clusterOrder = o_.clusterOrder;
        auto model = engine.addModel(bunny->mesh, bspParams);
        if (!model) return Error{model.error().message};
        const LocalBsp& bsp = engine.model(*model);
        for (std::uint32_t i = 0; i < o_.count; ++i) {
            auto h = engine.addObject(*model, transformAt(i, 0));
            if (!h) return Error{h.error().message};
            handles_.push_back(*h);
        }
        description_ = "bunny mesh: " + bunny->choice.path + " (" + std::to_string(bunny->loadedTriangles) + " triangles" +
                       (bunny->choice.subdivided ? ", 2 levels of Loop subdivision -> " + std::to_string(bunny->subdividedTriangles)
                                                 : std::string()) +
                       (bunny->holesCapped ? ", " + std::to_string(bunny->holesCapped) + " holes capped with " +
                                                 std::to_string(bunny->cappingTriangles) + " triangles"
                                           : std::string()) +
                       "; drawn " + (bsp.faces == FaceMode::CullBack ? "with back faces culled" : "two-sided") +
                       "); local BSP: " + std::to_string(bsp.stats.leaves) + " parts, " +
                       std::to_string(bsp.stats.trianglesAfter) + " triangles; " + std::to_string(o_.count) +
                       " bunnies in a box of side " + fmt(o_.box) + ", bunny size " + fmt(o_.bunnySize);
        setupMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        return {};
    }

    Status update(Engine& engine, std::uint64_t frame) override {
        for (std::uint32_t i = 0; i < handles_.size(); ++i)
            if (Status s = engine.setTransform(handles_[i], transformAt(i, frame)); !s) return s;
        return {};
    }

    Camera camera(std::uint64_t frame, float aspect) const override {
        Camera c;
        c.aspect = aspect;
        c.fovYRadians = 1.0f;
        c.nearPlane = 0.05f;
        c.farPlane = 8.0f * o_.box + 2.0f * o_.orbit;
        path_.apply(frame, c);
        return c;
    }

    std::uint64_t defaultFrames() const override { return path_.frameCount(); }

private:
    Transform transformAt(std::uint32_t i, std::uint64_t frame) const {
        Transform t;
        t.translation = motion_.position(i, frame);
        const glm::vec4 q = motion_.orientation(i);
        t.rotation = glm::quat(q.x, q.y, q.z, q.w);  // orientation() is (w, x, y, z)
        return t;
    }

    static CameraPath makePath(const BunnySwarmOptions& o) {
        const float b = o.box;
        if (o.orbit > 0.0f) return CameraPath::orbit(glm::vec3(0.0f), o.orbit, 0.25f * o.box, o.frames);
        // Approach from outside, dive through the swarm, come out the far side, then swing
        // around it and back to the start (a loop, so any frame count is valid).
        std::vector<glm::vec3> eyes = {
            {0.15f * b, 0.35f * b, 1.5f * b},   {0.1f * b, 0.1f * b, 0.55f * b},  {-0.05f * b, 0.0f, 0.1f * b},
            {-0.15f * b, -0.05f * b, -0.3f * b}, {-0.35f * b, 0.1f * b, -0.9f * b}, {-1.2f * b, 0.4f * b, -0.6f * b},
            {-1.3f * b, 0.5f * b, 0.8f * b},
        };
        std::vector<glm::vec3> targets = {
            {0.0f, 0.0f, 0.0f},         {-0.05f * b, 0.0f, -0.3f * b}, {-0.15f * b, -0.05f * b, -0.6f * b},
            {-0.3f * b, 0.0f, -1.0f * b}, {0.0f, 0.0f, 0.0f},           {0.0f, 0.0f, 0.0f},
            {0.0f, 0.0f, 0.0f},
        };
        const std::uint32_t perSegment = std::max<std::uint32_t>(1, o.frames / static_cast<std::uint32_t>(eyes.size()));
        return CameraPath(std::move(eyes), std::move(targets), perSegment, true);
    }

    BunnySwarmOptions o_;
    BouncingMotion motion_;
    CameraPath path_;
    std::vector<ObjectHandle> handles_;
    std::string description_;
};

}  // namespace

Expected<BunnyMeshChoice> findBunnyMesh(const BunnySwarmOptions& o) {
    if (!o.meshPath.empty()) {
        if (!fs::exists(o.meshPath)) return Error{o.meshPath + ": mesh file not found"};
        return BunnyMeshChoice{o.meshPath, false};
    }
    std::string dir = o.assetsDir;
    if (dir.empty()) {
        const char* env = std::getenv("DYNCULL_ASSETS");
        dir = env && *env ? env : "assets";
    }
    const fs::path full = fs::path(dir) / "bun_zipper.ply";
    if (fs::exists(full)) return BunnyMeshChoice{full.string(), false};
    const fs::path npm = fs::path(dir) / "bunny_npm.ply";
    if (fs::exists(npm)) return BunnyMeshChoice{npm.string(), true};
    // The setup script always writes ./assets/bunny_npm.ply; fall back to it when a
    // different asset directory lacks both files.
    if (fs::exists("assets/bunny_npm.ply")) return BunnyMeshChoice{"assets/bunny_npm.ply", true};
    return Error{"no bunny mesh: looked for " + full.string() + " and " + npm.string() +
                 " (run scripts/setup.sh, or pass --mesh PATH or --assets DIR)"};
}

Expected<BunnyMesh> prepareBunnyMesh(const BunnySwarmOptions& options) {
    auto choice = findBunnyMesh(options);
    if (!choice) return Error{choice.error().message};
    auto scene = loadScene(choice->path);
    if (!scene) return Error{scene.error().message};
    if (scene->meshes.empty()) return Error{choice->path + ": no mesh"};
    BunnyMesh b;
    b.choice = *choice;
    b.mesh = std::move(scene->meshes[0]);
    b.loadedTriangles = b.mesh.triangleCount();
    if (choice->subdivided) b.mesh = loopSubdivide(b.mesh, 2);
    normalise(b.mesh, options.bunnySize);
    b.subdividedTriangles = b.mesh.triangleCount();
    if (!options.keepHoles) {
        const HoleCapping capped = capHoles(b.mesh, b.mesh.indices.size());
        b.holesCapped = capped.holes;
        b.cappingTriangles = capped.triangles;
    }
    return b;
}

std::unique_ptr<DemoScene> makeBunnySwarm(const BunnySwarmOptions& options) {
    return std::make_unique<BunnySwarm>(options);
}

}  // namespace dyncull
