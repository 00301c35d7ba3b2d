// Perspective camera and view frustum (world space, right-handed, OpenGL clip conventions:
// camera looks down -Z in view space, clip z in [-1, 1]).
#pragma once

#include <array>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/error.hpp"

namespace dyncull {

struct Camera {
    glm::vec3 position{0.0f, 0.0f, 5.0f};  ///< world units
    glm::vec3 target{0.0f};                ///< point looked at, world units
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float fovYRadians = 0.9f;  ///< vertical field of view
    float aspect = 16.0f / 9.0f;  ///< width / height
    float nearPlane = 0.05f;  ///< world units, > 0
    float farPlane = 1000.0f;  ///< world units, > nearPlane

    glm::mat4 view() const;
    glm::mat4 projection() const;
    glm::mat4 viewProjection() const { return projection() * view(); }
    /// Camera-relative view-projection: projection times the rotation-only view, computed
    /// in double, for positions given relative to the eye (world minus `position`).
    /// Renderers use it with camera-relative model matrices (relativeModel) so precision
    /// does not depend on the distance from the world origin (world-space float matrices
    /// lose whole pixels beyond ~1e5 units).
    glm::mat4 viewProjectionRelative() const;
    /// `objectToWorld` with the eye subtracted from its translation, in double: the
    /// object-to-camera-relative matrix to pair with viewProjectionRelative().
    glm::mat4 relativeModel(const glm::mat4& objectToWorld) const;
    glm::vec3 forward() const;

    /// Camera placed to see all of `box` from direction `dir`, near/far fitted to it.
    static Camera framing(const Aabb& box, float aspect, const glm::vec3& dir = {0.6f, 0.45f, 1.0f});
};

/// Rejects NaN/Inf, near <= 0, far <= near, degenerate up/target, fov outside (0, pi).
Status validateCamera(const Camera& camera);

/// Six planes (left, right, bottom, top, near, far) with inward normals: a point p is
/// inside when dot(n, p) + d >= 0 for all planes. Extracted from a view-projection matrix.
struct Frustum {
    std::array<glm::vec4, 6> planes;  ///< xyz = normal (normalised), w = d; relative to `origin`
    /// Planes are given for points relative to this world point (0 for a world-space
    /// matrix, the eye for fromCamera); classify subtracts it in double.
    glm::dvec3 origin{0.0};

    static Frustum fromMatrix(const glm::mat4& viewProjection);
    /// The camera's frustum built camera-relative (viewProjectionRelative, origin = eye):
    /// exact to float precision of the planes near the eye at any distance from the world
    /// origin, where planes of a world-space float matrix are off by whole units at 1e7.
    static Frustum fromCamera(const Camera& camera);

    enum class Side { Outside, Intersecting, Inside };
    /// Conservative: Outside only if the box is fully behind one plane.
    Side classify(const Aabb& box) const;
    bool outside(const Aabb& box) const { return classify(box) == Side::Outside; }
};

}  // namespace dyncull
