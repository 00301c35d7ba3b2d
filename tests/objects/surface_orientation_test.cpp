// Surface analysis (analyseSurface / orientSurface). Oracles: volumes computed here from
// the indices by the divergence theorem (so a flip is checked by the geometry it leaves,
// not by the report alone), exact edge/hole counts of hand-built cubes, re-analysis after
// orientSurface (nothing left to flip, same topology), and the real Stanford bunny.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "dyncull/objects/hole_capping.hpp"
#include "dyncull/loaders/loaders.hpp"
#include "dyncull/objects/surface_orientation.hpp"

using namespace dyncull;

namespace {

/// Signed volume of the triangles [first, last) about `origin`, in double.
double volumeOf(const Mesh& m, glm::dvec3 origin, std::size_t first = 0, std::size_t last = ~std::size_t(0)) {
    last = std::min(last, m.triangleCount());
    double v = 0.0;
    for (std::size_t t = first; t < last; ++t) {
        const glm::dvec3 a = glm::dvec3(m.positions[m.indices[3 * t]]) - origin;
        const glm::dvec3 b = glm::dvec3(m.positions[m.indices[3 * t + 1]]) - origin;
        const glm::dvec3 c = glm::dvec3(m.positions[m.indices[3 * t + 2]]) - origin;
        v += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
    return v;
}

/// Appends an axis-aligned cube (12 triangles, counter-clockwise seen from outside) at
/// `lo` with side `side`. `perFace`: each face has its own 4 vertices, as loaders emit at
/// normal seams; otherwise the 8 corners are shared.
void addCube(Mesh& m, glm::vec3 lo, float side, bool perFace = false) {
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    auto corner = [&](int bits) {
        return lo + side * glm::vec3(float(bits & 1), float((bits >> 1) & 1), float((bits >> 2) & 1));
    };
    if (!perFace)
        for (int i = 0; i < 8; ++i) m.positions.push_back(corner(i));
    for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        for (int s = 0; s < 2; ++s) {
            // Corners of the face in a cycle over (u, v).
            const int cyc[4] = {s << axis, (s << axis) | (1 << u), (s << axis) | (1 << u) | (1 << v),
                                (s << axis) | (1 << v)};
            std::uint32_t q[4];
            for (int k = 0; k < 4; ++k) {
                if (perFace) {
                    q[k] = static_cast<std::uint32_t>(m.positions.size());
                    m.positions.push_back(corner(cyc[k]));
                } else {
                    q[k] = base + static_cast<std::uint32_t>(cyc[k]);
                }
            }
            // Wind the face around its outward normal (+axis on side 1, -axis on side 0).
            const glm::vec3 n = glm::cross(corner(cyc[1]) - corner(cyc[0]), corner(cyc[2]) - corner(cyc[0]));
            if ((n[axis] > 0.0f) != (s == 1)) std::swap(q[1], q[3]);
            m.indices.insert(m.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
        }
    }
}

void invertTriangles(Mesh& m, std::size_t first, std::size_t last) {
    for (std::size_t t = first; t < last; ++t) std::swap(m.indices[3 * t + 1], m.indices[3 * t + 2]);
}

Mesh cube(float side = 2.0f, glm::vec3 lo = glm::vec3(0.0f), bool perFace = false) {
    Mesh m;
    addCube(m, lo, side, perFace);
    return m;
}

/// orientSurface, then checks that a second analysis finds nothing to flip and the same
/// topology, volume and mode: orienting is idempotent and the report describes the result.
SurfaceReport orientAndRecheck(Mesh& m) {
    const SurfaceReport first = orientSurface(m);
    const SurfaceReport again = analyseSurface(m);
    EXPECT_EQ(again.flippedShells, 0u);
    EXPECT_EQ(again.mode, first.mode);
    EXPECT_EQ(again.edges, first.edges);
    EXPECT_EQ(again.boundaryEdges, first.boundaryEdges);
    EXPECT_EQ(again.misorientedEdges, first.misorientedEdges);
    EXPECT_EQ(again.shells, first.shells);
    EXPECT_EQ(again.cavityShells, first.cavityShells);
    EXPECT_NEAR(again.signedVolume, first.signedVolume, 1e-9 * std::max(1.0, std::abs(first.signedVolume)));
    return first;
}

TEST(SurfaceOrientation, ClosedOutwardCubeCullsBackFaces) {
    Mesh m = cube(2.0f);
    const std::vector<std::uint32_t> before = m.indices;
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_EQ(r.mode, FaceMode::CullBack);
    EXPECT_EQ(r.triangles, 12u);
    EXPECT_EQ(r.weldedVertices, 8u);
    EXPECT_EQ(r.edges, 18u);  // Euler: V - E + F = 2
    EXPECT_TRUE(r.closed());
    EXPECT_TRUE(r.consistent());
    EXPECT_EQ(r.shells, 1u);
    EXPECT_EQ(r.closedShells, 1u);
    EXPECT_EQ(r.flippedShells, 0u);
    EXPECT_DOUBLE_EQ(r.signedVolume, 8.0);
    EXPECT_EQ(m.indices, before);
    EXPECT_EQ(r.summary(), "closed, consistent, outward: cull back faces");
}

TEST(SurfaceOrientation, InvertedCubeIsFlipped) {
    Mesh m = cube(2.0f);
    invertTriangles(m, 0, 12);
    ASSERT_DOUBLE_EQ(volumeOf(m, glm::dvec3(0.0)), -8.0);
    const SurfaceReport preview = analyseSurface(m);
    EXPECT_EQ(preview.flippedShells, 1u);
    EXPECT_DOUBLE_EQ(volumeOf(m, glm::dvec3(0.0)), -8.0);  // analysis alone changes nothing
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_EQ(r.mode, FaceMode::CullBack);
    EXPECT_EQ(r.flippedShells, 1u);
    EXPECT_DOUBLE_EQ(r.signedVolume, 8.0);
    EXPECT_DOUBLE_EQ(volumeOf(m, glm::dvec3(0.0)), 8.0);
    EXPECT_DOUBLE_EQ(volumeOf(m, glm::dvec3(-3.0, 5.0, 7.0)), 8.0);  // closed: any origin
    EXPECT_NE(r.summary().find("1 flipped"), std::string::npos) << r.summary();
}

TEST(SurfaceOrientation, CubeWithMissingFaceIsOpen) {
    Mesh m = cube(2.0f);
    m.indices.resize(m.indices.size() - 6);  // drop the last face's two triangles
    const std::vector<std::uint32_t> before = m.indices;
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_EQ(r.mode, FaceMode::TwoSided);
    EXPECT_EQ(r.boundaryEdges, 4u);
    EXPECT_EQ(r.holes, 1u);
    EXPECT_EQ(r.edges, 17u);  // the missing face's diagonal is gone
    EXPECT_FALSE(r.closed());
    EXPECT_TRUE(r.consistent());
    EXPECT_EQ(r.closedShells, 0u);
    EXPECT_EQ(m.indices, before);
    EXPECT_EQ(r.summary(), "open (4 boundary edges in 1 hole): two-sided");
}

TEST(SurfaceOrientation, OneFlippedTriangleIsInconsistent) {
    Mesh m = cube(2.0f);
    invertTriangles(m, 5, 6);
    const std::vector<std::uint32_t> before = m.indices;
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_EQ(r.mode, FaceMode::TwoSided);
    EXPECT_TRUE(r.closed());
    EXPECT_FALSE(r.consistent());
    EXPECT_EQ(r.misorientedEdges, 3u);  // each of its edges runs the same way as its neighbour's
    EXPECT_EQ(r.flippedShells, 0u);
    EXPECT_EQ(m.indices, before);  // an inconsistent shell is never flipped
    EXPECT_NE(r.summary().find("inconsistent (3 misoriented edges)"), std::string::npos) << r.summary();
}

TEST(SurfaceOrientation, SeparateInvertedShellIsFlippedAlone) {
    Mesh m = cube(1.0f);
    addCube(m, glm::vec3(5.0f, 0.0f, 0.0f), 2.0f);
    invertTriangles(m, 12, 24);
    const std::vector<std::uint32_t> before = m.indices;
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_EQ(r.mode, FaceMode::CullBack);
    EXPECT_EQ(r.shells, 2u);
    EXPECT_EQ(r.closedShells, 2u);
    EXPECT_EQ(r.flippedShells, 1u);
    EXPECT_EQ(r.cavityShells, 0u);
    EXPECT_DOUBLE_EQ(r.signedVolume, 9.0);
    EXPECT_TRUE(std::equal(before.begin(), before.begin() + 36, m.indices.begin()));  // outward one untouched
    EXPECT_DOUBLE_EQ(volumeOf(m, glm::dvec3(0.0), 12, 24), 8.0);
}

TEST(SurfaceOrientation, HollowCubeKeepsItsCavity) {
    Mesh m = cube(4.0f);
    addCube(m, glm::vec3(1.0f), 2.0f);
    invertTriangles(m, 12, 24);  // the inner wall faces into the hollow, on purpose
    const std::vector<std::uint32_t> before = m.indices;
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_EQ(r.mode, FaceMode::CullBack);
    EXPECT_EQ(r.shells, 2u);
    EXPECT_EQ(r.cavityShells, 1u);
    EXPECT_EQ(r.flippedShells, 0u);
    EXPECT_DOUBLE_EQ(r.signedVolume, 64.0 - 8.0);
    EXPECT_EQ(m.indices, before);
    EXPECT_EQ(r.summary(), "closed, consistent, outward (2 shells, 1 cavity): cull back faces");
}

TEST(SurfaceOrientation, CavityTouchingItsContainerIsKept) {
    // The hollow shares a corner and parts of three faces with the outer wall: tests from
    // those points are undecided, the others find it inside.
    Mesh m = cube(4.0f);
    addCube(m, glm::vec3(0.0f), 2.0f);
    invertTriangles(m, 12, 24);
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_EQ(r.weldedVertices, 15u);
    EXPECT_EQ(r.shells, 2u);  // a shared corner, no shared edge
    EXPECT_EQ(r.cavityShells, 1u);
    EXPECT_EQ(r.flippedShells, 0u);
    EXPECT_EQ(r.mode, FaceMode::CullBack);
    EXPECT_DOUBLE_EQ(r.signedVolume, 56.0);
}

TEST(SurfaceOrientation, HollowCubeWithInvertedOuterWallIsRepaired) {
    // Both walls face inwards: the outer one is wrong (it contains nothing outward), and once
    // flipped it is the container of the inner one, which is then a cavity and stays.
    Mesh m = cube(4.0f);
    addCube(m, glm::vec3(1.0f), 2.0f);
    invertTriangles(m, 0, 24);
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_EQ(r.mode, FaceMode::CullBack);
    EXPECT_EQ(r.flippedShells, 1u);
    EXPECT_EQ(r.cavityShells, 1u);
    EXPECT_DOUBLE_EQ(volumeOf(m, glm::dvec3(0.0), 0, 12), 64.0);
    EXPECT_DOUBLE_EQ(volumeOf(m, glm::dvec3(0.0), 12, 24), -8.0);
}

TEST(SurfaceOrientation, OutwardShellInsideAnotherIsLeftOutward) {
    // An eye inside a head: two outward shells, one inside the other. Nothing is flipped.
    Mesh m = cube(4.0f);
    addCube(m, glm::vec3(1.0f), 2.0f);
    const std::vector<std::uint32_t> before = m.indices;
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_EQ(r.mode, FaceMode::CullBack);
    EXPECT_EQ(r.flippedShells + r.cavityShells, 0u);
    EXPECT_DOUBLE_EQ(r.signedVolume, 72.0);
    EXPECT_EQ(m.indices, before);
}

TEST(SurfaceOrientation, ManyCavitiesInsideOneShell) {
    // 1,000 inward cubes inside one outward cube, plus 10 inward ones outside it.
    Mesh m = cube(40.0f);
    for (int i = 0; i < 1000; ++i)
        addCube(m, glm::vec3(float(i % 10), float(i / 10 % 10), float(i / 100)) * 3.5f + 2.0f, 1.0f);
    for (int i = 0; i < 10; ++i) addCube(m, glm::vec3(50.0f + 2.0f * float(i), 0.0f, 0.0f), 1.0f);
    invertTriangles(m, 12, m.triangleCount());
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_EQ(r.mode, FaceMode::CullBack);
    EXPECT_EQ(r.shells, 1011u);
    EXPECT_EQ(r.cavityShells, 1000u);
    EXPECT_EQ(r.flippedShells, 10u);
    EXPECT_DOUBLE_EQ(r.signedVolume, 64000.0 - 1000.0 + 10.0);
    // About the origin, far from most cubes: products of coordinates near 30 round.
    EXPECT_NEAR(volumeOf(m, glm::dvec3(0.0), 12, 12 + 12 * 1000), -1000.0, 1e-9);
    EXPECT_NEAR(volumeOf(m, glm::dvec3(0.0), 12 + 12 * 1000, m.triangleCount()), 10.0, 1e-9);
}

TEST(SurfaceOrientation, MirroredExportWithThousandsOfShellsIsFlipped) {
    // 10,000 separate inward cubes (a model exported through a mirroring transform): each is
    // checked for containers through the box tree, not against every other shell, so the
    // nesting budget (linear in the triangles) is not exhausted and every one is flipped.
    Mesh m;
    for (int i = 0; i < 10000; ++i)
        addCube(m, glm::vec3(float(i % 25), float(i / 25 % 20), float(i / 500)) * 2.0f, 1.0f);
    invertTriangles(m, 0, m.triangleCount());
    const auto t0 = std::chrono::steady_clock::now();
    const SurfaceReport r = orientAndRecheck(m);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.shells, 10000u);
    EXPECT_EQ(r.flippedShells, 10000u);
    EXPECT_EQ(r.ambiguousShells, 0u);
    EXPECT_EQ(r.mode, FaceMode::CullBack);
    EXPECT_DOUBLE_EQ(r.signedVolume, 10000.0);
    EXPECT_LT(ms, 5000.0);
    RecordProperty("orient_ms", static_cast<int>(ms));
}

TEST(SurfaceOrientation, SeamDuplicatesAreWelded) {
    Mesh m = cube(2.0f, glm::vec3(-1.0f), /*perFace=*/true);
    ASSERT_EQ(m.positions.size(), 24u);
    // A -0.0 coordinate must weld with +0.0.
    Mesh z = cube(1.0f, glm::vec3(0.0f), true);
    for (glm::vec3& p : z.positions)
        if (p.x == 0.0f && &p - z.positions.data() < 12) p.x = -0.0f;
    for (Mesh* mesh : {&m, &z}) {
        const SurfaceReport r = orientAndRecheck(*mesh);
        EXPECT_EQ(r.weldedVertices, 8u);
        EXPECT_EQ(r.edges, 18u);
        EXPECT_TRUE(r.closed());
        EXPECT_EQ(r.mode, FaceMode::CullBack);
    }
    EXPECT_DOUBLE_EQ(analyseSurface(m).signedVolume, 8.0);
}

TEST(SurfaceOrientation, DegenerateTrianglesAreIgnored) {
    Mesh m = cube(2.0f, glm::vec3(0.0f), true);
    m.indices.insert(m.indices.end(), {0, 0, 1});  // repeats an index
    m.positions.push_back(m.positions[0]);          // repeats a position under another index
    m.indices.insert(m.indices.end(), {0, 5, static_cast<std::uint32_t>(m.positions.size() - 1)});
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_EQ(r.triangles, 14u);
    EXPECT_EQ(r.degenerateTriangles, 2u);
    EXPECT_EQ(r.mode, FaceMode::CullBack);
    EXPECT_EQ(r.summary(), "closed, consistent, outward: cull back faces; 2 degenerate triangles ignored");

    // Collinear but distinct vertices are a real (open) triangle, not a degenerate one.
    Mesh c = cube(2.0f);
    const auto n = static_cast<std::uint32_t>(c.positions.size());
    c.positions.insert(c.positions.end(), {glm::vec3(5, 0, 0), glm::vec3(6, 0, 0), glm::vec3(7, 0, 0)});
    c.indices.insert(c.indices.end(), {n, n + 1, n + 2});
    const SurfaceReport rc = analyseSurface(c);
    EXPECT_EQ(rc.degenerateTriangles, 0u);
    EXPECT_EQ(rc.shells, 2u);
    EXPECT_EQ(rc.boundaryEdges, 3u);
    EXPECT_EQ(rc.mode, FaceMode::TwoSided);
}

TEST(SurfaceOrientation, NonManifoldEdgeIsTwoSided) {
    Mesh m = cube(2.0f);
    // A fin on the cube's edge from corner 0 to corner 1: a third triangle on that edge.
    m.positions.push_back(glm::vec3(1.0f, -3.0f, -3.0f));
    m.indices.insert(m.indices.end(), {0, 1, 8});
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_EQ(r.mode, FaceMode::TwoSided);
    EXPECT_EQ(r.nonManifoldEdges, 1u);
    EXPECT_EQ(r.boundaryEdges, 2u);
    EXPECT_EQ(r.shells, 1u);
    EXPECT_FALSE(r.closed());
    EXPECT_NE(r.summary().find("non-manifold (1 edge)"), std::string::npos) << r.summary();
}

TEST(SurfaceOrientation, CoincidentOppositeQuadHasZeroVolume) {
    // A quad and its back, both drawn: the back split along the other diagonal, so every
    // edge has exactly two opposite uses (closed, consistent) and the volume is exactly 0.
    Mesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    m.indices = {0, 1, 2, 0, 2, 3, 1, 0, 3, 1, 3, 2};
    const std::vector<std::uint32_t> before = m.indices;
    const SurfaceReport r = orientAndRecheck(m);
    EXPECT_TRUE(r.closed());
    EXPECT_TRUE(r.consistent());
    EXPECT_EQ(r.closedShells, 1u);
    EXPECT_EQ(r.zeroVolumeShells, 1u);
    EXPECT_EQ(r.signedVolume, 0.0);
    EXPECT_EQ(r.mode, FaceMode::TwoSided);
    EXPECT_EQ(m.indices, before);
    EXPECT_EQ(r.summary(), "1 flat closed shell (zero volume): two-sided");

    // Split along the same diagonal on both sides, that diagonal has four uses.
    Mesh same = m;
    same.indices = {0, 1, 2, 0, 2, 3, 0, 2, 1, 0, 3, 2};
    const SurfaceReport rs = analyseSurface(same);
    EXPECT_EQ(rs.nonManifoldEdges, 1u);
    EXPECT_EQ(rs.mode, FaceMode::TwoSided);

    // A single triangle and its back; and a closed box squashed to a plate one float ulp
    // thick (1e-7 of its size), which is flat to the precision of its coordinates.
    Mesh tri = m;
    tri.indices = {0, 1, 2, 0, 2, 1};
    EXPECT_EQ(analyseSurface(tri).zeroVolumeShells, 1u);
    Mesh plate = cube(1.0f);
    for (glm::vec3& p : plate.positions) p.z *= 1e-7f;
    const SurfaceReport rp = analyseSurface(plate);
    EXPECT_TRUE(rp.closed());
    EXPECT_EQ(rp.zeroVolumeShells, 1u);
    EXPECT_EQ(rp.mode, FaceMode::TwoSided);
    Mesh thin = cube(1.0f);  // 1e-4 thick: thin, but a real solid
    for (glm::vec3& p : thin.positions) p.z *= 1e-4f;
    EXPECT_EQ(analyseSurface(thin).mode, FaceMode::CullBack);
}

TEST(SurfaceOrientation, HugeCoordinatesKeepTheVolumeSign) {
    for (float offset : {1e6f, -3e6f}) {
        Mesh m = cube(1.0f, glm::vec3(offset, 2.0f * offset, offset));
        const SurfaceReport r = analyseSurface(m);
        EXPECT_EQ(r.mode, FaceMode::CullBack);
        EXPECT_DOUBLE_EQ(r.signedVolume, 1.0);
        invertTriangles(m, 0, 12);
        const SurfaceReport inv = orientAndRecheck(m);
        EXPECT_EQ(inv.flippedShells, 1u);
        EXPECT_EQ(inv.mode, FaceMode::CullBack);
        EXPECT_DOUBLE_EQ(volumeOf(m, glm::dvec3(offset, 2.0 * offset, offset)), 1.0);
    }
    // A hollow one far away: the nesting test works relative to the data too.
    Mesh h = cube(4.0f, glm::vec3(1e6f));
    addCube(h, glm::vec3(1e6f + 1.0f), 2.0f);
    invertTriangles(h, 12, 24);
    const SurfaceReport rh = analyseSurface(h);
    EXPECT_EQ(rh.cavityShells, 1u);
    EXPECT_EQ(rh.mode, FaceMode::CullBack);
}

TEST(SurfaceOrientation, EmptyMeshIsTwoSided) {
    Mesh m;
    const SurfaceReport r = orientSurface(m);
    EXPECT_EQ(r.mode, FaceMode::TwoSided);  // nothing to draw either way
    EXPECT_EQ(r.shells, 0u);
    EXPECT_EQ(r.triangles, 0u);
    EXPECT_NE(r.summary().find("empty"), std::string::npos);
    Mesh d;
    d.positions = {{0, 0, 0}, {1, 0, 0}};
    d.indices = {0, 1, 1};
    const SurfaceReport rd = analyseSurface(d);
    EXPECT_EQ(rd.mode, FaceMode::TwoSided);
    EXPECT_EQ(rd.degenerateTriangles, 1u);
    EXPECT_EQ(rd.shells, 0u);
}

std::filesystem::path dataFile(const char* name) {
    std::filesystem::path dir;
    if (const char* env = std::getenv("DYNCULL_DATA"); env && *env) dir = env;
    else dir = DYNCULL_SHARED_DATA_DIR;
    return dir / name;
}

TEST(SurfaceOrientation, StanfordBunnyIsOpenAndOutward) {
    const auto path = dataFile("bun_zipper.ply");
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not available";
    auto scene = loadScene(path);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->meshes.size(), 1u);
    Mesh& m = scene->meshes[0];
    const std::vector<std::uint32_t> before = m.indices;
    const auto t0 = std::chrono::steady_clock::now();
    const SurfaceReport r = orientSurface(m);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.triangles, 69451u);
    EXPECT_EQ(r.boundaryEdges, 223u);
    EXPECT_GE(r.holes, 1u);
    EXPECT_TRUE(r.consistent());
    EXPECT_GT(r.signedVolume, 0.0);  // open, but outward: about its box centre the volume is positive
    EXPECT_EQ(r.flippedShells, 0u);
    EXPECT_EQ(r.mode, FaceMode::TwoSided);
    EXPECT_EQ(m.indices, before);
    RecordProperty("orient_ms", static_cast<int>(ms));  // speed is the benchmarks' business, not an assertion
    std::printf("bunny: %s (%.2f ms)\n", r.summary().c_str(), ms);

    // Its five holes (the scanner could not see the base) capped: a closed solid.
    const HoleCapping capped = capHoles(m, m.indices.size());
    EXPECT_EQ(capped.holes, r.holes);
    EXPECT_EQ(capped.triangles, 223u);  // one per boundary edge
    EXPECT_EQ(capped.skippedLoops, 0u);
    const SurfaceReport closed = analyseSurface(m);
    EXPECT_TRUE(closed.closed() && closed.consistent()) << closed.summary();
    EXPECT_EQ(closed.mode, FaceMode::CullBack) << closed.summary();
}

