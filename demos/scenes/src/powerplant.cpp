// Procedural power plant in the size and character of the UNC Power Plant model (about
// 1,200 objects, 12.7M triangles): a four-storey steel hall (walls with windows and doors,
// floors with shafts and an atrium, columns, floor framing, roof trusses, stairs), three
// boilers with tube banks inside closed shells, two turbine sets, tanks, machinery,
// cabinets, catwalks, hundreds of individually routed pipes with bends and flanges, and
// pipe racks; outside a chimney, a tank farm and a pipe bridge. Metres, Y up. Everything
// is a pure function of the options (own RNG mapping), so the cache key is the options.
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
// Hall: x in [0, kHallX], z in [0, kHallZ], storeys every kStorey, roof at 4 storeys.
constexpr float kHallX = 96.0f, kHallZ = 56.0f, kStorey = 10.0f;
constexpr int kLevels = 4;
constexpr float kRoof = kStorey * kLevels;
// Three boilers along x, their shafts through every floor.
constexpr float kBoilerX[3] = {14.0f, 38.0f, 70.0f};
constexpr float kBoilerZ = 16.0f, kBoilerR = 6.5f, kShaft = 8.0f;
// Atrium through the floors (the camera rises through it) and the ground-floor aisle
// between the two doors, both kept free of equipment and pipes.
struct Rect {
    float x0, z0, x1, z1;
    bool overlaps(const Rect& o) const { return x0 < o.x1 && o.x0 < x1 && z0 < o.z1 && o.z0 < z1; }
};
constexpr Rect kAtrium{46.0f, 24.0f, 58.0f, 36.0f};
constexpr Rect kAisle{-1.0f, 25.0f, kHallX + 1.0f, 33.0f};
// Stair towers (x0 of the flight footprint; 8 m x 3.4 m).
constexpr float kStairX[2] = {2.0f, 86.0f};
constexpr float kStairZ = 50.0f;

Transform at(const glm::vec3& p, float yaw = 0.0f, const glm::vec3& scale = glm::vec3(1.0f)) {
    Transform t;
    t.translation = p;
    t.rotation = glm::angleAxis(yaw, glm::vec3(0, 1, 0));
    t.scale = scale;
    return t;
}

class Generator {
public:
    explicit Generator(const PowerPlantOptions& o) : o_(o), rng_(o.seed * 0x9E3779B97F4A7C15ull + 12345) {}

    GeneratedScene run(ProgressBar* progress) {
        struct Stage {
            void (Generator::*fn)();
            double weight;
        };
        const Stage stages[] = {{&Generator::hall, 1}, {&Generator::steel, 1}, {&Generator::boilers, 3},
                                {&Generator::turbines, 1}, {&Generator::equipment, 5}, {&Generator::walkways, 1},
                                {&Generator::pipes, 4}, {&Generator::racks, 3}, {&Generator::outside, 1}};
        double total = 0.0;
        for (const Stage& s : stages) total += s.weight;
        for (const Stage& s : stages) {
            (this->*s.fn)();
            if (progress) progress->advance(s.weight / total);
        }
        return std::move(scene_);
    }

private:
    int count(int n) const { return std::max(1, static_cast<int>(std::lround(static_cast<float>(n) * o_.size))); }
    std::uint32_t seg(float n) const { return std::max<std::uint32_t>(6, static_cast<std::uint32_t>(std::lround(n * o_.detail))); }
    std::uint32_t steps(float n) const { return std::max<std::uint32_t>(2, static_cast<std::uint32_t>(std::lround(n * o_.detail))); }

    std::uint32_t addMesh(Mesh mesh, std::string name) {
        mesh.name = std::move(name);
        scene_.meshes.push_back(std::move(mesh));
        return static_cast<std::uint32_t>(scene_.meshes.size() - 1);
    }
    void place(std::uint32_t mesh, const Transform& t) { scene_.objects.push_back({mesh, t, true}); }

    // ---- free floor space: a 1 m grid per level ----
    bool freeRect(int level, const Rect& r) const {
        if (r.x0 < 1.0f || r.z0 < 1.0f || r.x1 > kHallX - 1.0f || r.z1 > kHallZ - 1.0f) return false;
        if (r.overlaps(kAtrium) || (level == 0 && r.overlaps(kAisle))) return false;
        for (const Rect& u : used_[level])
            if (r.overlaps(u)) return false;
        return true;
    }
    void reserve(int level, const Rect& r) { used_[level].push_back(r); }
    /// Finds a free spot of footprint w x d on `level` (tries a few random positions).
    bool findSpot(int level, float w, float d, glm::vec3& where) {
        for (int attempt = 0; attempt < 60; ++attempt) {
            const float x = rng_.uniform(1.5f + 0.5f * w, kHallX - 1.5f - 0.5f * w);
            const float z = rng_.uniform(1.5f + 0.5f * d, kHallZ - 1.5f - 0.5f * d);
            const Rect r{x - 0.5f * w - 0.6f, z - 0.5f * d - 0.6f, x + 0.5f * w + 0.6f, z + 0.5f * d + 0.6f};
            if (freeRect(level, r)) {
                reserve(level, r);
                where = {x, kStorey * static_cast<float>(level), z};
                return true;
            }
        }
        return false;
    }
    void addAnchor(const glm::vec3& p) { anchors_.push_back(p); }

