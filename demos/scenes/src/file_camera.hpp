// How a file scene is viewed: walked through when it is an elongated interior (an
// atrium, a street), orbited otherwise (compact models, or elongated objects seen from
// outside such as an engine).
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/scene.hpp"

namespace dyncull {

/// The walkthrough's frame: along the longest horizontal axis at 30% of the height,
/// offset sideways by `side`. World space, units of the scene.
struct WalkAxes {
    glm::vec3 base, along, side;
};
WalkAxes walkAxes(const Aabb& bounds);
/// The four eye points of the walkthrough (world space).
std::vector<glm::vec3> walkEyes(const Aabb& bounds);

/// Fraction of rays from `eyes` along `dirs` (unit vectors) whose first hit is a
/// triangle's front face. Brute force over every instanced triangle: O(triangles x rays).
double enclosedFraction(const Scene& scene, const std::vector<glm::vec3>& eyes, const std::vector<glm::vec3>& dirs);

/// `n` evenly spread unit directions (a Fibonacci sphere).
std::vector<glm::vec3> sphereDirections(int n);

struct FileCameraChoice {
    bool walkthrough = false;
    bool elongated = false;         ///< longest / shortest side of the bounds > 1.8
    double enclosedFraction = 0.0;  ///< measured on the walk path; 0 when not elongated
};
/// Walk through when the bounds are elongated (longest / shortest side > 1.8) and more
/// than 70% of 96 rays from the middle of the walk meet front faces: from inside an
/// interior nearly every ray meets a wall's front, from inside a solid object rays meet
/// back faces or escape. `bounds` are the scene's world bounds.
FileCameraChoice chooseFileCamera(const Scene& scene, const Aabb& bounds);

}  // namespace dyncull
