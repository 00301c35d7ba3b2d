#include "dyncull/objects/camera.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <glm/gtc/matrix_access.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace dyncull {

glm::mat4 Camera::view() const { return glm::lookAt(position, target, up); }

glm::dmat4 reversedZPerspective(double fovY, double aspect, double n, double f) {
    // Column-major. Double: at near 1e-4 and far 1e7 the terms n / (f - n) = 1e-11 and
    // n f / (f - n) ~ n are each exact to float once rounded; nothing cancels (unlike
    // OpenGL's (f + n) / (f - n), which is 1 in float).
    const double t = std::tan(0.5 * fovY);
    glm::dmat4 p(0.0);
    p[0][0] = 1.0 / (aspect * t);
    p[1][1] = 1.0 / t;
    p[2][2] = n / (f - n);
    p[2][3] = -1.0;  // clip w = -z_view = distance along the view direction
    p[3][2] = n * f / (f - n);
    return p;
}

glm::dmat4 reversedZOrthographic(double height, double aspect, double n, double f) {
    glm::dmat4 p(1.0);
    p[0][0] = 2.0 / (aspect * height);
    p[1][1] = 2.0 / height;
    p[2][2] = 1.0 / (f - n);  // clip z = (f - d) / (f - n) with d = -z_view: 1 at near, 0 at far
    p[3][2] = f / (f - n);
    return p;  // clip w = 1
}

glm::dmat4 Camera::projectionDouble() const {
    if (orthographic()) return reversedZOrthographic(orthoHeight, aspect, nearPlane, farPlane);
    return reversedZPerspective(fovYRadians, aspect, nearPlane, farPlane);
}

glm::dvec4 Camera::distanceRowRelative() const {
    if (!orthographic()) return glm::row(viewProjectionRelativeDouble(), 3);  // clip w
    return glm::dvec4(glm::normalize(glm::dvec3(target) - glm::dvec3(position)), 0.0);
}

glm::mat4 Camera::viewProjection() const {
    return glm::mat4(projectionDouble() * glm::lookAt(glm::dvec3(position), glm::dvec3(target), glm::dvec3(up)));
}

glm::dmat4 Camera::viewProjectionRelativeDouble() const {
    const glm::dvec3 eye(position);
    const glm::dmat4 rot = glm::lookAt(glm::dvec3(0.0), glm::dvec3(target) - eye, glm::dvec3(up));
    return projectionDouble() * rot;
}

glm::mat4 Camera::relativeModel(const glm::mat4& objectToWorld) const {
    glm::mat4 m = objectToWorld;
    // Float minus float in double is exact; the rounding back to float then loses only
    // what the camera-relative position itself cannot hold.
    m[3] = glm::vec4(glm::vec3(glm::dvec3(objectToWorld[3]) - glm::dvec3(position)), objectToWorld[3][3]);
    return m;
}

glm::vec3 Camera::forward() const { return glm::normalize(target - position); }

Camera Camera::framing(const Aabb& box, float aspectRatio, const glm::vec3& dir) {
    Camera c;
    c.aspect = aspectRatio;
    const glm::vec3 centre = box.empty() ? glm::vec3(0.0f) : box.center();
    const float radius = box.empty() ? 1.0f : std::max(0.5f * glm::length(box.extent()), 1e-6f);
    // Distance at which a sphere of `radius` fits the narrower field of view.
    const float fovX = 2.0f * std::atan(std::tan(c.fovYRadians * 0.5f) * aspectRatio);
    const float halfFov = 0.5f * std::min(c.fovYRadians, fovX);
    const float dist = radius / std::sin(halfFov) * 1.05f;
    c.target = centre;
    c.position = centre + glm::normalize(dir) * dist;
    c.nearPlane = std::max(dist - radius * 1.5f, dist * 1e-3f);
    c.farPlane = dist + radius * 1.5f;
    return c;
}

Status checkFramable(const Aabb& b) {
    if (b.empty()) return Error{"the model has no vertices to frame"};
    const glm::vec3 lo = b.min, hi = b.max;
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(lo[i]) || !std::isfinite(hi[i])) return Error{"the model's bounds are not finite"};
    // The framing camera sits about 2.2 radii from the centre with its far plane 3.7 radii
    // out: 1e36 leaves a factor of 300 before float overflows at 3.4e38.
    constexpr double kLimit = 1e36;
    double size = 0.0, reach = 0.0;
    for (int i = 0; i < 3; ++i) {
        size = std::max(size, static_cast<double>(hi[i]) - static_cast<double>(lo[i]));
        reach = std::max({reach, std::abs(static_cast<double>(lo[i])), std::abs(static_cast<double>(hi[i]))});
    }
    char buf[160];
    if (size == 0.0) return Error{"the model has zero size (all its vertices are at one point): nothing to frame"};
    if (reach >= kLimit || size >= kLimit) {
        std::snprintf(buf, sizeof buf, "the model reaches %.3g units from the origin (size %.3g): a single-precision "
                      "camera cannot frame beyond 1e36", reach, size);
        return Error{buf};
    }
    // 64 ulps: float spacing at `reach` is reach * 2^-23.
    if (size < 64.0 * reach * 0x1p-23) {
        std::snprintf(buf, sizeof buf, "the model is %.3g units across at %.3g from the origin: below 64 float ulps, "
                      "its vertices cannot be told apart in single precision", size, reach);
        return Error{buf};
    }
    return {};
}

