// Object transforms for tests: placed at a point, uniformly scaled, optionally rotated.
#pragma once

#include "dyncull/objects/transform.hpp"

namespace dyncull::test {

/// World-space placement `p` (world units), uniform scale `s`, rotation `r`.
inline Transform at(glm::vec3 p, float s = 1.0f, glm::quat r = glm::quat(1, 0, 0, 0)) {
    Transform t;
    t.translation = p;
    t.scale = glm::vec3(s);
    t.rotation = r;
    return t;
}

}  // namespace dyncull::test
