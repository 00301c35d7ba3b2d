// Perspective or orthographic camera and view frustum (world space, right-handed; the camera
// looks down -Z in view space).
//
// Depth convention: reversed Z with zero-to-one depth. Clip x and y are OpenGL's [-w, w];
// clip z / w is 1 at the near plane and 0 at the far plane. The engine renders with
// glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE), a 32-bit float depth buffer cleared to 0
// and GL_GREATER: depth ~ near / distance then keeps float's full relative precision at
// every distance (near 1e-4 with far 1e7 separates surfaces 1e-5 of their distance apart
// anywhere), where OpenGL's [-1, 1] float depth, ~1 - 2 near / distance, rounds to exactly
// 1.0 beyond ~3e7 near-plane distances (3,400 units at near 1e-4).
// The matrices are pure math (no GL): they live here so the core's frustum and screen
// rectangles use exactly what the engine draws with.
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
    /// > 0: an orthographic camera showing this many world units from the bottom of the view
    /// to its top (a directional light's shadow map; fovYRadians is then unused); 0: perspective.
    float orthoHeight = 0.0f;
    bool orthographic() const { return orthoHeight > 0.0f; }

    /// World to view space (eye at the origin, looking down -Z), world units.
    glm::mat4 view() const;
    /// View to clip space, reversed Z (reversedZPerspective of the fields), built in double.
    glm::mat4 projection() const { return glm::mat4(projectionDouble()); }
    glm::dmat4 projectionDouble() const;
    /// World to clip space (built in double, rounded once). Precise near the world origin
    /// only; renderers use viewProjectionRelative.
    glm::mat4 viewProjection() const;
    /// Camera-relative view-projection: projection times the rotation-only view, computed
    /// in double, for positions given relative to the eye (world minus `position`).
    /// Renderers use it with camera-relative model matrices (relativeModel) so precision
    /// does not depend on the distance from the world origin (world-space float matrices
    /// lose whole pixels beyond ~1e5 units).
    glm::mat4 viewProjectionRelative() const { return glm::mat4(viewProjectionRelativeDouble()); }
    /// The same in double, for CPU-side projection (frustum planes, screen rectangles).
    glm::dmat4 viewProjectionRelativeDouble() const;
    /// `objectToWorld` with the eye subtracted from its translation, in double: the
    /// object-to-camera-relative matrix to pair with viewProjectionRelative().
    glm::mat4 relativeModel(const glm::mat4& objectToWorld) const;
    glm::vec3 forward() const;
    /// The row r with dot(r, (p, 1)) = p's distance along the view direction (world units)
    /// for a point p relative to the eye: clip w of viewProjectionRelativeDouble for a
    /// perspective camera (the same rounding as the projection), the unit view direction
    /// for an orthographic one (whose clip w is 1). What near-plane tests compare with nearPlane.
    glm::dvec4 distanceRowRelative() const;

    /// Camera placed to see all of `box` from direction `dir`, near/far fitted to it.
    static Camera framing(const Aabb& box, float aspect, const glm::vec3& dir = {0.6f, 0.45f, 1.0f});
};

/// Reversed-Z perspective projection with zero-to-one depth (see the top of this file):
/// view space (looking down -Z, units of the arguments) to clip space with clip w = view
/// distance along -Z and clip z / w = near (far - d) / (d (far - near)), i.e. 1 at d = near,
/// 0 at d = far. Finite far plane, not infinite: far keeps its meaning for frustum culling
/// and GL clipping alike, and with a float depth buffer it costs no precision. fovY in
/// radians, aspect = width / height; needs 0 < near < far.
glm::dmat4 reversedZPerspective(double fovY, double aspect, double nearPlane, double farPlane);

/// Reversed-Z orthographic projection with zero-to-one depth: view space to clip space with
/// clip w = 1, x and y in [-1, 1] over `height` x `height * aspect` units, clip z = (far - d) /
/// (far - near) for view distance d: 1 at near, 0 at far (linear). Needs near < far.
glm::dmat4 reversedZOrthographic(double height, double aspect, double nearPlane, double farPlane);
/// Rejects NaN/Inf, near <= 0, far <= near, degenerate up/target, fov outside (0, pi), a
/// negative or non-finite orthographic height.
Status validateCamera(const Camera& camera);

/// Whether Camera::framing can show `worldBounds` (world units) as a picture: the box must be
/// non-empty and finite, have a non-zero size, keep the framing camera's position and far
/// plane finite in single precision (every coordinate and the size below 1e36), and be at
/// least 64 float ulps of its distance from the origin across (else its vertices and the
/// camera collapse onto a few representable positions). The error says which, without a
/// file name: the caller prefixes it.
Status checkFramable(const Aabb& worldBounds);

/// Six planes (left, right, bottom, top, near, far) with inward normals: a point p is
/// inside when dot(n, p) + d >= 0 for all planes. Extracted from a view-projection matrix
/// in this file's reversed-Z convention (near: z <= w, far: z >= 0).
struct Frustum {
    std::array<glm::vec4, 6> planes;  ///< xyz = normal (normalised), w = d; relative to `origin`
    /// Planes are given for points relative to this world point (0 for a world-space
    /// matrix, the eye for fromCamera); classify subtracts it in double.
    glm::dvec3 origin{0.0};

    static Frustum fromMatrix(const glm::mat4& viewProjection);
    static Frustum fromMatrix(const glm::dmat4& viewProjection);
    /// The camera's frustum built camera-relative (viewProjectionRelativeDouble, origin = eye):
    /// exact to float precision of the planes near the eye at any distance from the world
    /// origin, where planes of a world-space float matrix are off by whole units at 1e7.
    static Frustum fromCamera(const Camera& camera);

    enum class Side { Outside, Intersecting, Inside };
    /// Conservative: Outside only if the box is fully behind one plane.
    Side classify(const Aabb& box) const;
    bool outside(const Aabb& box) const { return classify(box) == Side::Outside; }
};

/// One frame's view, derived once from the camera and the viewport and handed to every
/// stage (scheduler, query backend, renderer), so none derives its own: the camera (world
/// space), the viewport in pixels, the camera-relative view-projection in double
/// (Camera::viewProjectionRelativeDouble) and its inverse, and the frustum (fromCamera).
struct FrameView {
    Camera camera;
    int width = 1, height = 1;
    glm::dmat4 viewProjRelative{1.0};
    glm::dmat4 inverseViewProjRelative{1.0};
    Frustum frustum;

    /// `width` and `height` are clamped to at least 1.
    static FrameView of(const Camera& camera, int width, int height);
};

}  // namespace dyncull
