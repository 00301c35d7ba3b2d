// Ear clipping against brute force: the triangles of a simple polygon must cover exactly
// its area, lie inside it (centroids by a crossing-number test) and keep its winding.
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "dyncull/objects/polygon_triangulation.hpp"

namespace dyncull {
namespace {

// Polygon in the xy plane, then carried into 3D by `toWorld` (so the projection step is tested too).
struct Polygon {
    std::vector<glm::dvec2> flat;
    std::vector<glm::vec3> corners;
};

Polygon place(const std::vector<glm::dvec2>& flat, const glm::mat4& toWorld) {
    Polygon p{flat, {}};
    for (const glm::dvec2& q : flat) p.corners.emplace_back(toWorld * glm::vec4(float(q.x), float(q.y), 0.0f, 1.0f));
    return p;
}

double signedArea(const std::vector<glm::dvec2>& poly) {
    double a = 0.0;
    for (std::size_t i = 0; i < poly.size(); ++i) {
        const glm::dvec2 &p = poly[i], &q = poly[(i + 1) % poly.size()];
        a += p.x * q.y - q.x * p.y;
    }
    return 0.5 * a;
}

bool inside(const std::vector<glm::dvec2>& poly, glm::dvec2 pt) {
    bool in = false;
    for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
        const glm::dvec2 &a = poly[i], &b = poly[j];
        if ((a.y > pt.y) != (b.y > pt.y) && pt.x < (b.x - a.x) * (pt.y - a.y) / (b.y - a.y) + a.x) in = !in;
    }
    return in;
}

double triArea(const std::vector<glm::dvec2>& p, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    return 0.5 * ((p[b].x - p[a].x) * (p[c].y - p[a].y) - (p[b].y - p[a].y) * (p[c].x - p[a].x));
}

// The brute-force checks every simple-polygon case must pass.
void expectExactCover(const Polygon& poly, const std::vector<std::uint32_t>& tris) {
    ASSERT_EQ(tris.size() % 3, 0u);
    const double area = signedArea(poly.flat);
    const double tolerance = 1e-5 * std::abs(area);  // float corners, double sums
    double sum = 0.0;
    for (std::size_t t = 0; t < tris.size(); t += 3) {
        ASSERT_LT(tris[t], poly.flat.size());
        ASSERT_LT(tris[t + 1], poly.flat.size());
        ASSERT_LT(tris[t + 2], poly.flat.size());
        const double a = triArea(poly.flat, tris[t], tris[t + 1], tris[t + 2]);
        EXPECT_GT(a * area, 0.0) << "triangle " << t / 3 << " inverted or flat";
        sum += a;
        const glm::dvec2 centroid = (poly.flat[tris[t]] + poly.flat[tris[t + 1]] + poly.flat[tris[t + 2]]) / 3.0;
        EXPECT_TRUE(inside(poly.flat, centroid)) << "triangle " << t / 3 << " centroid outside";
    }
    EXPECT_NEAR(sum, area, tolerance);
}

std::vector<glm::dvec2> star(int points, double outer, double inner) {
    std::vector<glm::dvec2> p;
    for (int i = 0; i < 2 * points; ++i) {
        const double a = std::numbers::pi * i / points;
        const double r = i % 2 == 0 ? outer : inner;
        p.emplace_back(r * std::cos(a), r * std::sin(a));
    }
    return p;
}

const glm::mat4 kTilted = glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(100.0f, -20.0f, 5.0f)), 0.7f,
                                      glm::normalize(glm::vec3(1.0f, 2.0f, 0.5f)));

TEST(PolygonTriangulation, StarWith200CornersIsNotADisc) {
    for (bool clockwise : {false, true}) {
        auto flat = star(100, 10.0, 3.0);
        if (clockwise) std::reverse(flat.begin(), flat.end());
        const Polygon poly = place(flat, kTilted);
        std::vector<std::uint32_t> tris;
        TriangulationScratch scratch;
        EXPECT_EQ(triangulatePolygon(poly.corners, tris, scratch), Triangulation::Ok);
        EXPECT_EQ(tris.size(), 3 * (flat.size() - 2));
        expectExactCover(poly, tris);
    }
}

TEST(PolygonTriangulation, ConvexPolygonIsTheFanFromCornerZero) {
    const Polygon poly = place({{0, 0}, {2, 0}, {3, 1}, {2, 2}, {0, 2}}, glm::mat4(1.0f));
    std::vector<std::uint32_t> tris;
    TriangulationScratch scratch;
    EXPECT_EQ(triangulatePolygon(poly.corners, tris, scratch), Triangulation::Ok);
    EXPECT_EQ(tris, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4}));
}