TEST(SurfaceOrientation, NpmBunnyIsClosedAndOutward) {
    // scripts/setup.sh writes it to ./assets ($DYNCULL_ASSETS overrides, as for the demos).
    std::filesystem::path path = DYNCULL_ASSETS_DIR "/bunny_npm.ply";
    if (const char* env = std::getenv("DYNCULL_ASSETS"); env && *env) path = std::filesystem::path(env) / "bunny_npm.ply";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not available";
    auto scene = loadScene(path);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->meshes.size(), 1u);
    const SurfaceReport r = analyseSurface(scene->meshes[0]);
    EXPECT_EQ(r.triangles, 3674u);
    EXPECT_TRUE(r.closed());  // unlike the Stanford scan, the npm bunny is watertight
    EXPECT_TRUE(r.consistent());
    EXPECT_EQ(r.shells, 1u);
    EXPECT_GT(r.signedVolume, 0.0);
    EXPECT_EQ(r.flippedShells, 0u);
    EXPECT_EQ(r.mode, FaceMode::CullBack);
}

// A flat square (two triangles, counter-clockwise seen from +z) at `lo` with side `side`.
void addSquare(Mesh& m, glm::vec3 lo, float side) {
    const auto b = static_cast<std::uint32_t>(m.positions.size());
    m.positions.insert(m.positions.end(), {lo, lo + glm::vec3(side, 0, 0), lo + glm::vec3(side, side, 0), lo + glm::vec3(0, side, 0)});
    m.indices.insert(m.indices.end(), {b, b + 1, b + 2, b, b + 2, b + 3});
}

