// Procedural primitives: valid, finite unit normals, watertight with consistent outward
// winding (every directed edge matched by its reverse after welding; positive volume).
#include <cmath>
#include <functional>
#include <map>
#include <tuple>
#include <unordered_map>

#include <gtest/gtest.h>

#include "procedural_mesh.hpp"

namespace dyncull {
namespace {

using procedural::MeshBuilder;

/// Welds vertices closer than `eps` (grid of cell eps, 27-neighbour search).
std::vector<std::uint32_t> weld(const Mesh& m, float eps) {
    std::map<std::tuple<long, long, long>, std::vector<std::uint32_t>> grid;
    std::vector<std::uint32_t> rep(m.positions.size());
    for (std::uint32_t i = 0; i < m.positions.size(); ++i) {
        const glm::vec3 p = m.positions[i];
        const long cx = std::lround(std::floor(p.x / eps)), cy = std::lround(std::floor(p.y / eps)),
                   cz = std::lround(std::floor(p.z / eps));
        rep[i] = i;
        bool found = false;
        for (long dx = -1; dx <= 1 && !found; ++dx)
            for (long dy = -1; dy <= 1 && !found; ++dy)
                for (long dz = -1; dz <= 1 && !found; ++dz) {
                    auto it = grid.find({cx + dx, cy + dy, cz + dz});
                    if (it == grid.end()) continue;
                    for (std::uint32_t j : it->second)
                        if (glm::length(m.positions[j] - p) <= eps) {
                            rep[i] = rep[j];
                            found = true;
                            break;
                        }
                }
        grid[{cx, cy, cz}].push_back(i);
    }
    return rep;
}

struct Closure {
    std::size_t unmatched = 0;
    double volume = 0.0;
};

Closure closure(const Mesh& m) {
    const Aabb b = m.bounds();
    // Welding tolerance: float noise of corners computed along different faces, scaled to the mesh.
    const float eps = 1e-5f * std::max(1.0f, glm::length(b.extent()));
    const std::vector<std::uint32_t> rep = weld(m, eps);
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    Closure c;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const std::uint32_t v[3] = {rep[m.indices[t]], rep[m.indices[t + 1]], rep[m.indices[t + 2]]};
        const glm::dvec3 a(m.positions[m.indices[t]]), bb(m.positions[m.indices[t + 1]]), cc(m.positions[m.indices[t + 2]]);
        c.volume += glm::dot(a, glm::cross(bb, cc)) / 6.0;
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) continue;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t x = v[k], y = v[(k + 1) % 3];
            if (x < y) ++edges[{x, y}];
            else --edges[{y, x}];
        }
    }
    for (const auto& e : edges) c.unmatched += static_cast<std::size_t>(std::abs(e.second));
    return c;
}

void expectClosedValid(const Mesh& m, const char* what) {
    SCOPED_TRACE(what);
    ASSERT_GT(m.triangleCount(), 0u);
    EXPECT_EQ(validateMesh(m), "");
    ASSERT_EQ(m.normals.size(), m.positions.size());
    for (const glm::vec3& n : m.normals) {
        ASSERT_TRUE(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z));
        ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f);
    }
    const Closure c = closure(m);
    EXPECT_EQ(c.unmatched, 0u) << "open or inconsistently wound edges";
    EXPECT_GT(c.volume, 0.0) << "faces point inwards";
}

Mesh build(const std::function<void(MeshBuilder&)>& f) {
    Mesh m;
    MeshBuilder b(m);
    f(b);
    return m;
}

TEST(ProceduralMesh, BasicSolidsAreClosedAndOutward) {
    expectClosedValid(build([](MeshBuilder& b) { b.box({-1, -2, -3}, {1, 2, 3}); }), "box");
    expectClosedValid(build([](MeshBuilder& b) { b.bar({0, 0, 0}, {1, 2, 3}, 0.1f); }), "bar");
    expectClosedValid(build([](MeshBuilder& b) { b.cylinder({0, 0, 0}, {0.3f, 2, -1}, 0.5f, 17); }), "cylinder");
    expectClosedValid(build([](MeshBuilder& b) { b.sphere({1, 2, 3}, 2.0f, 24, 12); }), "sphere");
    expectClosedValid(build([](MeshBuilder& b) { b.dome({0, 1, 0}, 3.0f, 20, 6); }), "dome");
    expectClosedValid(build([](MeshBuilder& b) { b.tank({0, 0, 0}, {4, 0, 0}, 1.0f, 32, 8); }), "tank");
}