    // ---- hall: walls, floors, roof ----
    void hall() {
        std::vector<MeshBuilder::Opening> longWall, shortWall;
        for (int l = 0; l < kLevels; ++l) {
            const float v = kStorey * static_cast<float>(l);
            for (float u = 4.0f; u + 3.0f < kHallX - 2.0f; u += 6.0f) longWall.push_back({u, v + 4.0f, u + 3.0f, v + 7.5f});
            for (float u = 4.0f; u + 3.0f < kHallZ - 2.0f; u += 6.0f) {
                const bool door = l == 0 && u + 3.0f > kAisle.z0 && u < kAisle.z1;
                if (!door) shortWall.push_back({u, v + 4.0f, u + 3.0f, v + 7.5f});
            }
        }
        std::vector<MeshBuilder::Opening> doorWall = shortWall;
        doorWall.push_back({kAisle.z0 + 0.5f, 0.0f, kAisle.z1 - 0.5f, 9.0f});  // the big doors on the aisle
        Mesh south, north, west, east;
        MeshBuilder(south).wall({0, 0, 0}, {1, 0, 0}, kHallX, kRoof + 1.0f, 0.4f, longWall);
        MeshBuilder(north).wall({0, 0, kHallZ - 0.4f}, {1, 0, 0}, kHallX, kRoof + 1.0f, 0.4f, longWall);
        // Short walls run along +z; their thickness goes towards -x, so place them inside out.
        MeshBuilder(west).wall({0.4f, 0, 0}, {0, 0, 1}, kHallZ, kRoof + 1.0f, 0.4f, doorWall);
        MeshBuilder(east).wall({kHallX, 0, 0}, {0, 0, 1}, kHallZ, kRoof + 1.0f, 0.4f, doorWall);
        place(addMesh(std::move(south), "wall_south"), at({0, 0, 0}));
        place(addMesh(std::move(north), "wall_north"), at({0, 0, 0}));
        place(addMesh(std::move(west), "wall_west"), at({0, 0, 0}));
        place(addMesh(std::move(east), "wall_east"), at({0, 0, 0}));

        // Floors: slabs below each level, holes for shafts, atrium and stairs. A floor is a
        // wall laid flat (built in the xy plane, turned +90 degrees about x: y -> z).
        for (int l = 1; l <= kLevels; ++l) {
            std::vector<MeshBuilder::Opening> holes;
            for (float bx : kBoilerX) holes.push_back({bx - kShaft, kBoilerZ - kShaft, bx + kShaft, kBoilerZ + kShaft});
            if (l < kLevels) {
                holes.push_back({kAtrium.x0, kAtrium.z0, kAtrium.x1, kAtrium.z1});
                for (float sx : kStairX) holes.push_back({sx, kStairZ, sx + 8.0f, kStairZ + 3.4f});
            }
            Mesh floor;
            MeshBuilder(floor).wall({0.4f, 0.4f, 0}, {1, 0, 0}, kHallX - 0.8f, kHallZ - 0.8f, 0.5f, holes);
            Transform t;
            t.translation = {0, kStorey * static_cast<float>(l), 0};
            t.rotation = glm::angleAxis(0.5f * kPi, glm::vec3(1, 0, 0));
            // Built at v = z in [0.4, 55.6]: rotated, v maps to +z and thickness to -y.
            t.translation.z -= 0.0f;
            place(addMesh(std::move(floor), l == kLevels ? "roof" : "floor_" + std::to_string(l)), t);
        }
        for (int l = 0; l < kLevels; ++l) {
            reserve(l, {kStairX[0] - 0.5f, kStairZ - 1.0f, kStairX[0] + 9.0f, kStairZ + 5.0f});
            reserve(l, {kStairX[1] - 1.0f, kStairZ - 1.0f, kStairX[1] + 8.5f, kStairZ + 5.0f});
            for (float bx : kBoilerX) reserve(l, {bx - kShaft, kBoilerZ - kShaft, bx + kShaft, kBoilerZ + kShaft});
        }
    }

    // ---- structural steel: columns, floor framing, roof trusses, crane ----
    void steel() {
        Mesh column;
        {
            MeshBuilder b(column);
            b.iBeam({0, 0, 0}, {0, kRoof, 0}, {1, 0, 0}, 0.6f, 0.4f, 0.04f);
            b.box({-0.5f, 0, -0.5f}, {0.5f, 0.05f, 0.5f});
            for (int l = 1; l < kLevels; ++l) {
                const float y = kStorey * static_cast<float>(l);
                b.box({-0.35f, y - 1.0f, -0.22f}, {0.35f, y - 0.9f, 0.22f});  // bracket plates
                for (int k = 0; k < 6; ++k) b.cylinder({-0.25f + 0.1f * static_cast<float>(k), y - 0.95f, -0.25f},
                                                       {-0.25f + 0.1f * static_cast<float>(k), y - 0.95f, 0.25f}, 0.02f, 8);
            }
        }
        const std::uint32_t col = addMesh(std::move(column), "column");
        for (float x = 0.0f; x <= kHallX + 0.1f; x += 12.0f)
            for (float z = 0.0f; z <= kHallZ + 0.1f; z += 14.0f) {
                const glm::vec3 p{std::clamp(x, 0.8f, kHallX - 0.8f), 0.0f, std::clamp(z, 0.8f, kHallZ - 0.8f)};
                place(col, at(p));
            }
        for (int l = 1; l < kLevels; ++l) {
            Mesh framing;
            MeshBuilder b(framing);
            const float y = kStorey * static_cast<float>(l) - 0.5f - 0.35f;
            for (float z = 0.8f; z < kHallZ; z += 7.0f) b.iBeam({0.8f, y, z}, {kHallX - 0.8f, y, z}, {0, 1, 0}, 0.7f, 0.3f, 0.03f);
            for (float x = 0.8f; x < kHallX; x += 6.0f) b.iBeam({x, y, 0.8f}, {x, y, kHallZ - 0.8f}, {0, 1, 0}, 0.7f, 0.3f, 0.03f);
            place(addMesh(std::move(framing), "framing_" + std::to_string(l)), at({0, 0, 0}));
        }
        Mesh truss;
        MeshBuilder(truss).truss({0, 0, 0.5f}, {0, 0, kHallZ - 0.5f}, {0, 1, 0}, 2.5f, 28, 0.18f);
        MeshBuilder(truss).truss({0.6f, 0, 0.5f}, {0.6f, 0, kHallZ - 0.5f}, {0, 1, 0}, 2.5f, 28, 0.18f);
        const std::uint32_t tr = addMesh(std::move(truss), "roof_truss");
        for (float x = 0.0f; x <= kHallX + 0.1f; x += 6.0f)
            place(tr, at({std::clamp(x, 0.8f, kHallX - 1.6f), kRoof - 3.2f, 0.0f}));
        Mesh crane;
        {
            MeshBuilder b(crane);
            b.iBeam({1, 0, 4}, {1, 0, kHallZ - 4}, {0, 1, 0}, 1.2f, 0.6f, 0.05f);
            b.iBeam({5, 0, 4}, {5, 0, kHallZ - 4}, {0, 1, 0}, 1.2f, 0.6f, 0.05f);
            b.box({0, 0.6f, 20}, {6, 1.6f, 23});
            b.cylinder({3, -0.5f, 21.5f}, {3, -6, 21.5f}, 0.05f, 8);
            b.sphere({3, -6.4f, 21.5f}, 0.4f, 16, 8);
        }
        place(addMesh(std::move(crane), "crane"), at({20, kRoof - 5.0f, 0}));
    }

