// Procedural city: a grid of blocks, one closed building per block (facade ledges and
// pilasters outside; floor slabs and furniture-like clutter inside, never visible through
// the closed walls, so occlusion culling should drop it), sidewalks, street lamps and
// parked cars; the camera walks the streets at eye height. Metres, Y up. Deterministic.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/objects/motion.hpp"
#include "generators.hpp"
#include "prepared_scene.hpp"
#include "procedural_mesh.hpp"
#include "scene_cache.hpp"

namespace dyncull {
namespace {

using procedural::MeshBuilder;
using procedural::Rng;

constexpr float kPi = 3.14159265358979f;
constexpr float kLot = 30.0f, kStreet = 14.0f, kPitch = kLot + kStreet;
constexpr float kFloorHeight = 3.5f;

Transform at(const glm::vec3& p, float yaw = 0.0f) {
    Transform t;
    t.translation = p;
    t.rotation = glm::angleAxis(yaw, glm::vec3(0, 1, 0));
    return t;
}

/// Street centre line west of block column i (x) or south of block row j (z).
float streetLine(int i) { return static_cast<float>(i) * kPitch - 0.5f * kStreet; }

void shell(MeshBuilder& b, Rng& rng, float w, float d, int floors) {
    const float h = kFloorHeight * static_cast<float>(floors), t = 0.3f;
    // Closed hollow box: four walls, roof, ground slab.
    b.box({0, 0, 0}, {w, t, d});
    b.box({0, 0, 0}, {w, h, t});
    b.box({0, 0, d - t}, {w, h, d});
    b.box({0, 0, t}, {t, h, d - t});
    b.box({w - t, 0, t}, {w, h, d - t});
    b.box({0, h - t, 0}, {w, h, d});
    for (int f = 1; f < floors; ++f) {  // ledges
        const float y = kFloorHeight * static_cast<float>(f);
        b.box({-0.15f, y, -0.15f}, {w + 0.15f, y + 0.2f, 0.0f});
        b.box({-0.15f, y, d}, {w + 0.15f, y + 0.2f, d + 0.15f});
        b.box({-0.15f, y, 0.0f}, {0.0f, y + 0.2f, d});
        b.box({w, y, 0.0f}, {w + 0.15f, y + 0.2f, d});
    }
    for (float x = 2.0f; x < w - 1.0f; x += 4.0f) {  // pilasters on the long faces
        b.box({x, 0, -0.25f}, {x + 0.4f, h, 0.0f});
        b.box({x, 0, d}, {x + 0.4f, h, d + 0.25f});
    }
    b.box({0, h, 0}, {w, h + 1.0f, 0.25f});  // parapet
    b.box({0, h, d - 0.25f}, {w, h + 1.0f, d});
    b.box({0, h, 0.25f}, {0.25f, h + 1.0f, d - 0.25f});
    b.box({w - 0.25f, h, 0.25f}, {w, h + 1.0f, d - 0.25f});
    for (int k = rng.range(1, 4); k > 0; --k) {  // rooftop units
        const float x = rng.uniform(1.0f, w - 4.0f), z = rng.uniform(1.0f, d - 4.0f);
        b.box({x, h, z}, {x + rng.uniform(1.5f, 3.0f), h + rng.uniform(1.0f, 2.2f), z + rng.uniform(1.5f, 3.0f)});
    }
    if (rng.chance(0.3f)) b.cylinder({w * 0.5f, h, d * 0.5f}, {w * 0.5f, h + 3.0f, d * 0.5f}, 1.5f, 16);
}

void desk(MeshBuilder& b, const glm::vec3& p, float yaw) {
    const glm::vec3 x{std::cos(yaw), 0, -std::sin(yaw)}, z{std::sin(yaw), 0, std::cos(yaw)}, y{0, 1, 0};
    b.orientedBox(p + y * 0.74f, x, y, z, {0.8f, 0.02f, 0.4f});
    for (float sx : {-0.75f, 0.75f})
        for (float sz : {-0.35f, 0.35f}) b.orientedBox(p + x * sx + z * sz + y * 0.36f, x, y, z, {0.025f, 0.36f, 0.025f});
    // Chair.
    const glm::vec3 c = p + z * 0.7f;
    b.orientedBox(c + y * 0.45f, x, y, z, {0.22f, 0.03f, 0.22f});
    b.orientedBox(c + z * 0.22f + y * 0.75f, x, y, z, {0.22f, 0.28f, 0.02f});
    b.orientedBox(c + y * 0.22f, x, y, z, {0.03f, 0.22f, 0.03f});
}

void shelf(MeshBuilder& b, const glm::vec3& p, float yaw) {
    const glm::vec3 x{std::cos(yaw), 0, -std::sin(yaw)}, z{std::sin(yaw), 0, std::cos(yaw)}, y{0, 1, 0};
    for (float sx : {-0.9f, 0.9f}) b.orientedBox(p + x * sx + y * 1.0f, x, y, z, {0.02f, 1.0f, 0.2f});
    for (int k = 0; k < 5; ++k) b.orientedBox(p + y * (0.1f + 0.45f * static_cast<float>(k)), x, y, z, {0.9f, 0.015f, 0.2f});
}

void interior(MeshBuilder& b, Rng& rng, float w, float d, int floors) {
    const float area = (w - 1.0f) * (d - 1.0f);
    for (int f = 0; f < floors; ++f) {
        const float y = kFloorHeight * static_cast<float>(f);
        if (f > 0) b.box({0.3f, y - 0.25f, 0.3f}, {w - 0.3f, y, d - 0.3f});
        // A partition wall and a few furniture groups per floor.
        const float px = rng.uniform(0.3f * w, 0.7f * w);
        b.box({px, y, 0.3f}, {px + 0.12f, y + 2.8f, rng.uniform(0.4f * d, 0.8f * d)});
        const int items = std::max(2, static_cast<int>(area / 80.0f));
        for (int k = 0; k < items; ++k) {
            const glm::vec3 p{rng.uniform(1.5f, w - 1.5f), y, rng.uniform(1.5f, d - 1.5f)};
            const float yaw = 0.5f * kPi * static_cast<float>(rng.range(0, 3));
            if (rng.chance(0.7f)) desk(b, p, yaw);
            else shelf(b, p, yaw);
        }
    }
}

class Generator {
public:
    explicit Generator(const CityOptions& o) : o_(o), rng_(o.seed * 0xD1B54A32D192ED03ull + 777) {}

