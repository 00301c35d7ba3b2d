// Point sets for the bounding-volume tests: generic clouds and the degenerate cases the
// volumes must survive (single, repeated, collinear, planar, thin-slab, far from origin).
#pragma once

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace dyncull::test {

struct NamedPoints {
    std::string name;
    std::vector<glm::vec3> points;
};

inline glm::mat3 testRotation(float ax, float ay, float az) {
    const float cx = std::cos(ax), sx = std::sin(ax), cy = std::cos(ay), sy = std::sin(ay), cz = std::cos(az),
                sz = std::sin(az);
    const glm::mat3 rx(1, 0, 0, 0, cx, sx, 0, -sx, cx), ry(cy, 0, -sy, 0, 1, 0, sy, 0, cy), rz(cz, sz, 0, -sz, cz, 0, 0, 0, 1);
    return rz * ry * rx;
}

inline std::vector<NamedPoints> volumeTestPointSets() {
    std::vector<NamedPoints> sets;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const glm::mat3 rot = testRotation(0.4f, 0.9f, -0.3f);

    NamedPoints box{"rotated box 10x2x0.5", {}};
    for (int i = 0; i < 500; ++i) box.points.push_back(rot * glm::vec3(5.0f * u(rng), u(rng), 0.25f * u(rng)) + glm::vec3(3, -2, 7));
    sets.push_back(box);

    NamedPoints sphere{"sphere", {}};
    for (int i = 0; i < 400; ++i) {
        glm::vec3 p(u(rng), u(rng), u(rng));
        if (glm::length(p) < 1e-3f) continue;
        sphere.points.push_back(2.0f * glm::normalize(p));
    }
    sets.push_back(sphere);

    NamedPoints blob{"bumpy blob", {}};
    for (int i = 0; i <= 24; ++i)
        for (int j = 0; j < 48; ++j) {
            const float th = 3.14159265f * static_cast<float>(i) / 24.0f, ph = 6.2831853f * static_cast<float>(j) / 48.0f;
            const float r = 1.0f + 0.3f * std::sin(5.0f * th) * std::cos(4.0f * ph);
            blob.points.push_back(r * glm::vec3(std::sin(th) * std::cos(ph), 0.6f * std::cos(th), std::sin(th) * std::sin(ph)));
        }
    sets.push_back(blob);

    sets.push_back({"cube corners", {}});
    for (int i = 0; i < 8; ++i) sets.back().points.push_back({(i & 1) ? 1.0f : -1.0f, (i & 2) ? 2.0f : -2.0f, (i & 4) ? 0.5f : -0.5f});
    sets.push_back({"octahedron", {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}});
    sets.push_back({"single point", {{0.3f, -7.0f, 2.5f}}});
    sets.push_back({"single point at origin", {{0.0f, 0.0f, 0.0f}}});
    sets.push_back({"repeated point", std::vector<glm::vec3>(50, glm::vec3(1.0f, 2.0f, 3.0f))});
    NamedPoints two{"two points repeated", {}};
    for (int i = 0; i < 20; ++i) two.points.push_back(i % 2 ? glm::vec3(1, 1, 1) : glm::vec3(-2, 0.5f, 4));
    sets.push_back(two);
    NamedPoints line{"collinear (diagonal)", {}};
    for (int i = 0; i < 30; ++i) line.points.push_back(glm::vec3(1, 2, -1) + (static_cast<float>(i) * 0.1f) * glm::vec3(0.3f, -0.5f, 0.8f));
    sets.push_back(line);
    NamedPoints axisPlane{"planar (axis plane y=2)", {}};
    for (int i = 0; i < 100; ++i) axisPlane.points.push_back({3.0f * u(rng), 2.0f, u(rng)});
    sets.push_back(axisPlane);
    NamedPoints diagPlane{"planar (x+y+z=1)", {}};
    for (int i = 0; i < 100; ++i) {
        const float a = u(rng), b = u(rng);
        diagPlane.points.push_back({a, b, 1.0f - a - b});
    }
    sets.push_back(diagPlane);
    NamedPoints tilted{"planar (tilted, triangle)", {}};
    for (int i = 0; i < 60; ++i) {
        const float a = 0.5f * (u(rng) + 1.0f), b = 0.5f * (u(rng) + 1.0f) * (1.0f - a);
        tilted.points.push_back(rot * glm::vec3(4.0f * a, 3.0f * b, 0.0f));
    }
    sets.push_back(tilted);
    NamedPoints slab{"thin slab (1e-4 thick, diagonal)", {}};
    for (int i = 0; i < 200; ++i) {
        const float a = u(rng), b = u(rng), t = 1e-4f * u(rng);
        slab.points.push_back(glm::vec3(a, b, -a - b) + t * glm::normalize(glm::vec3(1, 1, 1)));
    }
    sets.push_back(slab);
    NamedPoints far{"far from origin (1e4), small", {}};
    for (int i = 0; i < 200; ++i) far.points.push_back(glm::vec3(1e4f, -2e4f, 5e3f) + rot * glm::vec3(u(rng), 0.2f * u(rng), 0.05f * u(rng)));
    sets.push_back(far);
    return sets;
}

}  // namespace dyncull::test