TEST(ProceduralMesh, SphereVolumeMatchesFormula) {
    const Mesh m = build([](MeshBuilder& b) { b.sphere({0, 0, 0}, 1.0f, 96, 48); });
    const double v = closure(m).volume;
    EXPECT_NEAR(v, 4.0 / 3.0 * 3.14159265358979, 0.01);
}

TEST(ProceduralMesh, TubesWithBendsAreClosed) {
    const std::vector<glm::vec3> path = {{0, 0, 0}, {0, 5, 0}, {4, 5, 0}, {4, 5, 3}, {4, 1, 3}, {6, 0, 5}};
    const Mesh m = build([&](MeshBuilder& b) { b.tube(path, 0.2f, 16, 0.8f, 10); });
    expectClosedValid(m, "bent tube");
    // Straight tube: 2 rings x 16 segments x 2 + two 16-triangle caps.
    const Mesh s = build([](MeshBuilder& b) { b.tube({{0, 0, 0}, {0, 0, 3}}, 0.2f, 16, 0.0f, 0); });
    EXPECT_EQ(s.triangleCount(), 16u * 2 + 2 * 16u);
    // The swept ring keeps its radius along the bends: every side vertex lies 0.2 from the axis path.
    const Aabb box = m.bounds();
    EXPECT_LT(box.min.x, -0.19f);
    EXPECT_GT(box.max.y, 5.19f);
}

TEST(ProceduralMesh, DegenerateTubeInputsAreHandled) {
    // Repeated points are dropped; a single distinct point gives nothing; a U-turn is a sharp corner.
    EXPECT_EQ(build([](MeshBuilder& b) { b.tube({{1, 1, 1}, {1, 1, 1}}, 0.1f, 8, 0.5f, 4); }).triangleCount(), 0u);
    expectClosedValid(build([](MeshBuilder& b) { b.tube({{0, 0, 0}, {0, 0, 0}, {0, 2, 0}, {0, 2, 0}}, 0.1f, 8, 0.5f, 4); }),
                      "duplicates");
    const Mesh u = build([](MeshBuilder& b) { b.tube({{0, 0, 0}, {0, 2, 0}, {0, 0.5f, 0.001f}}, 0.1f, 8, 0.5f, 4); });
    EXPECT_EQ(validateMesh(u), "");
}

TEST(ProceduralMesh, StructuralPartsAreClosed) {
    expectClosedValid(build([](MeshBuilder& b) { b.iBeam({0, 0, 0}, {6, 0, 0}, {0, 1, 0}, 0.6f, 0.3f, 0.03f); }), "ibeam");
    expectClosedValid(build([](MeshBuilder& b) { b.truss({0, 0, 0}, {0, 0, 12}, {0, 1, 0}, 2.0f, 6, 0.1f); }), "truss");
    expectClosedValid(build([](MeshBuilder& b) { b.stairs({0, 0, 0}, {1, 0, 0}, 1.2f, 0.2f, 0.25f, 10); }), "stairs");
    expectClosedValid(build([](MeshBuilder& b) { b.grating({0, 0, 0}, {3, 0, 1}, 0.05f, 0.04f); }), "grating");
}

TEST(ProceduralMesh, WallOpeningsAreCutOut) {
    const Mesh m = build([](MeshBuilder& b) {
        b.wall({0, 0, 0}, {1, 0, 0}, 10.0f, 4.0f, 0.3f, {{1, 1, 3, 2}, {5, 0, 7, 3}});
    });
    expectClosedValid(m, "wall");
    // Area of the front face = full wall minus the openings: 40 - 2 - 6 = 32 m^2; the
    // volume is that times the thickness.
    EXPECT_NEAR(closure(m).volume, 32.0 * 0.3, 1e-3);
}

TEST(ProceduralMesh, RngIsDeterministicAndInRange) {
    procedural::Rng a(42), b(42), c(43);
    bool differs = false;
    for (int i = 0; i < 1000; ++i) {
        const float x = a.uniform(-2.0f, 3.0f);
        EXPECT_EQ(x, b.uniform(-2.0f, 3.0f));
        EXPECT_GE(x, -2.0f);
        EXPECT_LT(x, 3.0f);
        const int k = a.range(-3, 5);
        EXPECT_EQ(k, b.range(-3, 5));
        EXPECT_GE(k, -3);
        EXPECT_LE(k, 5);
        differs |= c.next() != a.next();
        b.next();
    }
    EXPECT_TRUE(differs);
    // Fixed first outputs: the same sequence on every standard library.
    procedural::Rng d(0);
    EXPECT_EQ(d.next(), 0xE220A8397B1DCDAFull);
}

}  // namespace
}  // namespace dyncull