    // ---- boilers: closed shells with tube banks inside, drums, downcomers, burners ----
    void boilers() {
        Mesh shell, bank, drum, burners;
        {
            MeshBuilder b(shell);
            b.tank({0, 3.5f, 0}, {0, 30.0f, 0}, kBoilerR, seg(96), steps(16));
            for (float y = 5.0f; y < 30.0f; y += 2.5f) b.cylinder({0, y, 0}, {0, y + 0.3f, 0}, kBoilerR + 0.15f, seg(96));
            for (int k = 0; k < 8; ++k) {  // skirt legs
                const float a = 2.0f * kPi * static_cast<float>(k) / 8.0f;
                const glm::vec3 p{(kBoilerR - 0.4f) * std::cos(a), 0.0f, (kBoilerR - 0.4f) * std::sin(a)};
                b.iBeam(p, p + glm::vec3(0, 5.0f, 0), glm::vec3(std::cos(a), 0, std::sin(a)), 0.5f, 0.3f, 0.04f);
            }
        }
        {
            // Serpentine tube bank filling the shell: hidden from outside, so occlusion
            // culling should skip it whenever the shell is in front.
            MeshBuilder b(bank);
            const int tubes = 200;
            for (int i = 0; i < tubes; ++i) {
                const float a = 2.0f * kPi * static_cast<float>(i) / static_cast<float>(tubes);
                const float r = kBoilerR - 0.6f - 1.6f * static_cast<float>(i % 3);
                std::vector<glm::vec3> pts;
                const int legs = 8;
                for (int k = 0; k <= legs; ++k) {
                    const float y = 5.0f + 23.0f * static_cast<float>(k) / static_cast<float>(legs);
                    const float da = (k % 2 == 0 ? -1.0f : 1.0f) * 0.012f;
                    pts.push_back({r * std::cos(a + da), y, r * std::sin(a + da)});
                    pts.push_back({(r - 0.6f) * std::cos(a + da), y + 1.2f, (r - 0.6f) * std::sin(a + da)});
                }
                b.tube(pts, 0.035f, seg(12), 0.25f, steps(6));
            }
        }
        {
            MeshBuilder b(drum);
            b.tank({-5, 33, 0}, {5, 33, 0}, 1.2f, seg(48), steps(10));
            for (int k = 0; k < 6; ++k) {
                const float x = -4.0f + 1.6f * static_cast<float>(k);
                b.tube({{x, 32.0f, 0.6f}, {x, 32.0f, kBoilerR + 0.8f}, {x, 2.0f, kBoilerR + 0.8f}, {x, 2.0f, kBoilerR - 1.0f}}, 0.18f,
                       seg(20), 0.7f, steps(10));
            }
        }
        {
            MeshBuilder b(burners);
            b.box({-4, 0, 0}, {4, 6, 1.2f});
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 2; ++j) {
                    const glm::vec3 c{-2.7f + 2.7f * static_cast<float>(i), 1.8f + 2.4f * static_cast<float>(j), 1.2f};
                    b.cylinder(c, c + glm::vec3(0, 0, 1.6f), 0.7f, seg(40));
                    b.cylinder(c + glm::vec3(0, 0, 1.6f), c + glm::vec3(0, 0, 1.9f), 0.9f, seg(40));
                    for (int k = 0; k < 16; ++k) {  // flange bolts
                        const float a = 2.0f * kPi * static_cast<float>(k) / 16.0f;
                        const glm::vec3 q = c + glm::vec3(0.8f * std::cos(a), 0.8f * std::sin(a), 1.9f);
                        b.cylinder(q, q + glm::vec3(0, 0, 0.08f), 0.03f, 8);
                    }
                    b.tube({c + glm::vec3(0, 0.7f, 1.0f), c + glm::vec3(0, 2.0f, 1.0f), c + glm::vec3(0, 2.0f, 3.5f)}, 0.1f, seg(16),
                           0.4f, steps(8));
                }
        }
        const std::uint32_t s = addMesh(std::move(shell), "boiler_shell"), k = addMesh(std::move(bank), "boiler_tube_bank"),
                            d = addMesh(std::move(drum), "boiler_drum"), u = addMesh(std::move(burners), "boiler_burners");
        for (float bx : kBoilerX) {
            const glm::vec3 p{bx, 0.0f, kBoilerZ};
            place(s, at(p));
            place(k, at(p));
            place(d, at(p));
            place(u, at(p + glm::vec3(0, 0, kBoilerR), 0.0f));
            addAnchor(p + glm::vec3(kBoilerR + 0.3f, 8.0f, 0));
            addAnchor(p + glm::vec3(-kBoilerR - 0.3f, 18.0f, 0));
            addAnchor(p + glm::vec3(0, 28.0f, kBoilerR + 0.3f));
        }
    }

    // ---- turbine-generator sets on the first floor ----
    void turbines() {
        Mesh t;
        MeshBuilder b(t);
        const float radii[] = {1.4f, 2.0f, 2.6f, 2.6f, 2.2f, 1.6f, 1.8f, 1.8f};
        float x = 0.0f;
        for (float r : radii) {
            b.cylinder({x, 2.8f, 0}, {x + 3.0f, 2.8f, 0}, r, seg(72));
            b.cylinder({x + 2.7f, 2.8f, 0}, {x + 3.0f, 2.8f, 0}, r + 0.2f, seg(72));
            for (int k = 0; k < 36; ++k) {
                const float a = 2.0f * kPi * static_cast<float>(k) / 36.0f;
                const glm::vec3 q{x + 3.0f, 2.8f + (r + 0.1f) * std::cos(a), (r + 0.1f) * std::sin(a)};
                b.cylinder(q, q + glm::vec3(0.12f, 0, 0), 0.04f, 8);
            }
            x += 3.0f;
        }
        b.box({-0.5f, 0, -2.0f}, {x + 0.5f, 0.6f, 2.0f});
        for (int k = 0; k < 4; ++k)
            b.tube({{3.0f + 5.0f * static_cast<float>(k), 4.5f, 0}, {3.0f + 5.0f * static_cast<float>(k), 6.5f, 0},
                    {3.0f + 5.0f * static_cast<float>(k), 6.5f, 3.0f}, {3.0f + 5.0f * static_cast<float>(k), 0.6f, 3.0f}},
                   0.3f, seg(28), 1.0f, steps(12));
        const std::uint32_t m = addMesh(std::move(t), "turbine_generator");
        const float xs[2] = {8.0f, 62.0f};
        for (float tx : xs) {
            place(m, at({tx, kStorey, 44.0f}));
            reserve(1, {tx - 1.0f, 40.0f, tx + x + 1.0f, 48.0f});
            addAnchor({tx + 2.0f, kStorey + 5.0f, 44.0f});
            addAnchor({tx + 20.0f, kStorey + 5.0f, 44.0f});
        }
    }

    // ---- tanks, machinery, cabinets ----
    Mesh tankMesh(int variant) {
        Mesh m;
        MeshBuilder b(m);
        Rng r(o_.seed * 31 + static_cast<std::uint64_t>(variant));
        const float rad = r.uniform(1.0f, 2.4f);
        if (variant % 2 == 0) {  // vertical on legs, with ladder and nozzles
            const float h = r.uniform(3.0f, 6.0f);
            b.tank({0, 1.2f + rad, 0}, {0, 1.2f + rad + h, 0}, rad, seg(96), steps(24));
            for (int k = 0; k < 4; ++k) {
                const float a = kPi * (0.25f + 0.5f * static_cast<float>(k));
                const glm::vec3 p{0.85f * rad * std::cos(a), 0, 0.85f * rad * std::sin(a)};
                b.bar(p, p + glm::vec3(0, 1.6f + rad, 0), 0.15f);
            }
            for (int k = 0; k < 24; ++k) b.bar({rad + 0.2f, 1.5f + 0.3f * static_cast<float>(k), -0.2f},
                                              {rad + 0.2f, 1.5f + 0.3f * static_cast<float>(k), 0.2f}, 0.03f);
            b.bar({rad + 0.2f, 1.2f, -0.22f}, {rad + 0.2f, 1.2f + 2.0f * rad + h, -0.22f}, 0.05f);
            b.bar({rad + 0.2f, 1.2f, 0.22f}, {rad + 0.2f, 1.2f + 2.0f * rad + h, 0.22f}, 0.05f);
            for (int k = 0; k < 6; ++k) {
                const float a = 2.0f * kPi * static_cast<float>(k) / 6.0f + 0.3f;
                const glm::vec3 p{(rad - 0.05f) * std::cos(a), 1.2f + rad + r.uniform(0.5f, h), (rad - 0.05f) * std::sin(a)};
                const glm::vec3 d{std::cos(a), 0, std::sin(a)};
                b.cylinder(p, p + d * 0.5f, 0.12f, seg(20));
                b.cylinder(p + d * 0.45f, p + d * 0.55f, 0.22f, seg(20));
            }
        } else {  // horizontal on saddles
            const float len = r.uniform(4.0f, 8.0f);
            b.tank({-0.5f * len, 1.0f + rad, 0}, {0.5f * len, 1.0f + rad, 0}, rad, seg(96), steps(24));
            for (float sx : {-0.3f * len, 0.3f * len}) b.box({sx - 0.3f, 0, -0.8f * rad}, {sx + 0.3f, 1.0f + 0.6f * rad, 0.8f * rad});
            for (int k = 0; k < 4; ++k) {
                const glm::vec3 p{-0.4f * len + 0.25f * len * static_cast<float>(k), 1.0f + 2.0f * rad - 0.1f, 0};
                b.cylinder(p, p + glm::vec3(0, 0.6f, 0), 0.15f, seg(20));
                b.cylinder(p + glm::vec3(0, 0.5f, 0), p + glm::vec3(0, 0.62f, 0), 0.25f, seg(20));
            }
        }
        return m;
    }

    Mesh machineMesh(int variant) {
        Mesh m;
        MeshBuilder b(m);
        Rng r(o_.seed * 131 + static_cast<std::uint64_t>(variant));
        const float len = r.uniform(2.0f, 4.0f), w = r.uniform(1.2f, 2.2f);
        // Skid frame.
        b.iBeam({-0.5f * len, 0.15f, -0.5f * w}, {0.5f * len, 0.15f, -0.5f * w}, {0, 1, 0}, 0.3f, 0.15f, 0.02f);
        b.iBeam({-0.5f * len, 0.15f, 0.5f * w}, {0.5f * len, 0.15f, 0.5f * w}, {0, 1, 0}, 0.3f, 0.15f, 0.02f);
        b.box({-0.5f * len, 0.3f, -0.5f * w}, {0.5f * len, 0.35f, 0.5f * w});
        // Motor with cooling fins.
        const float mr = r.uniform(0.35f, 0.6f);
        const glm::vec3 m0{-0.45f * len, 0.45f + mr, 0}, m1{-0.05f * len, 0.45f + mr, 0};
        b.cylinder(m0, m1, mr, seg(96));
        const int fins = 48;
        for (int k = 0; k < fins; ++k) {
            const float a = 2.0f * kPi * static_cast<float>(k) / static_cast<float>(fins);
            const glm::vec3 d{0, std::cos(a), std::sin(a)};
            b.orientedBox(0.5f * (m0 + m1) + d * (mr + 0.04f), {1, 0, 0}, d, glm::cross(glm::vec3(1, 0, 0), d),
                          {0.5f * (m1.x - m0.x) * 0.9f, 0.05f, 0.008f});
        }
        // Coupling guard and pump casing.
        b.cylinder(m1, m1 + glm::vec3(0.1f * len, 0, 0), 0.5f * mr, seg(32));
        const glm::vec3 pc = m1 + glm::vec3(0.1f * len + 0.7f * mr + 0.2f, 0, 0);
        b.sphere(pc, 0.9f * mr + 0.2f, seg(96), steps(48));
        for (int k = 0; k < 24; ++k) {  // casing bolts
            const float a = 2.0f * kPi * static_cast<float>(k) / 24.0f;
            const glm::vec3 q = pc + glm::vec3(-0.2f, (0.9f * mr + 0.25f) * std::cos(a), (0.9f * mr + 0.25f) * std::sin(a));
            b.cylinder(q, q + glm::vec3(0.12f, 0, 0), 0.03f, 8);
        }
        // Impeller inside the casing (hidden unless the casing is culled away): curved vanes.
        for (int k = 0; k < 7; ++k) {
            const float a = 2.0f * kPi * static_cast<float>(k) / 7.0f;
            std::vector<glm::vec3> vane;
            for (int j = 0; j < 4; ++j) {
                const float rr = 0.1f + 0.2f * static_cast<float>(j) * (0.9f * mr + 0.1f);
                const float aa = a + 0.35f * static_cast<float>(j);
                vane.push_back(pc + glm::vec3(0.02f * static_cast<float>(j), rr * std::cos(aa), rr * std::sin(aa)));
            }
            b.tube(vane, 0.025f, seg(16), 0.15f, steps(12));
        }
        // Suction and discharge with flanges.
        const float pr = 0.12f + 0.1f * mr;
        b.tube({pc, pc + glm::vec3(0.6f, 0, 0), pc + glm::vec3(0.6f, 0, 0.8f), pc + glm::vec3(0.6f, -0.4f, 0.8f)}, pr, seg(24), 3.0f * pr, steps(10));
        b.tube({pc, pc + glm::vec3(0, 1.3f, 0)}, pr, seg(24), 0.0f, 0);
        b.cylinder(pc + glm::vec3(0, 1.2f, 0), pc + glm::vec3(0, 1.3f, 0), 1.7f * pr, seg(24));
        // Control box and conduit.
        b.box({0.1f * len, 0.35f, 0.2f * w}, {0.35f * len, 1.4f, 0.45f * w});
        b.tube({{0.2f * len, 1.4f, 0.3f * w}, {0.2f * len, 1.8f, 0.3f * w}, {-0.25f * len, 1.8f, 0.3f * w}, {-0.25f * len, 0.45f + 2.0f * mr, 0}},
               0.03f, seg(12), 0.15f, steps(6));
        return m;
    }

    Mesh cabinetMesh() {
        Mesh m;
        MeshBuilder b(m);
        b.box({0, 0, 0}, {1.2f, 2.2f, 0.6f});
        for (int k = 0; k < 16; ++k) {
            const float y = 0.3f + 0.1f * static_cast<float>(k);
            b.box({0.15f, y, 0.6f}, {0.55f, y + 0.03f, 0.63f});
            b.box({0.65f, y, 0.6f}, {1.05f, y + 0.03f, 0.63f});
        }
        b.box({0.05f, 1.0f, 0.6f}, {0.08f, 1.3f, 0.66f});
        return m;
    }

    void equipment() {
        std::uint32_t tanks[6], machines[12];
        for (int v = 0; v < 6; ++v) tanks[v] = addMesh(tankMesh(v), "tank_" + std::to_string(v));
        for (int v = 0; v < 12; ++v) machines[v] = addMesh(machineMesh(v), "machine_" + std::to_string(v));
        const std::uint32_t cabinet = addMesh(cabinetMesh(), "cabinet");
        tankMeshes_.assign(tanks, tanks + 6);
        machineMeshes_.assign(machines, machines + 12);
        for (int l = 0; l < kLevels; ++l) {
            for (int i = 0; i < count(11); ++i) {
                const int v = rng_.range(0, 5);
                const Aabb bb = scene_.meshes[tanks[v]].bounds();
                const float yaw = v % 2 ? 0.5f * kPi * static_cast<float>(rng_.range(0, 1)) : 0.0f;
                const float wx = std::abs(std::cos(yaw)) > 0.5f ? bb.extent().x : bb.extent().z;
                const float wz = std::abs(std::cos(yaw)) > 0.5f ? bb.extent().z : bb.extent().x;
                glm::vec3 p;
                if (!findSpot(l, wx, wz, p)) continue;
                place(tanks[v], at(p, yaw));
                addAnchor(p + glm::vec3(0, bb.max.y * 0.8f, 0));
            }
            for (int i = 0; i < count(58); ++i) {
                const int v = rng_.range(0, 11);
                const Aabb bb = scene_.meshes[machines[v]].bounds();
                const bool turn = rng_.chance(0.5f);
                glm::vec3 p;
                if (!findSpot(l, turn ? bb.extent().z : bb.extent().x, turn ? bb.extent().x : bb.extent().z, p)) continue;
                place(machines[v], at(p, turn ? 0.5f * kPi : 0.0f));
                addAnchor(p + glm::vec3(0, bb.max.y, 0));
            }
            for (int i = 0; i < count(4); ++i) {  // rows of cabinets along a wall
                glm::vec3 p;
                const int n = rng_.range(3, 6);
                if (!findSpot(l, 1.25f * static_cast<float>(n), 0.7f, p)) continue;
                for (int k = 0; k < n; ++k) place(cabinet, at(p + glm::vec3(-0.625f * static_cast<float>(n) + 1.25f * static_cast<float>(k), 0, -0.3f)));
            }
        }
    }

    // ---- stairs and catwalks ----
    void walkways() {
        Mesh flight;
        {
            MeshBuilder b(flight);
            b.stairs({0, 0, 0.8f}, {1, 0, 0}, 1.4f, 0.2f, 0.26f, 25);
            b.box({6.5f, 4.9f, 0}, {8.0f, 5.0f, 3.4f});
            b.stairs({6.5f, 5.0f, 2.6f}, {-1, 0, 0}, 1.4f, 0.2f, 0.26f, 25);
        }
        const std::uint32_t fl = addMesh(std::move(flight), "stair_flight");
        for (float sx : kStairX)
            for (int l = 0; l + 1 < kLevels; ++l) place(fl, at({sx, kStorey * static_cast<float>(l), kStairZ}));
        Mesh catwalk;
        {
            MeshBuilder b(catwalk);
            const float len = 13.0f;
            b.grating({0, 0, 0}, {len, 0, 1.0f}, 0.03f, 0.04f);
            for (float z : {0.0f, 1.0f}) {
                for (float x = 0.0f; x <= len + 0.01f; x += 1.625f) b.bar({x, 0, z}, {x, 1.1f, z}, 0.05f);
                b.bar({0, 1.1f, z}, {len, 1.1f, z}, 0.05f);
                b.bar({0, 0.55f, z}, {len, 0.55f, z}, 0.04f);
                b.box({0, 0, z - 0.005f}, {len, 0.12f, z + 0.005f});
            }
            for (float x = 0.0f; x <= len + 0.01f; x += 3.25f) b.iBeam({x, -0.2f, 0}, {x, -0.2f, 1.0f}, {0, 1, 0}, 0.2f, 0.1f, 0.015f);
        }
        const std::uint32_t cw = addMesh(std::move(catwalk), "catwalk");
        const float half = 6.5f, offset = kBoilerR + 0.4f;
        for (float bx : kBoilerX)
            for (int l = 0; l < count(kLevels); ++l) {
                const float y = kStorey * static_cast<float>(l) + 5.0f;
                place(cw, at({bx - half, y, kBoilerZ + offset}));                      // south side, along +x
                place(cw, at({bx + half, y, kBoilerZ - offset}, kPi));                 // north side
                place(cw, at({bx + offset, y, kBoilerZ + half}, 0.5f * kPi));          // along -z
                place(cw, at({bx - offset, y, kBoilerZ - half}, -0.5f * kPi));         // along +z
            }
    }

    // ---- pipes: individually routed, each its own mesh ----
    bool routeClear(const std::vector<glm::vec3>& pts) const {
        for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
            const Rect r{std::min(pts[i].x, pts[i + 1].x) - 0.6f, std::min(pts[i].z, pts[i + 1].z) - 0.6f,
                         std::max(pts[i].x, pts[i + 1].x) + 0.6f, std::max(pts[i].z, pts[i + 1].z) + 0.6f};
            if (r.overlaps(kAtrium)) return false;
            if (std::min(pts[i].y, pts[i + 1].y) < 7.0f && r.overlaps(kAisle)) return false;
        }
        return true;
    }

    void pipe(Mesh& m, const std::vector<glm::vec3>& pts, float r, bool flanges, bool valve) {
        MeshBuilder b(m);
        const std::uint32_t s = seg(24.0f + 80.0f * r);
        b.tube(pts, r, s, 3.0f * r, steps(16));
        if (!flanges) return;
        for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
            const glm::vec3 d = pts[i + 1] - pts[i];
            const float len = glm::length(d);
            if (len < 8.0f * r + 1.0f) continue;
            const glm::vec3 u = d / len;
            for (float t = 4.0f * r + 0.5f; t < len - 4.0f * r - 0.5f; t += 3.0f) {
                const glm::vec3 c = pts[i] + u * t;
                b.cylinder(c - u * 0.04f, c + u * 0.04f, 1.6f * r, s);
            }
            if (valve && i == 1) {
                const glm::vec3 c = pts[i] + u * (0.5f * len);
                b.sphere(c, 1.7f * r, s, s / 2);
                const glm::vec3 side = procedural::anyPerpendicular(u);
                b.cylinder(c, c + side * (3.0f * r + 0.2f), 0.2f * r, 8);
                b.cylinder(c + side * (3.0f * r + 0.2f), c + side * (3.0f * r + 0.25f), 2.0f * r, s);
            }
        }
    }

    void pipes() {
        if (anchors_.size() < 2) return;
        const int n = count(640);
        for (int i = 0; i < n; ++i) {
            std::vector<glm::vec3> pts;
            const float r = 0.05f + 0.4f * std::pow(rng_.uniform(0.0f, 1.0f), 2.5f);
            for (int attempt = 0; attempt < 12; ++attempt) {
                const glm::vec3 a = anchors_[static_cast<std::size_t>(rng_.range(0, static_cast<int>(anchors_.size()) - 1))];
                glm::vec3 b = anchors_[static_cast<std::size_t>(rng_.range(0, static_cast<int>(anchors_.size()) - 1))];
                if (glm::length(b - a) < 4.0f || glm::length(b - a) > 45.0f) {
                    b = a + glm::vec3(rng_.uniform(-14.0f, 14.0f), rng_.uniform(-3.0f, 3.0f), rng_.uniform(-10.0f, 10.0f));
                    b = glm::clamp(b, glm::vec3(1.5f, 0.5f, 1.5f), glm::vec3(kHallX - 1.5f, kRoof - 1.5f, kHallZ - 1.5f));
                }
                const float base = std::floor(std::max(a.y, b.y) / kStorey) * kStorey;
                const float h = std::min(base + rng_.uniform(7.0f, 9.2f), kRoof - 4.5f);
                const glm::vec3 a0 = a + glm::vec3(rng_.uniform(-0.4f, 0.4f), 0, rng_.uniform(-0.4f, 0.4f));
                pts = {a0, {a0.x, h, a0.z}};
                if (rng_.chance(0.5f)) pts.push_back({b.x, h, a0.z});
                else pts.push_back({a0.x, h, b.z});
                pts.push_back({b.x, h, b.z});
                pts.push_back(b);
                if (routeClear(pts)) break;
                pts.clear();
            }
            if (pts.empty()) continue;
            Mesh m;
            pipe(m, pts, r, true, rng_.chance(0.35f));
            place(addMesh(std::move(m), "pipe_" + std::to_string(i)), at({0, 0, 0}));
        }
    }

    // ---- pipe racks: bundles of parallel pipes on portal frames ----
    void rackBundle(Mesh& m, const std::vector<glm::vec3>& route, int pipesPerLayer, int layers, float floorY) {
        MeshBuilder b(m);
        const float r = rng_.uniform(0.08f, 0.22f), spacing = 3.0f * r + 0.1f;
        // Left normals of the legs; a corner is offset by the sum of its two normals, which
        // for right angles puts parallel pipes exactly on their offset lines.
        std::vector<glm::vec3> normals;
        for (std::size_t i = 0; i + 1 < route.size(); ++i) {
            const glm::vec3 d = glm::normalize(route[i + 1] - route[i]);
            normals.push_back({-d.z, 0, d.x});
        }
        for (int layer = 0; layer < layers; ++layer)
            for (int k = 0; k < pipesPerLayer; ++k) {
                const float off = (static_cast<float>(k) - 0.5f * static_cast<float>(pipesPerLayer - 1)) * spacing;
                std::vector<glm::vec3> pts;
                for (std::size_t i = 0; i < route.size(); ++i) {
                    glm::vec3 n = i == 0 ? normals[0] : i + 1 == route.size() ? normals.back() : normals[i - 1] + normals[i];
                    pts.push_back(route[i] + n * off + glm::vec3(0, 1.2f * static_cast<float>(layer), 0));
                }
                pipe(m, pts, r * (layer == 0 ? 1.0f : 0.7f), true, false);
            }
        const float halfWidth = 0.5f * static_cast<float>(pipesPerLayer) * spacing + 0.3f;
        for (std::size_t i = 0; i + 1 < route.size(); ++i) {
            const glm::vec3 d = route[i + 1] - route[i];
            const float len = glm::length(d);
            for (float t = 1.0f; t < len - 1.0f; t += 6.0f) {
                const glm::vec3 c = route[i] + d * (t / len) - glm::vec3(0, r + 0.2f, 0);
                const glm::vec3 n = normals[i] * halfWidth;
                b.iBeam(c - n, c + n, {0, 1, 0}, 0.25f, 0.15f, 0.02f);
                b.iBeam(c - n, {c.x - n.x, floorY, c.z - n.z}, d / len, 0.25f, 0.15f, 0.02f);
                b.iBeam(c + n, {c.x + n.x, floorY, c.z + n.z}, d / len, 0.25f, 0.15f, 0.02f);
            }
        }
    }

    void racks() {
        const int perLevel = count(10);
        int made = 0;
        for (int l = 0; l < kLevels; ++l)
            for (int i = 0; i < perLevel; ++i) {
                const float floorY = kStorey * static_cast<float>(l);
                const float h = floorY + rng_.uniform(6.0f, 7.5f);
                std::vector<glm::vec3> route;
                for (int attempt = 0; attempt < 20 && route.empty(); ++attempt) {
                    glm::vec3 p{rng_.uniform(3.0f, kHallX - 3.0f), h, rng_.uniform(3.0f, kHallZ - 3.0f)};
                    route = {p};
                    const int legs = rng_.range(2, 4);
                    bool alongX = rng_.chance(0.5f);
                    for (int k = 0; k < legs; ++k) {
                        glm::vec3 q = p;
                        if (alongX) q.x = std::clamp(p.x + rng_.uniform(-40.0f, 40.0f), 3.0f, kHallX - 3.0f);
                        else q.z = std::clamp(p.z + rng_.uniform(-25.0f, 25.0f), 3.0f, kHallZ - 3.0f);
                        if (glm::length(q - p) < 6.0f) break;
                        route.push_back(q);
                        p = q;
                        alongX = !alongX;
                    }
                    if (route.size() < 2 || !routeClear(route)) route.clear();
                }
                if (route.empty()) continue;
                Mesh m;
                rackBundle(m, route, rng_.range(6, 12), rng_.range(1, 3), floorY);
                place(addMesh(std::move(m), "rack_" + std::to_string(made++)), at({0, 0, 0}));
            }
    }

    // ---- outside: ground, chimney, tank farm, transformer yard, pipe bridge ----
    void outside() {
        Mesh ground;
        MeshBuilder(ground).box({-150, -0.5f, -150}, {250, 0, 200});
        place(addMesh(std::move(ground), "ground"), at({0, 0, 0}));
        Mesh chimney;
        {
            MeshBuilder b(chimney);
            b.cylinder({0, 0, 0}, {0, 90, 0}, 3.5f, seg(64));
            for (float y = 4.0f; y < 90.0f; y += 6.0f) b.cylinder({0, y, 0}, {0, y + 0.5f, 0}, 3.7f, seg(64));
            for (int k = 0; k < 260; ++k) b.bar({3.7f, 0.35f * static_cast<float>(k), -0.25f}, {3.7f, 0.35f * static_cast<float>(k), 0.25f}, 0.04f);
            b.bar({3.7f, 0, -0.27f}, {3.7f, 91, -0.27f}, 0.06f);
            b.bar({3.7f, 0, 0.27f}, {3.7f, 91, 0.27f}, 0.06f);
        }
        place(addMesh(std::move(chimney), "chimney"), at({40, 0, -22}));
        Mesh duct;
        MeshBuilder(duct).tube({{38, 20, 4}, {38, 28, 4}, {38, 28, -18}, {40, 28, -18.5f}}, 1.8f, seg(48), 4.0f, steps(16));
        place(addMesh(std::move(duct), "flue_duct"), at({0, 0, 0}));
        for (int i = 0; i < count(14); ++i) {
            const int v = 2 * rng_.range(0, 2);  // vertical tanks in the farm
            place(tankMeshes_[static_cast<std::size_t>(v)],
                  at({110.0f + 9.0f * static_cast<float>(i % 4), 0, 6.0f + 10.0f * static_cast<float>(i / 4)}));
        }
        for (int i = 0; i < count(20); ++i) {
            const int v = rng_.range(0, 11);
            place(machineMeshes_[static_cast<std::size_t>(v)],
                  at({-30.0f + 5.5f * static_cast<float>(i % 5), 0, 4.0f + 6.0f * static_cast<float>(i / 5)}));
        }
        for (int i = 0; i < count(3); ++i) {
            Mesh m;
            const float z = 8.0f + 6.0f * static_cast<float>(i);
            rackBundle(m, {{kHallX + 0.5f, 9.0f, z}, {106.0f, 9.0f, z}, {106.0f, 9.0f, z + 20.0f}, {140.0f, 9.0f, z + 20.0f}}, 6, 1, 0.0f);
            place(addMesh(std::move(m), "pipe_bridge_" + std::to_string(i)), at({0, 0, 0}));
        }
    }

    PowerPlantOptions o_;
    Rng rng_;
    GeneratedScene scene_;
    std::vector<Rect> used_[kLevels];
    std::vector<glm::vec3> anchors_;
    std::vector<std::uint32_t> tankMeshes_, machineMeshes_;
};