    GeneratedScene run(ProgressBar* progress) {
        const float sizeX = static_cast<float>(o_.blocksX) * kPitch, sizeZ = static_cast<float>(o_.blocksZ) * kPitch;
        Mesh ground;
        MeshBuilder(ground).box({-kPitch, -0.3f, -kPitch}, {sizeX + kPitch, 0.0f, sizeZ + kPitch});
        place(add(std::move(ground), "asphalt"), at({0, 0, 0}));
        Mesh walk;
        {
            MeshBuilder b(walk);
            b.box({-3.0f, 0.0f, -3.0f}, {kLot + 3.0f, 0.15f, kLot + 3.0f});
        }
        const std::uint32_t sidewalk = add(std::move(walk), "sidewalk");
        Mesh lampMesh;
        {
            MeshBuilder b(lampMesh);
            b.cylinder({0, 0, 0}, {0, 6, 0}, 0.1f, 12);
            b.bar({0, 6, 0}, {1.5f, 6, 0}, 0.08f);
            b.box({1.2f, 5.7f, -0.2f}, {1.9f, 5.95f, 0.2f});
        }
        const std::uint32_t lamp = add(std::move(lampMesh), "lamp");
        std::uint32_t cars[3];
        for (int v = 0; v < 3; ++v) {
            Mesh car;
            MeshBuilder b(car);
            const float len = 4.0f + 0.5f * static_cast<float>(v), hgt = 1.4f + 0.3f * static_cast<float>(v);
            b.box({-0.5f * len, 0.35f, -0.9f}, {0.5f * len, 0.35f + 0.55f * hgt, 0.9f});
            b.box({-0.3f * len, 0.35f + 0.55f * hgt, -0.8f}, {0.25f * len, 0.35f + hgt, 0.8f});
            for (float sx : {-0.32f * len, 0.32f * len})
                for (float sz : {-0.92f, 0.72f}) b.cylinder({sx, 0.35f, sz}, {sx, 0.35f, sz + 0.2f}, 0.35f, 16);
            cars[v] = add(std::move(car), "car_" + std::to_string(v));
        }
        const double total = static_cast<double>(o_.blocksX) * o_.blocksZ;
        for (std::uint32_t i = 0; i < o_.blocksX; ++i)
            for (std::uint32_t j = 0; j < o_.blocksZ; ++j) {
                const glm::vec3 lot{static_cast<float>(i) * kPitch, 0.0f, static_cast<float>(j) * kPitch};
                place(sidewalk, at(lot));
                place(lamp, at(lot + glm::vec3(-2.0f, 0.15f, -2.0f), 0.25f * kPi + kPi));
                // Floors: mostly low and mid rise, a few towers.
                const float u = rng_.uniform(0.0f, 1.0f);
                const int floors = u < 0.85f ? rng_.range(2, 7) : rng_.range(8, 16);
                const float w = rng_.uniform(14.0f, kLot), d = rng_.uniform(14.0f, kLot);
                const glm::vec3 p = lot + glm::vec3(rng_.uniform(0.0f, kLot - w), 0.15f, rng_.uniform(0.0f, kLot - d));
                Mesh sh, in;
                MeshBuilder bs(sh), bi(in);
                shell(bs, rng_, w, d, floors);
                interior(bi, rng_, w, d, floors);
                const std::string id = std::to_string(i) + "_" + std::to_string(j);
                place(add(std::move(sh), "building_" + id), at(p));
                place(add(std::move(in), "interior_" + id), at(p));
                if (rng_.chance(0.4f)) {  // a parked car along the block's south side
                    const int v = rng_.range(0, 2);
                    place(cars[v], at(lot + glm::vec3(rng_.uniform(3.0f, kLot - 3.0f), 0.0f, -4.5f)));
                }
                if (progress) progress->advance(1.0 / total);
            }
        return std::move(scene_);
    }

private:
    std::uint32_t add(Mesh m, std::string name) {
        m.name = std::move(name);
        scene_.meshes.push_back(std::move(m));
        return static_cast<std::uint32_t>(scene_.meshes.size() - 1);
    }
    void place(std::uint32_t mesh, const Transform& t) { scene_.objects.push_back({mesh, t, true}); }

