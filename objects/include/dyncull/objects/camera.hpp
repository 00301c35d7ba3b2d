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
    glm::vec3 forward() const;

    /// Camera placed to see all of `box` from direction `dir`, near/far fitted to it.
    static Camera framing(const Aabb& box, float aspect, const glm::vec3& dir = {0.6f, 0.45f, 1.0f});
};

/// Rejects NaN/Inf, near <= 0, far <= near, degenerate up/target, fov outside (0, pi).
Status validateCamera(const Camera& camera);

/// Six planes (left, right, bottom, top, near, far) with inward normals: a point p is
/// inside when dot(n, p) + d >= 0 for all planes. Extracted from a view-projection matrix.
struct Frustum {
    std::array<glm::vec4, 6> planes;  ///< xyz = normal (normalised), w = d

    static Frustum fromMatrix(const glm::mat4& viewProjection);

    enum class Side { Outside, Intersecting, Inside };
    /// Conservative: Outside only if the box is fully behind one plane.
    Side classify(const Aabb& box) const;
    bool outside(const Aabb& box) const { return classify(box) == Side::Outside; }
};

}  // namespace dyncull
