// Deterministic motion (our own code, no physics library): objects moving on straight
// lines and bouncing off the walls of a box, and smooth camera paths through waypoints.
// Both are closed-form in the frame index, so the same seed gives the same positions at
// every frame on every run, independent of frame rate or of which frames were sampled.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/camera.hpp"

namespace dyncull {

/// Points bouncing inside `box` (world units; velocities in units per frame).
class BouncingMotion {
public:
    /// `count` points with seeded start positions inside `box` and random directions at
    /// `speed` units/frame. `margin` keeps each point that far from the walls (e.g. the
    /// object's bounding radius), so the object's box stays inside; on an axis where
    /// `margin` exceeds half the box extent the points stay at the box centre.
    /// Precondition (asserted): `box` finite and non-empty. Uses std::mt19937_64 with our
    /// own uniform mapping, so positions are identical across standard libraries.
    BouncingMotion(std::uint32_t count, const Aabb& box, float speed, float margin, std::uint64_t seed);

    std::uint32_t count() const { return static_cast<std::uint32_t>(start_.size()); }
    /// Position of point i at frame `frame` (reflection at the walls, exact for any frame).
    glm::vec3 position(std::uint32_t i, std::uint64_t frame) const;
    /// A seeded per-object orientation (unit quaternion components w,x,y,z) for variety.
    glm::vec4 orientation(std::uint32_t i) const { return orient_[i]; }

private:
    Aabb inner_;
    std::vector<glm::vec3> start_, velocity_;
    std::vector<glm::vec4> orient_;
};

/// Camera path sampled smoothly (centripetal Catmull-Rom) through eye waypoints and
/// look-at waypoints; frame f maps to parameter f / framesPerSegment.
class CameraPath {
public:
    /// `eyes` non-empty; `targets` one per eye or a single fixed target (asserted). With
    /// `loop` the path closes back to the first waypoint, else it stops at the last one.
    CameraPath(std::vector<glm::vec3> eyes, std::vector<glm::vec3> targets, std::uint32_t framesPerSegment, bool loop);
    /// Circle of radius `dist` around `centre` at height `height` above it, `frames` per turn
    /// (exact when `frames` has a divisor in [8, 64]; else rounded to a multiple of 16).
    static CameraPath orbit(const glm::vec3& centre, float dist, float height, std::uint32_t frames);

    /// Fills position/target of `camera` (other fields untouched) for frame `frame`.
    void apply(std::uint64_t frame, Camera& camera) const;
    std::uint64_t frameCount() const;  ///< frames to traverse the path once

private:
    std::vector<glm::vec3> eyes_, targets_;
    std::uint32_t framesPerSegment_;
    bool loop_;
};

}  // namespace dyncull
