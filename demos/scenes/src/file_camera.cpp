// Choosing a file scene's camera path by looking at the geometry from the walk path.
#include "file_camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dyncull {

// Run once per load, on the two middle eyes of the walk: cost is what it is.
double enclosedFraction(const Scene& scene, const std::vector<glm::vec3>& eyes, const std::vector<glm::vec3>& dirs) {
    struct Hit {
        float t = std::numeric_limits<float>::infinity();
        bool front = false;
    };
    std::vector<Hit> hits(eyes.size() * dirs.size());
    for (const Instance& inst : scene.instances) {
        const Mesh& m = scene.meshes[inst.mesh];
        // Mirroring instances flip the winding; the determinant's sign restores it.
        const float flip = glm::determinant(glm::mat3(inst.transform)) < 0.0f ? -1.0f : 1.0f;
        for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
            const glm::vec3 a = glm::vec3(inst.transform * glm::vec4(m.positions[m.indices[t]], 1.0f));
            const glm::vec3 e1 = glm::vec3(inst.transform * glm::vec4(m.positions[m.indices[t + 1]], 1.0f)) - a;
            const glm::vec3 e2 = glm::vec3(inst.transform * glm::vec4(m.positions[m.indices[t + 2]], 1.0f)) - a;
            const glm::vec3 n = flip * glm::cross(e1, e2);
            for (std::size_t i = 0; i < eyes.size(); ++i) {
                const glm::vec3 s = eyes[i] - a;
                for (std::size_t d = 0; d < dirs.size(); ++d) {
                    // Moller-Trumbore; zero-area triangles give det == 0 and are skipped.
                    const glm::vec3 p = glm::cross(dirs[d], e2);
                    const float det = glm::dot(e1, p);
                    if (det == 0.0f) continue;
                    const float inv = 1.0f / det;
                    const float u = glm::dot(s, p) * inv;
                    if (u < 0.0f || u > 1.0f) continue;
                    const glm::vec3 q = glm::cross(s, e1);
                    const float v = glm::dot(dirs[d], q) * inv;
                    if (v < 0.0f || u + v > 1.0f) continue;
                    const float dist = glm::dot(e2, q) * inv;
                    Hit& h = hits[i * dirs.size() + d];
                    if (dist > 0.0f && dist < h.t) h = {dist, glm::dot(n, dirs[d]) < 0.0f};
                }
            }
        }
    }
    std::size_t front = 0;
    for (const Hit& h : hits) front += h.front ? 1 : 0;
    return hits.empty() ? 0.0 : double(front) / double(hits.size());
}

std::vector<glm::vec3> sphereDirections(int n) {
    std::vector<glm::vec3> dirs;
    const float golden = 2.39996323f;  // pi * (3 - sqrt(5))
    for (int i = 0; i < n; ++i) {
        const float y = 1.0f - 2.0f * (float(i) + 0.5f) / float(n);
        const float r = std::sqrt(std::max(0.0f, 1.0f - y * y));
        dirs.emplace_back(r * std::cos(golden * float(i)), y, r * std::sin(golden * float(i)));
    }
    return dirs;
}

WalkAxes walkAxes(const Aabb& bounds) {
    const glm::vec3 e = bounds.extent();
    const int axis = e.x >= e.z ? 0 : 2;
    WalkAxes w{bounds.center() + glm::vec3(0.0f, -0.2f * e.y, 0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
    w.along[axis] = 0.4f * e[axis];
    w.side[2 - axis] = 0.15f * e[2 - axis];
    return w;
}
std::vector<glm::vec3> walkEyes(const Aabb& bounds) {
    const WalkAxes w = walkAxes(bounds);
    return {w.base - w.along, w.base - 0.3f * w.along + w.side, w.base + 0.3f * w.along - w.side, w.base + w.along};
}

FileCameraChoice chooseFileCamera(const Scene& scene, const Aabb& bounds) {
    const glm::vec3 e = bounds.extent();
    const float longest = std::max({e.x, e.y, e.z});
    const float shortest = std::max(std::min({e.x, e.y, e.z}), 1e-6f * longest);
    FileCameraChoice c;
    c.elongated = longest / shortest > 1.8f;
    if (!c.elongated) return c;
    const std::vector<glm::vec3> eyes = walkEyes(bounds);
    c.enclosedFraction = enclosedFraction(scene, {eyes[1], eyes[2]}, sphereDirections(48));
    c.walkthrough = c.enclosedFraction > 0.7;
    return c;
}

}  // namespace dyncull
