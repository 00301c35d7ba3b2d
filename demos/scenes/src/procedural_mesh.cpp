// Procedural primitives; see procedural_mesh.hpp. Tube frames by the double reflection
// method of Wang, Juttler, Zheng and Liu, "Computation of rotation minimizing frames",
// ACM Transactions on Graphics 27(1), 2008.
#include "procedural_mesh.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace dyncull::procedural {
namespace {

constexpr float kTwoPi = 6.28318530717958647692f;

/// One profile sample of a surface of revolution: radius and height along the axis, the
/// profile normal (radial, axial), and whether it connects to the previous sample
/// (false starts a new strip: a crease such as a cylinder's rim).
struct ProfilePoint {
    float r, h, nr, nh;
    bool connect = true;
};

}  // namespace

std::uint64_t Rng::next() {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

float Rng::uniform(float lo, float hi) {
    const float u = static_cast<float>(next() >> 40) * (1.0f / 16777216.0f);
    return lo + (hi - lo) * u;
}

int Rng::range(int lo, int hi) {
    assert(hi >= lo);
    const std::uint64_t span = static_cast<std::uint64_t>(static_cast<std::int64_t>(hi) - lo) + 1;
    return static_cast<int>(lo + static_cast<std::int64_t>(next() % span));
}

glm::vec3 anyPerpendicular(const glm::vec3& v) {
    const glm::vec3 a = std::abs(v.x) < 0.6f * glm::length(v) ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    return glm::normalize(glm::cross(v, a));
}

std::uint32_t MeshBuilder::vertex(const glm::vec3& p, const glm::vec3& n) {
    m_.positions.push_back(p);
    m_.normals.push_back(n);
    return static_cast<std::uint32_t>(m_.positions.size() - 1);
}

void MeshBuilder::tri(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    m_.indices.insert(m_.indices.end(), {a, b, c});
}

void MeshBuilder::cap(const std::vector<glm::vec3>& ring, const glm::vec3& centre, const glm::vec3& n) {
    // The ring runs counter-clockwise about its tube direction; a cap facing the other way
    // takes the fan in reverse order.
    const std::uint32_t c = vertex(centre, n);
    const std::uint32_t first = static_cast<std::uint32_t>(m_.positions.size());
    for (const glm::vec3& p : ring) vertex(p, n);
    const std::uint32_t k = static_cast<std::uint32_t>(ring.size());
    const glm::vec3 winding = glm::cross(ring[0] - centre, ring[1 % k] - centre);
    const bool ccw = glm::dot(winding, n) > 0.0f;
    for (std::uint32_t i = 0; i < k; ++i) {
        const std::uint32_t a = first + i, b = first + (i + 1) % k;
        if (ccw) tri(c, a, b);
        else tri(c, b, a);
    }
}

void MeshBuilder::orientedBox(const glm::vec3& centre, const glm::vec3& ax, const glm::vec3& ay, const glm::vec3& az,
                              const glm::vec3& half) {
    const glm::vec3 axes[3] = {ax, ay, az};
    for (int k = 0; k < 3; ++k) {
        for (int s = -1; s <= 1; s += 2) {
            const glm::vec3 n = static_cast<float>(s) * axes[k];
            glm::vec3 u = axes[(k + 1) % 3] * half[(k + 1) % 3];
            glm::vec3 v = axes[(k + 2) % 3] * half[(k + 2) % 3];
            if (glm::dot(glm::cross(u, v), n) < 0.0f) std::swap(u, v);
            const glm::vec3 c = centre + n * half[k];
            const std::uint32_t a = vertex(c - u - v, n), b = vertex(c + u - v, n), d = vertex(c + u + v, n),
                                e = vertex(c - u + v, n);
            tri(a, b, d);
            tri(a, d, e);
        }
    }
}

void MeshBuilder::box(const glm::vec3& lo, const glm::vec3& hi) {
    orientedBox(0.5f * (lo + hi), {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0.5f * (hi - lo));
}

void MeshBuilder::bar(const glm::vec3& a, const glm::vec3& b, float thickness) {
    const glm::vec3 d = b - a;
    const float len = glm::length(d);
    if (!(len > 0.0f)) return;
    const glm::vec3 x = d / len;
    const glm::vec3 y = anyPerpendicular(x);
    const glm::vec3 z = glm::cross(x, y);
    orientedBox(0.5f * (a + b), x, y, z, {0.5f * len, 0.5f * thickness, 0.5f * thickness});
}

namespace {

/// Surface of revolution around the axis through `base` along unit `w`.
void revolve(MeshBuilder& builder, Mesh& m, const glm::vec3& base, const glm::vec3& w,
             const std::vector<ProfilePoint>& profile, std::uint32_t segments) {
    (void)builder;
    const glm::vec3 e1 = anyPerpendicular(w);
    const glm::vec3 e2 = glm::cross(w, e1);  // e1 x e2 = w: increasing angle is counter-clockwise about w
    std::vector<glm::vec2> dirs(segments);
    for (std::uint32_t i = 0; i < segments; ++i) {
        const float a = kTwoPi * static_cast<float>(i) / static_cast<float>(segments);
        dirs[i] = {std::cos(a), std::sin(a)};
    }
    auto ring = [&](const ProfilePoint& p) {
        const std::uint32_t first = static_cast<std::uint32_t>(m.positions.size());
        const glm::vec3 c = base + w * p.h;
        if (p.r == 0.0f) {
            m.positions.push_back(c);
            m.normals.push_back(glm::normalize(w * p.nh));
            return first;
        }
        for (const glm::vec2& d : dirs) {
            const glm::vec3 radial = e1 * d.x + e2 * d.y;
            m.positions.push_back(c + radial * p.r);
            m.normals.push_back(glm::normalize(radial * p.nr + w * p.nh));
        }
        return first;
    };
    std::uint32_t prev = ring(profile[0]);
    for (std::size_t k = 1; k < profile.size(); ++k) {
        const std::uint32_t cur = ring(profile[k]);
        if (profile[k].connect) {
            const bool lowPole = profile[k - 1].r == 0.0f, highPole = profile[k].r == 0.0f;
            for (std::uint32_t i = 0; i < segments; ++i) {
                const std::uint32_t j = (i + 1) % segments;
                const std::uint32_t a = lowPole ? prev : prev + i, b = lowPole ? prev : prev + j;
                const std::uint32_t c = highPole ? cur : cur + j, d = highPole ? cur : cur + i;
                if (!lowPole) m.indices.insert(m.indices.end(), {a, b, c});
                if (!highPole) m.indices.insert(m.indices.end(), {a, c, d});
            }
        }
        prev = cur;
    }
}

}  // namespace

void MeshBuilder::cylinder(const glm::vec3& a, const glm::vec3& b, float radius, std::uint32_t segments) {
    const float len = glm::length(b - a);
    if (!(len > 0.0f) || segments < 3) return;
    revolve(*this, m_, a, (b - a) / len,
            {{0, 0, 0, -1}, {radius, 0, 0, -1}, {radius, 0, 1, 0, false}, {radius, len, 1, 0}, {radius, len, 0, 1, false},
             {0, len, 0, 1}},
            segments);
}

void MeshBuilder::sphere(const glm::vec3& centre, float radius, std::uint32_t segments, std::uint32_t rings) {
    rings = std::max<std::uint32_t>(rings, 2);
    std::vector<ProfilePoint> p;
    for (std::uint32_t j = 0; j <= rings; ++j) {
        const float t = -0.5f * kTwoPi * 0.5f + 0.5f * kTwoPi * static_cast<float>(j) / static_cast<float>(rings);
        const float r = (j == 0 || j == rings) ? 0.0f : radius * std::cos(t);
        p.push_back({r, radius * std::sin(t), std::cos(t), std::sin(t)});
    }
    revolve(*this, m_, centre, {0, 1, 0}, p, std::max<std::uint32_t>(segments, 3));
}

void MeshBuilder::dome(const glm::vec3& base, float radius, std::uint32_t segments, std::uint32_t rings) {
    rings = std::max<std::uint32_t>(rings, 1);
    std::vector<ProfilePoint> p = {{0, 0, 0, -1}, {radius, 0, 0, -1}};
    for (std::uint32_t j = 0; j <= rings; ++j) {
        const float t = 0.25f * kTwoPi * static_cast<float>(j) / static_cast<float>(rings);
        p.push_back({j == rings ? 0.0f : radius * std::cos(t), radius * std::sin(t), std::cos(t), std::sin(t), j != 0});
    }
    revolve(*this, m_, base, {0, 1, 0}, p, std::max<std::uint32_t>(segments, 3));
}

void MeshBuilder::tank(const glm::vec3& a, const glm::vec3& b, float radius, std::uint32_t segments,
                       std::uint32_t headRings) {
    const float len = glm::length(b - a);
    if (!(len > 0.0f) || segments < 3) return;
    headRings = std::max<std::uint32_t>(headRings, 1);
    std::vector<ProfilePoint> p;
    for (std::uint32_t j = 0; j <= headRings; ++j) {  // bottom head: pole up to the equator
        const float t = -0.25f * kTwoPi + 0.25f * kTwoPi * static_cast<float>(j) / static_cast<float>(headRings);
        p.push_back({j == 0 ? 0.0f : radius * std::cos(t), radius * std::sin(t), std::cos(t), std::sin(t)});
    }
    for (std::uint32_t j = 0; j <= headRings; ++j) {  // top head: equator up to the pole
        const float t = 0.25f * kTwoPi * static_cast<float>(j) / static_cast<float>(headRings);
        p.push_back({j == headRings ? 0.0f : radius * std::cos(t), len + radius * std::sin(t), std::cos(t), std::sin(t)});
    }
    revolve(*this, m_, a, (b - a) / len, p, segments);
}

void MeshBuilder::tube(const std::vector<glm::vec3>& polyline, float radius, std::uint32_t segments, float bendRadius,
                       std::uint32_t bendSteps) {
    if (segments < 3) return;
    // Drop repeated points: duplicates have no direction. Scale: 1e-6 of the path size.
    Aabb box;
    for (const glm::vec3& p : polyline) box.extend(p);
    const float eps = 1e-6f * std::max(1e-6f, glm::length(box.extent()));
    std::vector<glm::vec3> pts;
    for (const glm::vec3& p : polyline)
        if (pts.empty() || glm::length(p - pts.back()) > eps) pts.push_back(p);
    if (pts.size() < 2) return;

    // Centre line with exact tangents: straight legs joined by circular arcs.
    std::vector<glm::vec3> c, t;
    c.push_back(pts[0]);
    t.push_back(glm::normalize(pts[1] - pts[0]));
    for (std::size_t i = 1; i + 1 < pts.size(); ++i) {
        const glm::vec3 din = pts[i] - pts[i - 1], dout = pts[i + 1] - pts[i];
        const float lin = glm::length(din), lout = glm::length(dout);
        const glm::vec3 d0 = din / lin, d1 = dout / lout;
        const float cosPhi = std::clamp(glm::dot(d0, d1), -1.0f, 1.0f);
        const float phi = std::acos(cosPhi);
        if (phi < 1e-3f || cosPhi < -0.98f || bendSteps == 0) {
            // Straight through, or a near U-turn (no arc fits): a sharp corner.
            c.push_back(pts[i]);
            t.push_back(glm::normalize(d0 + d1 + 1e-3f * anyPerpendicular(d0)));
            continue;
        }
        const float tanHalf = std::tan(0.5f * phi);
        const float legLen = std::min(bendRadius * tanHalf, 0.45f * std::min(lin, lout));
        const float r = legLen / tanHalf;
        const glm::vec3 n = glm::normalize(d1 - d0 * cosPhi);
        const glm::vec3 start = pts[i] - d0 * legLen;
        const glm::vec3 centre = start + n * r;
        for (std::uint32_t s = 0; s <= bendSteps; ++s) {
            const float a = phi * static_cast<float>(s) / static_cast<float>(bendSteps);
            c.push_back(centre + r * (-n * std::cos(a) + d0 * std::sin(a)));
            t.push_back(glm::normalize(d0 * std::cos(a) + n * std::sin(a)));
        }
    }
    c.push_back(pts.back());
    t.push_back(glm::normalize(pts.back() - pts[pts.size() - 2]));

    // Rotation-minimising frames by double reflection.
    std::vector<glm::vec3> u(c.size());
    u[0] = anyPerpendicular(t[0]);
    for (std::size_t i = 0; i + 1 < c.size(); ++i) {
        const glm::vec3 v1 = c[i + 1] - c[i];
        const float c1 = glm::dot(v1, v1);
        if (c1 <= eps * eps) {
            u[i + 1] = u[i];
            continue;
        }
        const glm::vec3 rl = u[i] - (2.0f / c1) * glm::dot(v1, u[i]) * v1;
        const glm::vec3 tl = t[i] - (2.0f / c1) * glm::dot(v1, t[i]) * v1;
        const glm::vec3 v2 = t[i + 1] - tl;
        const float c2 = glm::dot(v2, v2);
        glm::vec3 r = c2 > 1e-12f ? rl - (2.0f / c2) * glm::dot(v2, rl) * v2 : rl;
        r -= t[i + 1] * glm::dot(r, t[i + 1]);  // re-orthogonalise against float drift
        u[i + 1] = glm::normalize(r);
    }

    std::vector<glm::vec2> dirs(segments);
    for (std::uint32_t i = 0; i < segments; ++i) {
        const float a = kTwoPi * static_cast<float>(i) / static_cast<float>(segments);
        dirs[i] = {std::cos(a), std::sin(a)};
    }
    const std::uint32_t first = static_cast<std::uint32_t>(m_.positions.size());
    std::vector<glm::vec3> startRing, endRing;
    for (std::size_t k = 0; k < c.size(); ++k) {
        const glm::vec3 v = glm::cross(t[k], u[k]);  // u x v = t: counter-clockwise about t
        for (const glm::vec2& d : dirs) {
            const glm::vec3 radial = u[k] * d.x + v * d.y;
            vertex(c[k] + radial * radius, radial);
            if (k == 0) startRing.push_back(c[k] + radial * radius);
            if (k + 1 == c.size()) endRing.push_back(c[k] + radial * radius);
        }
    }
    for (std::uint32_t k = 0; k + 1 < c.size(); ++k) {
        const std::uint32_t lo = first + k * segments, hi = lo + segments;
        for (std::uint32_t i = 0; i < segments; ++i) {
            const std::uint32_t j = (i + 1) % segments;
            tri(lo + i, lo + j, hi + j);
            tri(lo + i, hi + j, hi + i);
        }
    }
    cap(startRing, c.front(), -t.front());
    cap(endRing, c.back(), t.back());
}

void MeshBuilder::iBeam(const glm::vec3& a, const glm::vec3& b, const glm::vec3& up, float height, float width,
                        float thickness) {
    const float len = glm::length(b - a);
    if (!(len > 0.0f)) return;
    const glm::vec3 x = (b - a) / len;
    glm::vec3 y = up - x * glm::dot(up, x);
    y = glm::length(y) > 1e-6f ? glm::normalize(y) : anyPerpendicular(x);
    const glm::vec3 z = glm::cross(x, y);
    const glm::vec3 mid = 0.5f * (a + b);
    const float hl = 0.5f * len, ht = 0.5f * thickness;
    orientedBox(mid + y * (0.5f * height - ht), x, y, z, {hl, ht, 0.5f * width});
    orientedBox(mid - y * (0.5f * height - ht), x, y, z, {hl, ht, 0.5f * width});
    orientedBox(mid, x, y, z, {hl, 0.5f * height - thickness, ht});
}

void MeshBuilder::truss(const glm::vec3& a, const glm::vec3& b, const glm::vec3& up, float depth, std::uint32_t bays,
                        float barSize) {
    const glm::vec3 d = b - a;
    if (!(glm::length(d) > 0.0f) || bays == 0) return;
    glm::vec3 y = up - glm::normalize(d) * glm::dot(up, glm::normalize(d));
    y = glm::length(y) > 1e-6f ? glm::normalize(y) : anyPerpendicular(d);
    const glm::vec3 top = y * depth;
    bar(a, b, barSize);
    bar(a + top, b + top, barSize);
    for (std::uint32_t i = 0; i <= bays; ++i) {
        const glm::vec3 p = a + d * (static_cast<float>(i) / static_cast<float>(bays));
        bar(p, p + top, barSize);
        if (i < bays) {
            const glm::vec3 q = a + d * (static_cast<float>(i + 1) / static_cast<float>(bays));
            if (i % 2 == 0) bar(p, q + top, 0.8f * barSize);
            else bar(p + top, q, 0.8f * barSize);
        }
    }
}

void MeshBuilder::stairs(const glm::vec3& base, const glm::vec3& dir, float width, float rise, float run,
                         std::uint32_t steps) {
    const glm::vec3 x = glm::normalize(glm::vec3(dir.x, 0.0f, dir.z));
    const glm::vec3 y(0, 1, 0);
    const glm::vec3 z = glm::cross(x, y);
    for (std::uint32_t k = 0; k < steps; ++k) {
        const glm::vec3 c = base + x * (run * (static_cast<float>(k) + 0.5f)) + y * (rise * static_cast<float>(k + 1) - 0.03f);
        orientedBox(c, x, y, z, {0.5f * run, 0.03f, 0.5f * width});
    }
    const glm::vec3 top = base + x * (run * static_cast<float>(steps)) + y * (rise * static_cast<float>(steps));
    for (int s = -1; s <= 1; s += 2) {
        const glm::vec3 side = z * (static_cast<float>(s) * (0.5f * width + 0.04f));
        bar(base + side, top + side, 0.08f);
        // Handrail posts and rail.
        bar(base + side, base + side + y * 1.0f, 0.04f);
        bar(top + side, top + side + y * 1.0f, 0.04f);
        bar(base + side + y * 1.0f, top + side + y * 1.0f, 0.04f);
    }
}

void MeshBuilder::grating(const glm::vec3& lo, const glm::vec3& hi, float pitch, float barHeight) {
    const float y0 = lo.y, y1 = lo.y + barHeight;
    const float lenZ = hi.z - lo.z;
    const std::uint32_t nz = std::max<std::uint32_t>(1, static_cast<std::uint32_t>(lenZ / pitch));
    for (std::uint32_t i = 0; i <= nz; ++i) {
        const float z = lo.z + lenZ * static_cast<float>(i) / static_cast<float>(nz);
        box({lo.x, y0, z - 0.004f}, {hi.x, y1, z + 0.004f});
    }
    const float lenX = hi.x - lo.x;
    const std::uint32_t nx = std::max<std::uint32_t>(1, static_cast<std::uint32_t>(lenX / (4.0f * pitch)));
    for (std::uint32_t i = 0; i <= nx; ++i) {
        const float x = lo.x + lenX * static_cast<float>(i) / static_cast<float>(nx);
        box({x - 0.004f, y0, lo.z}, {x + 0.004f, y0 + 0.5f * barHeight, hi.z});
    }
}

void MeshBuilder::wall(const glm::vec3& origin, const glm::vec3& along, float length, float height, float thickness,
                       const std::vector<Opening>& openings) {
    const glm::vec3 x = glm::normalize(along);
    const glm::vec3 y(0, 1, 0);
    const glm::vec3 z = glm::cross(x, y);
    std::vector<float> us = {0.0f, length};
    for (const Opening& o : openings) {
        us.push_back(std::clamp(o.u0, 0.0f, length));
        us.push_back(std::clamp(o.u1, 0.0f, length));
    }
    std::sort(us.begin(), us.end());
    us.erase(std::unique(us.begin(), us.end()), us.end());
    auto emit = [&](float u0, float u1, float v0, float v1) {
        if (u1 - u0 <= 0.0f || v1 - v0 <= 0.0f) return;
        const glm::vec3 c = origin + x * (0.5f * (u0 + u1)) + y * (0.5f * (v0 + v1)) + z * (0.5f * thickness);
        orientedBox(c, x, y, z, {0.5f * (u1 - u0), 0.5f * (v1 - v0), 0.5f * thickness});
    };
    for (std::size_t i = 0; i + 1 < us.size(); ++i) {
        const float ua = us[i], ub = us[i + 1];
        std::vector<std::pair<float, float>> holes;
        for (const Opening& o : openings)
            if (o.u0 <= ua && o.u1 >= ub) holes.push_back({std::max(0.0f, o.v0), std::min(height, o.v1)});
        std::sort(holes.begin(), holes.end());
        float v = 0.0f;
        for (const auto& h : holes) {
            emit(ua, ub, v, h.first);
            v = std::max(v, h.second);
        }
        emit(ua, ub, v, height);
    }
}

}  // namespace dyncull::procedural