TEST(HoleCapping, CubeWithMissingFaceIsClosedAgain) {
    for (const bool perFace : {false, true}) {  // seam duplicates must not split the rim
        Mesh m = cube(2.0f, glm::vec3(0.0f), perFace);
        m.indices.resize(m.indices.size() - 6);  // the last face (+z) missing
        ASSERT_EQ(analyseSurface(m).mode, FaceMode::TwoSided);
        const std::size_t vertices = m.positions.size();
        const HoleCapping c = capHoles(m, 100);
        EXPECT_EQ(c.holes, 1u);
        EXPECT_EQ(c.triangles, 4u);
        EXPECT_EQ(c.skippedLoops, 0u);
        EXPECT_EQ(m.positions.size(), vertices + 1);
        EXPECT_EQ(m.positions.back(), glm::vec3(1.0f, 1.0f, 2.0f));  // the centre of the missing face
        EXPECT_TRUE(validateMesh(m).empty()) << validateMesh(m);
        const SurfaceReport r = analyseSurface(m);
        EXPECT_TRUE(r.closed() && r.consistent()) << r.summary();
        EXPECT_EQ(r.mode, FaceMode::CullBack);
        EXPECT_NEAR(volumeOf(m, glm::dvec3(0.0)), 8.0, 1e-9) << "the cap is the missing face, wound outwards";
    }
}