TEST(PolygonTriangulation, ConcaveShapesInEveryPlane) {
    // An L, a U (comb) and an arrow, each in the xy, yz and xz planes and both windings.
    const std::vector<std::vector<glm::dvec2>> shapes = {
        {{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 3}, {0, 3}},
        {{0, 0}, {5, 0}, {5, 4}, {4, 4}, {4, 1}, {3, 1}, {3, 4}, {2, 4}, {2, 1}, {1, 1}, {1, 4}, {0, 4}},
        {{0, 1}, {3, 1}, {3, 0}, {5, 2}, {3, 4}, {3, 3}, {0, 3}, {1, 2}},
    };
    const glm::mat4 planes[] = {glm::mat4(1.0f),
                                glm::rotate(glm::mat4(1.0f), float(std::numbers::pi / 2), glm::vec3(0, 1, 0)),
                                glm::rotate(glm::mat4(1.0f), float(std::numbers::pi / 2), glm::vec3(1, 0, 0))};
    TriangulationScratch scratch;
    for (const auto& shape : shapes)
        for (const glm::mat4& m : planes)
            for (bool reverse : {false, true}) {
                auto flat = shape;
                if (reverse) std::reverse(flat.begin(), flat.end());
                const Polygon poly = place(flat, m);
                std::vector<std::uint32_t> tris;
                EXPECT_EQ(triangulatePolygon(poly.corners, tris, scratch), Triangulation::Ok);
                EXPECT_EQ(tris.size(), 3 * (flat.size() - 2));
                expectExactCover(poly, tris);
            }
}

TEST(PolygonTriangulation, CollinearCornersAreKeptWithoutZeroAreaTriangles) {
    // A square with a corner in the middle of each edge: every corner must still be used
    // (a neighbouring face may share it; leaving it out would open a T-junction crack).
    const Polygon poly = place({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}}, kTilted);
    std::vector<std::uint32_t> tris;
    TriangulationScratch scratch;
    EXPECT_EQ(triangulatePolygon(poly.corners, tris, scratch), Triangulation::Ok);
    expectExactCover(poly, tris);
    for (std::uint32_t k = 0; k < poly.corners.size(); ++k)
        EXPECT_NE(std::find(tris.begin(), tris.end(), k), tris.end()) << "corner " << k << " unused";
}

TEST(PolygonTriangulation, DuplicateCornersGiveNoFlatTriangles) {
    const Polygon poly = place({{0, 0}, {0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 1}, {1, 3}, {0, 3}, {0, 0}}, kTilted);
    std::vector<std::uint32_t> tris;
    TriangulationScratch scratch;
    EXPECT_EQ(triangulatePolygon(poly.corners, tris, scratch), Triangulation::Ok);
    expectExactCover(poly, tris);  // includes: no flat triangle
}

TEST(PolygonTriangulation, ZeroAreaPolygonsGiveNoTriangles) {
    TriangulationScratch scratch;
    std::vector<std::uint32_t> tris;
    const std::vector<glm::vec3> line = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}, {1, 1, 1}};
    EXPECT_EQ(triangulatePolygon(line, tris, scratch), Triangulation::ZeroArea);
    const std::vector<glm::vec3> point(6, glm::vec3(4.0f, 5.0f, 6.0f));
    EXPECT_EQ(triangulatePolygon(point, tris, scratch), Triangulation::ZeroArea);
    const std::vector<glm::vec3> nan = {{0, 0, 0}, {1, 0, 0}, {1, NAN, 0}, {0, 1, 0}};
    EXPECT_EQ(triangulatePolygon(nan, tris, scratch), Triangulation::ZeroArea);
    // Tiny but real polygons are not zero-area: the epsilon scales with the polygon.
    const std::vector<glm::vec3> tiny = {{0, 0, 0}, {1e-6f, 0, 0}, {1e-6f, 1e-6f, 0}, {0, 1e-6f, 0}};
    EXPECT_EQ(triangulatePolygon(tiny, tris, scratch), Triangulation::Ok);
    EXPECT_EQ(tris.size(), 6u);
}

TEST(PolygonTriangulation, SelfIntersectingPolygonFallsBackToValidIndices) {
    // A bow tie and a pentagram: no simple triangulation exists; the result must still index the polygon.
    const std::vector<std::vector<glm::vec3>> tangled = {
        {{0, 0, 0}, {2, 2, 0}, {2, 0, 0}, {0, 2, 0}, {-1, 1, 0}},
        {{0, 1, 0}, {0.588f, -0.809f, 0}, {-0.951f, 0.309f, 0}, {0.951f, 0.309f, 0}, {-0.588f, -0.809f, 0}}};
    TriangulationScratch scratch;
    for (const auto& poly : tangled) {
        std::vector<std::uint32_t> tris;
        const Triangulation r = triangulatePolygon(poly, tris, scratch);
        EXPECT_TRUE(r == Triangulation::Tangled || r == Triangulation::Ok);
        EXPECT_EQ(tris.size() % 3, 0u);
        EXPECT_FALSE(tris.empty());
        for (std::uint32_t k : tris) EXPECT_LT(k, poly.size());
    }
}

TEST(PolygonTriangulation, HugeSpikyPolygonHitsTheWorkBudget) {
    // 40000 corners, half of them reflex: the quadratic ear search would take minutes.
    const Polygon poly = place(star(20000, 10.0, 9.0), glm::mat4(1.0f));
    std::vector<std::uint32_t> tris = {7, 7, 7};
    TriangulationScratch scratch;
    EXPECT_EQ(triangulatePolygon(poly.corners, tris, scratch), Triangulation::TooComplex);
    EXPECT_EQ(tris, (std::vector<std::uint32_t>{7, 7, 7}));  // nothing appended
}

}  // namespace
}  // namespace dyncull