Status validateCamera(const Camera& c) {
    auto finite = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    if (!finite(c.position) || !finite(c.target) || !finite(c.up)) return Error{"camera: position, target or up is not finite"};
    if (!std::isfinite(c.fovYRadians) || c.fovYRadians <= 0.0f || c.fovYRadians >= std::numbers::pi_v<float>)
        return Error{"camera: vertical field of view must be in (0, pi) radians"};
    if (!std::isfinite(c.aspect) || c.aspect <= 0.0f) return Error{"camera: aspect must be positive"};
    if (!std::isfinite(c.orthoHeight) || c.orthoHeight < 0.0f)
        return Error{"camera: orthographic height must be finite and positive (0: perspective)"};
    if (!std::isfinite(c.nearPlane) || !std::isfinite(c.farPlane) || c.nearPlane <= 0.0f || c.farPlane <= c.nearPlane)
        return Error{"camera: need 0 < near < far"};
    const glm::vec3 f = c.target - c.position;
    if (glm::length(f) == 0.0f) return Error{"camera: target equals position"};
    if (glm::length(glm::cross(f, c.up)) <= 1e-6f * glm::length(f) * glm::length(c.up))
        return Error{"camera: up is parallel to the view direction"};
    return {};
}

Frustum Frustum::fromMatrix(const glm::mat4& m) { return fromMatrix(glm::dmat4(m)); }

Frustum Frustum::fromMatrix(const glm::dmat4& m) {
    // Gribb-Hartmann: planes are sums/differences of the rows of the clip matrix; reversed
    // Z puts the near plane at z <= w and the far plane at z >= 0.
    const glm::dvec4 r0(m[0][0], m[1][0], m[2][0], m[3][0]);
    const glm::dvec4 r1(m[0][1], m[1][1], m[2][1], m[3][1]);
    const glm::dvec4 r2(m[0][2], m[1][2], m[2][2], m[3][2]);
    const glm::dvec4 r3(m[0][3], m[1][3], m[2][3], m[3][3]);
    const glm::dvec4 planes[6] = {r3 + r0, r3 - r0, r3 + r1, r3 - r1, r3 - r2, r2};
    Frustum f;
    for (int i = 0; i < 6; ++i) {
        const double len = glm::length(glm::dvec3(planes[i]));
        f.planes[static_cast<std::size_t>(i)] = glm::vec4(len > 0.0 ? planes[i] / len : planes[i]);
    }
    return f;
}

Frustum Frustum::fromCamera(const Camera& camera) {
    Frustum f = fromMatrix(camera.viewProjectionRelativeDouble());
    f.origin = glm::dvec3(camera.position);
    return f;
}

FrameView FrameView::of(const Camera& camera, int width, int height) {
    FrameView v;
    v.camera = camera;
    v.width = std::max(width, 1);
    v.height = std::max(height, 1);
    v.viewProjRelative = camera.viewProjectionRelativeDouble();
    v.inverseViewProjRelative = glm::inverse(v.viewProjRelative);
    v.frustum = Frustum::fromMatrix(v.viewProjRelative);
    v.frustum.origin = glm::dvec3(camera.position);
    return v;
}

Frustum::Side Frustum::classify(const Aabb& box) const {
    // Double: box corners minus the origin are exact, so a world box 1e7 units from the
    // origin is tested as precisely as one next to it.
    const glm::dvec3 lo = glm::dvec3(box.min) - origin, hi = glm::dvec3(box.max) - origin;
    bool inside = true;
    for (const glm::vec4& p : planes) {
        const glm::dvec3 n(p);
        // Positive vertex (furthest along n) and negative vertex.
        const glm::dvec3 pv(n.x >= 0 ? hi.x : lo.x, n.y >= 0 ? hi.y : lo.y, n.z >= 0 ? hi.z : lo.z);
        const glm::dvec3 nv(n.x >= 0 ? lo.x : hi.x, n.y >= 0 ? lo.y : hi.y, n.z >= 0 ? lo.z : hi.z);
        if (glm::dot(n, pv) + double(p.w) < 0.0) return Side::Outside;
        if (glm::dot(n, nv) + double(p.w) < 0.0) inside = false;
    }
    return inside ? Side::Inside : Side::Intersecting;
}

}  // namespace dyncull
