// Procedural primitives for the generated demo scenes (power plant, city): boxes,
// capped cylinders and tanks, spheres and domes, swept tubes with bends, I-beams,
// lattice trusses, stairs, gratings and walls with openings. Every primitive is a union
// of closed, consistently wound (counter-clockwise outside) components with unit
// normals, so each passes validateMesh and is watertight component by component.
// Tube frames: Wang, Juttler, Zheng, Liu, "Computation of rotation minimizing frames",
// ACM TOG 27(1), 2008 (the double reflection method).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/objects/mesh.hpp"

namespace dyncull::procedural {

/// Deterministic generator (SplitMix64) with our own float/int mapping, so every standard
/// library produces the same scenes for the same seed.
class Rng {
public:
    explicit Rng(std::uint64_t seed) : s_(seed) {}
    std::uint64_t next();
    /// Uniform in [lo, hi) from the top 24 bits (exact in float).
    float uniform(float lo, float hi);
    /// Uniform integer in [lo, hi] (hi >= lo; modulo bias below 2^-32 is irrelevant here).
    int range(int lo, int hi);
    bool chance(float p) { return uniform(0.0f, 1.0f) < p; }

private:
    std::uint64_t s_;
};

/// Appends primitives to one mesh (object space, units of the caller, Y up). Borrows the
/// mesh; every add keeps normals one per position.
class MeshBuilder {
public:
    explicit MeshBuilder(Mesh& mesh) : m_(mesh) {}

    /// Axis-aligned box [lo, hi] (24 vertices, 12 triangles, flat faces).
    void box(const glm::vec3& lo, const glm::vec3& hi);
    /// Oriented box: centre, three orthonormal axes, half extents along them.
    void orientedBox(const glm::vec3& centre, const glm::vec3& ax, const glm::vec3& ay, const glm::vec3& az,
                     const glm::vec3& half);
    /// Square bar of side `thickness` from a to b (a != b), for struts, rails and legs.
    void bar(const glm::vec3& a, const glm::vec3& b, float thickness);
    /// Capped cylinder from a to b, `segments` >= 3 around.
    void cylinder(const glm::vec3& a, const glm::vec3& b, float radius, std::uint32_t segments);
    /// UV sphere, `segments` >= 3 around and `rings` >= 2 from pole to pole.
    void sphere(const glm::vec3& centre, float radius, std::uint32_t segments, std::uint32_t rings);
    /// Half sphere over the disc at `base` facing +Y (closed by a flat disc underneath).
    void dome(const glm::vec3& base, float radius, std::uint32_t segments, std::uint32_t rings);
    /// Vertical or horizontal tank: cylinder from a to b with hemispherical heads at both ends.
    void tank(const glm::vec3& a, const glm::vec3& b, float radius, std::uint32_t segments, std::uint32_t headRings);
    /// Circular tube swept along a polyline (>= 2 points, consecutive points distinct). Each
    /// corner becomes a circular bend of radius `bendRadius` (clamped to fit the legs),
    /// sampled with `bendSteps` rings; the ends are capped. Frames are rotation-minimising.
    void tube(const std::vector<glm::vec3>& polyline, float radius, std::uint32_t segments, float bendRadius,
              std::uint32_t bendSteps);
    /// I-beam from a to b: web height `height`, flange width `width`, plate thickness
    /// `thickness`; `up` (not parallel to b - a) is the direction of the web.
    void iBeam(const glm::vec3& a, const glm::vec3& b, const glm::vec3& up, float height, float width, float thickness);
    /// Planar lattice truss from a to b: top and bottom chords `depth` apart along `up`,
    /// `bays` panels with verticals and alternating diagonals, square bars of `bar`.
    void truss(const glm::vec3& a, const glm::vec3& b, const glm::vec3& up, float depth, std::uint32_t bays, float bar);
    /// Straight flight from `base` going along +dir (unit, horizontal) and up: `steps` treads
    /// of `width` x `run` rising `rise` each, plus two stringers.
    void stairs(const glm::vec3& base, const glm::vec3& dir, float width, float rise, float run, std::uint32_t steps);
    /// Grating floor over [lo, hi] (xz rectangle at lo.y): bearing bars along x every
    /// `pitch`, cross bars along z every 4 pitches, plus a frame.
    void grating(const glm::vec3& lo, const glm::vec3& hi, float pitch, float barHeight);
    /// Axis-aligned rectangular opening in a wall, in wall coordinates (u along, v up).
    struct Opening {
        float u0, v0, u1, v1;
    };
    /// Wall slab on the plane through `origin` spanned by unit `along` (u) and +Y (v),
    /// `length` x `height`, `thickness` thick towards `along` x Y; openings are cut out by
    /// tiling the rest with boxes (openings must lie inside and not overlap).
    void wall(const glm::vec3& origin, const glm::vec3& along, float length, float height, float thickness,
              const std::vector<Opening>& openings);

private:
    std::uint32_t vertex(const glm::vec3& p, const glm::vec3& n);
    void tri(std::uint32_t a, std::uint32_t b, std::uint32_t c);
    /// Closes a ring of vertices [first, first + count) with a fan around `centre`, normal `n`.
    void cap(const std::vector<glm::vec3>& ring, const glm::vec3& centre, const glm::vec3& n);
    Mesh& m_;
};

/// Unit vector perpendicular to `v` (v non-zero).
glm::vec3 anyPerpendicular(const glm::vec3& v);

}  // namespace dyncull::procedural