class PowerPlant final : public GeneratedDemoScene {
public:
    explicit PowerPlant(const PowerPlantOptions& o) : o_(o), path_(makePath(o.frames)) {}

    std::string name() const override { return "powerplant"; }
    Camera camera(std::uint64_t frame, float aspect) const override {
        Camera c;
        c.aspect = aspect;
        c.fovYRadians = 1.0f;
        c.nearPlane = 0.1f;
        c.farPlane = 600.0f;
        path_.apply(frame, c);
        return c;
    }
    std::uint64_t defaultFrames() const override { return path_.frameCount(); }

protected:
    std::string cacheFileName() const override { return "powerplant_" + std::to_string(paramsHash()) + ".dcs"; }
    std::uint64_t paramsHash() const override { return powerPlantParamsHash(o_); }
    const SceneCacheOptions& cacheOptions() const override { return o_.cache; }
    unsigned threads() const override { return o_.threads; }
    Expected<GeneratedScene> generate(ProgressBar& progress) const override { return generatePowerPlant(o_, &progress); }

private:
    static CameraPath makePath(std::uint32_t frames) {
        // Outside approach, in through the west door along the aisle, up the atrium past the
        // boilers and pipe racks, across the top floor, down and out the east door, then a
        // wide loop around the outside back to the start.
        std::vector<glm::vec3> eyes = {
            {-70, 30, -40}, {-25, 5, 29}, {8, 4.5f, 29}, {30, 5, 30}, {52, 9, 30}, {52, 24, 30},
            {68, 34, 38}, {84, 34, 30}, {88, 5, 29}, {120, 8, 30}, {150, 45, 90}, {40, 60, 120}, {-60, 45, 80}};
        std::vector<glm::vec3> targets = {
            {48, 15, 28}, {10, 5, 29}, {40, 5, 27}, {50, 8, 20}, {38, 16, 16}, {70, 22, 16},
            {90, 30, 40}, {70, 25, 16}, {110, 5, 29}, {48, 15, 28}, {48, 15, 28}, {48, 15, 28}, {48, 15, 28}};
        const std::uint32_t per = std::max<std::uint32_t>(1, frames / static_cast<std::uint32_t>(eyes.size()));
        return CameraPath(std::move(eyes), std::move(targets), per, true);
    }

    PowerPlantOptions o_;
    CameraPath path_;
};

}  // namespace

std::uint64_t powerPlantParamsHash(const PowerPlantOptions& o) {
    // Bump the generator revision whenever generated geometry changes.
    char key[160];
    std::snprintf(key, sizeof key, "powerplant|rev=2|seed=%llu|size=%.6g|detail=%.6g",
                  static_cast<unsigned long long>(o.seed), static_cast<double>(o.size), static_cast<double>(o.detail));
    return fnv1a64(key, std::char_traits<char>::length(key));
}

Expected<GeneratedScene> generatePowerPlant(const PowerPlantOptions& o, ProgressBar* progress) {
    if (!(o.size > 0.0f && o.size <= 1.0f)) return Error{"powerplant: size must be in (0, 1]"};
    if (!(o.detail > 0.0f && o.detail <= 1.0f)) return Error{"powerplant: detail must be in (0, 1]"};
    return Generator(o).run(progress);
}

std::unique_ptr<DemoScene> makePowerPlant(const PowerPlantOptions& options) { return std::make_unique<PowerPlant>(options); }

}  // namespace dyncull