TEST(HoleCapping, CapVertexGetsAnOutwardNormal) {
    Mesh m = cube();
    m.indices.resize(m.indices.size() - 6);
    computeNormals(m);
    capHoles(m, 100);
    ASSERT_EQ(m.normals.size(), m.positions.size());
    EXPECT_NEAR(m.normals.back().z, 1.0f, 1e-6f);
}

TEST(HoleCapping, TwoHolesAreCappedSeparately) {
    Mesh m = cube();
    m.indices.erase(m.indices.begin(), m.indices.begin() + 12);  // the faces x = 0 and x = 2
    const HoleCapping c = capHoles(m, 100);
    EXPECT_EQ(c.holes, 2u);
    EXPECT_EQ(c.triangles, 8u);
    EXPECT_EQ(analyseSurface(m).mode, FaceMode::CullBack);
    EXPECT_NEAR(volumeOf(m, glm::dvec3(0.0)), 8.0, 1e-9);
}

TEST(HoleCapping, LoopLongerThanTheLimitStaysOpen) {
    Mesh m = cube();
    m.indices.resize(m.indices.size() - 6);
    const Mesh before = m;
    const HoleCapping c = capHoles(m, 3);
    EXPECT_EQ(c.holes, 0u);
    EXPECT_EQ(c.skippedLoops, 1u);
    EXPECT_EQ(m.indices, before.indices);
    EXPECT_EQ(m.positions, before.positions);
}

