#include "dyncull/objects/transform.hpp"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace dyncull {

glm::mat4 Transform::matrix() const {
    glm::mat4 m = glm::mat4_cast(rotation);
    m[0] *= scale.x;
    m[1] *= scale.y;
    m[2] *= scale.z;
    m[3] = glm::vec4(translation, 1.0f);
    return m;
}

Transform Transform::fromMatrix(const glm::mat4& m) {
    Transform t;
    t.translation = glm::vec3(m[3]);
    glm::vec3 c0(m[0]), c1(m[1]), c2(m[2]);
    t.scale = {glm::length(c0), glm::length(c1), glm::length(c2)};
    // A mirrored basis (negative determinant) is expressed as negative x scale.
    if (glm::dot(glm::cross(c0, c1), c2) < 0.0f) t.scale.x = -t.scale.x;
    glm::mat3 r(c0 / t.scale.x, c1 / t.scale.y, c2 / t.scale.z);
    t.rotation = glm::normalize(glm::quat_cast(r));
    return t;
}

static bool finite3(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

Status validateTransform(const Transform& t) {
    if (!finite3(t.translation)) return Error{"transform: translation is not finite"};
    if (!finite3(t.scale)) return Error{"transform: scale is not finite"};
    if (t.scale.x == 0.0f || t.scale.y == 0.0f || t.scale.z == 0.0f)
        return Error{"transform: scale has a zero component"};
    const glm::vec4 q(t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w);
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z) || !std::isfinite(q.w))
        return Error{"transform: rotation is not finite"};
    // Unit quaternion expected; 1e-3 tolerates float round-off of user-built quaternions.
    if (std::abs(glm::dot(q, q) - 1.0f) > 1e-3f) return Error{"transform: rotation is not a unit quaternion"};
    return {};
}

Status validateMatrix(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return Error{"transform matrix has a non-finite element"};
    if (glm::determinant(glm::mat3(m)) == 0.0f) return Error{"transform matrix is singular"};
    return {};
}

}  // namespace dyncull