    CityOptions o_;
    Rng rng_;
    GeneratedScene scene_;
};

class City final : public GeneratedDemoScene {
public:
    explicit City(const CityOptions& o) : o_(o), path_(makePath(o)) {}

    std::string name() const override { return "city"; }
    Camera camera(std::uint64_t frame, float aspect) const override {
        Camera c;
        c.aspect = aspect;
        c.fovYRadians = 1.0f;
        c.nearPlane = 0.1f;
        c.farPlane = 1.5f * kPitch * static_cast<float>(std::max(o_.blocksX, o_.blocksZ)) + 100.0f;
        path_.apply(frame, c);
        return c;
    }
    std::uint64_t defaultFrames() const override { return path_.frameCount(); }

protected:
    std::string cacheFileName() const override { return "city_" + std::to_string(paramsHash()) + ".dcs"; }
    std::uint64_t paramsHash() const override { return cityParamsHash(o_); }
    const SceneCacheOptions& cacheOptions() const override { return o_.cache; }
    unsigned threads() const override { return o_.threads; }
    Expected<GeneratedScene> generate(ProgressBar& progress) const override { return generateCity(o_, &progress); }

private:
    static CameraPath makePath(const CityOptions& o) {
        // A loop around a rectangle of streets in the middle of the city, at eye height;
        // waypoints every block and just before/after each corner keep the spline in the street.
        const int nx = static_cast<int>(o.blocksX), nz = static_cast<int>(o.blocksZ);
        const int i0 = std::max(1, nx / 4), i1 = std::max(i0 + 1, 3 * nx / 4);
        const int j0 = std::max(1, nz / 4), j1 = std::max(j0 + 1, 3 * nz / 4);
        const glm::vec3 corners[4] = {{streetLine(i0), 1.7f, streetLine(j0)}, {streetLine(i1), 1.7f, streetLine(j0)},
                                      {streetLine(i1), 1.7f, streetLine(j1)}, {streetLine(i0), 1.7f, streetLine(j1)}};
        std::vector<glm::vec3> eyes, targets;
        for (int k = 0; k < 4; ++k) {
            const glm::vec3 a = corners[k], b = corners[(k + 1) % 4];
            const glm::vec3 dir = glm::normalize(b - a);
            const float len = glm::length(b - a);
            eyes.push_back(a + dir * 5.0f);
            for (float t = kPitch; t < len - 5.0f; t += kPitch) eyes.push_back(a + dir * t);
            eyes.push_back(b - dir * 5.0f);
        }
        for (std::size_t k = 0; k < eyes.size(); ++k) {
            const glm::vec3 next = eyes[(k + 1) % eyes.size()];
            const glm::vec3 dir = glm::normalize(next - eyes[k]);
            targets.push_back(eyes[k] + dir * 20.0f + glm::vec3(0, 1.5f, 0));
        }
        const std::uint32_t per = std::max<std::uint32_t>(1, o.frames / static_cast<std::uint32_t>(eyes.size()));
        return CameraPath(std::move(eyes), std::move(targets), per, true);
    }

    CityOptions o_;
    CameraPath path_;
};

}  // namespace

std::uint64_t cityParamsHash(const CityOptions& o) {
    char key[160];
    std::snprintf(key, sizeof key, "city|rev=2|seed=%llu|blocks=%ux%u", static_cast<unsigned long long>(o.seed), o.blocksX,
                  o.blocksZ);
    return fnv1a64(key, std::char_traits<char>::length(key));
}

Expected<GeneratedScene> generateCity(const CityOptions& o, ProgressBar* progress) {
    if (o.blocksX == 0 || o.blocksZ == 0 || o.blocksX > 200 || o.blocksZ > 200)
        return Error{"city: blocks must be in [1, 200] along each axis"};
    return Generator(o).run(progress);
}

std::unique_ptr<DemoScene> makeCity(const CityOptions& options) { return std::make_unique<City>(options); }

}  // namespace dyncull