TEST(HoleCapping, LoopsTouchingAtAVertexAreLeftOpen) {
    // Two squares sharing one corner: that rim vertex starts two rim edges.
    Mesh m;
    addSquare(m, glm::vec3(0.0f), 1.0f);
    addSquare(m, glm::vec3(1.0f, 1.0f, 0.0f), 1.0f);
    const HoleCapping c = capHoles(m, 100);
    EXPECT_EQ(c.holes, 0u);
    EXPECT_EQ(c.skippedLoops, 2u);
    EXPECT_EQ(m.triangleCount(), 4u);
}

TEST(HoleCapping, CappedSheetIsFlatAndStaysTwoSided) {
    // A lone square is all rim: its cap is a second, opposite square, a closed shell of zero
    // volume, which must not be culled (one side would vanish from behind).
    Mesh m;
    addSquare(m, glm::vec3(0.0f), 1.0f);
    EXPECT_EQ(capHoles(m, 100).holes, 1u);
    const SurfaceReport r = analyseSurface(m);
    EXPECT_TRUE(r.closed());
    EXPECT_EQ(r.mode, FaceMode::TwoSided) << r.summary();
}

TEST(HoleCapping, CappingDoesNotHideInconsistentWinding) {
    Mesh m = cube();
    m.indices.resize(m.indices.size() - 6);
    invertTriangles(m, 8, 9);  // in the face z = 0, away from the hole at z = 2: the rim is clean
    const HoleCapping c = capHoles(m, 100);
    EXPECT_EQ(c.holes, 1u);
    const SurfaceReport r = analyseSurface(m);
    EXPECT_TRUE(r.closed());
    EXPECT_GT(r.misorientedEdges, 0u);
    EXPECT_EQ(r.mode, FaceMode::TwoSided);
}

}  // namespace
