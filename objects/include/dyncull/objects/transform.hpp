// Rigid transform with (possibly non-uniform) scale: world = T * R * S * object.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "dyncull/objects/error.hpp"

namespace dyncull {

struct Transform {
    glm::vec3 translation{0.0f};  ///< world units
    glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  ///< unit quaternion (w, x, y, z)
    glm::vec3 scale{1.0f};  ///< per object axis, must be non-zero

    glm::mat4 matrix() const;
    /// Decompose an affine matrix without shear (glTF node matrices); shear is dropped.
    static Transform fromMatrix(const glm::mat4& m);
};

/// Rejects NaN/Inf components, zero scale and non-unit rotations (bad input at the API boundary).
Status validateTransform(const Transform& t);
/// Rejects non-finite or singular affine matrices.
Status validateMatrix(const glm::mat4& m);

}  // namespace dyncull
