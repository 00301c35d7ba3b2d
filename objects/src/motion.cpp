// Deterministic closed-form motion: bouncing points (reflection as a triangle wave) and
// camera paths (centripetal Catmull-Rom: Yuksel, Schaefer, Keyser, "Parameterization and
// applications of Catmull-Rom curves", Computer-Aided Design 43(7), 2011).
#include "dyncull/objects/motion.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <random>

namespace dyncull {
namespace {

// Uniform double in [0, 1) from the top 53 bits: std::mt19937_64 output is specified
// bit-exactly, std::uniform_real_distribution is not, so this keeps runs reproducible
// across standard libraries.
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// Position along one axis: start offset s + v*frame folded into [0, length] (reflection
// off both walls is a triangle wave of period 2*length).
float bounceAxis(float lo, float length, float start, float velocity, std::uint64_t frame) {
    if (!(length > 0.0f)) return lo;  // pinned axis
    const double period = 2.0 * length;
    double s = std::fmod(static_cast<double>(start - lo) + static_cast<double>(velocity) * static_cast<double>(frame), period);
    if (s < 0.0) s += period;
    const double p = s <= length ? s : period - s;
    return static_cast<float>(std::clamp(static_cast<double>(lo) + p, static_cast<double>(lo),
                                         static_cast<double>(lo) + length));
}

}  // namespace

BouncingMotion::BouncingMotion(std::uint32_t count, const Aabb& box, float speed, float margin, std::uint64_t seed) {
    assert(!box.empty() && box.finite() && "BouncingMotion needs a finite, non-empty box");
    assert(std::isfinite(speed) && std::isfinite(margin));
    const Aabb safeBox = (!box.empty() && box.finite()) ? box : Aabb::fromMinMax(glm::vec3(0.0f), glm::vec3(0.0f));
    const float m = std::isfinite(margin) ? std::max(margin, 0.0f) : 0.0f;
    const float v = std::isfinite(speed) ? speed : 0.0f;
    for (int a = 0; a < 3; ++a) {
        const float half = 0.5f * (safeBox.max[a] - safeBox.min[a]);
        if (m > half) {
            // The object is wider than the box on this axis: keep it at the centre.
            inner_.min[a] = inner_.max[a] = safeBox.min[a] + half;
        } else {
            inner_.min[a] = safeBox.min[a] + m;
            inner_.max[a] = safeBox.max[a] - m;
        }
    }
    std::mt19937_64 rng(seed);
    start_.resize(count);
    velocity_.resize(count);
    orient_.resize(count);
    const glm::vec3 ext = inner_.extent();
    for (std::uint32_t i = 0; i < count; ++i) {
        // Fixed draw order per point: 3 for the start, 2 for the direction, 3 for the orientation.
        const double ux = uniform01(rng), uy = uniform01(rng), uz = uniform01(rng);
        start_[i] = inner_.min + glm::vec3(static_cast<float>(ux), static_cast<float>(uy), static_cast<float>(uz)) * ext;
        // Uniform direction on the sphere (Archimedes: z uniform in [-1, 1]).
        const double z = 2.0 * uniform01(rng) - 1.0;
        const double phi = 2.0 * std::numbers::pi * uniform01(rng);
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        velocity_[i] = glm::vec3(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)),
                                 static_cast<float>(z)) * v;
        // Uniform random rotation (Shoemake, "Uniform random rotations", Graphics Gems III).
        const double u1 = uniform01(rng), u2 = uniform01(rng), u3 = uniform01(rng);
        const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
        const double t2 = 2.0 * std::numbers::pi * u2, t3 = 2.0 * std::numbers::pi * u3;
        glm::vec4 q(static_cast<float>(b * std::cos(t3)), static_cast<float>(a * std::sin(t2)),
                    static_cast<float>(a * std::cos(t2)), static_cast<float>(b * std::sin(t3)));
        orient_[i] = q / glm::length(q);  // w, x, y, z
    }
}

glm::vec3 BouncingMotion::position(std::uint32_t i, std::uint64_t frame) const {
    assert(i < start_.size());
    glm::vec3 p;
    for (int a = 0; a < 3; ++a)
        p[a] = bounceAxis(inner_.min[a], inner_.max[a] - inner_.min[a], start_[i][a], velocity_[i][a], frame);
    return p;
}

namespace {

// Centripetal Catmull-Rom segment p1 -> p2 at t in [0, 1], as a cubic Hermite curve with
// the non-uniform tangents of Yuksel et al. (knot spacing |p_{i+1} - p_i|^0.5).
glm::vec3 catmullRom(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2, const glm::vec3& p3, float t) {
    float d1 = std::sqrt(glm::length(p2 - p1));
    if (!(d1 > 0.0f)) return p1;  // repeated waypoint: the segment is a point
    float d0 = std::sqrt(glm::length(p1 - p0));
    float d2 = std::sqrt(glm::length(p3 - p2));
    // A repeated neighbour gives a zero knot interval; borrowing the middle one keeps the
    // tangent finite (relative threshold because positions can be in any units).
    if (d0 < 1e-4f * d1) d0 = d1;
    if (d2 < 1e-4f * d1) d2 = d1;
    const glm::vec3 m1 = ((p1 - p0) / d0 - (p2 - p0) / (d0 + d1) + (p2 - p1) / d1) * d1;
    const glm::vec3 m2 = ((p2 - p1) / d1 - (p3 - p1) / (d1 + d2) + (p3 - p2) / d2) * d1;
    const float t2 = t * t, t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * p1 + (t3 - 2 * t2 + t) * m1 + (-2 * t3 + 3 * t2) * p2 + (t3 - t2) * m2;
}

glm::vec3 samplePath(const std::vector<glm::vec3>& pts, bool loop, std::size_t seg, float t) {
    const std::size_t n = pts.size();
    if (n == 1) return pts[0];
    auto at = [&](std::ptrdiff_t i) -> glm::vec3 {
        const auto sn = static_cast<std::ptrdiff_t>(n);
        if (loop) return pts[static_cast<std::size_t>(((i % sn) + sn) % sn)];
        // Clamped ends: mirror the neighbour so the end tangent points along the path.
        if (i < 0) return 2.0f * pts[0] - pts[1];
        if (i >= sn) return 2.0f * pts[n - 1] - pts[n - 2];
        return pts[static_cast<std::size_t>(i)];
    };
    const auto s = static_cast<std::ptrdiff_t>(seg);
    return catmullRom(at(s - 1), at(s), at(s + 1), at(s + 2), t);
}

}  // namespace

CameraPath::CameraPath(std::vector<glm::vec3> eyes, std::vector<glm::vec3> targets, std::uint32_t framesPerSegment, bool loop)
    : eyes_(std::move(eyes)), targets_(std::move(targets)), framesPerSegment_(std::max(framesPerSegment, 1u)), loop_(loop) {
    assert(!eyes_.empty() && "CameraPath needs at least one eye waypoint");
    assert((targets_.size() == eyes_.size() || targets_.size() == 1) && "one target per eye, or one fixed target");
    if (eyes_.empty()) eyes_.push_back(glm::vec3(0.0f, 0.0f, 5.0f));
    if (targets_.empty()) targets_.push_back(glm::vec3(0.0f));
}

CameraPath CameraPath::orbit(const glm::vec3& centre, float dist, float height, std::uint32_t frames) {
    frames = std::max(frames, 1u);
    // Pick a waypoint count that divides `frames` so one turn takes exactly `frames`;
    // 16+ points keep the spline within ~0.05% of the circle's radius.
    std::uint32_t n = 0;
    for (std::uint32_t k = 16; k <= 64 && !n; ++k)
        if (frames % k == 0) n = k;
    for (std::uint32_t k = 8; k < 16 && !n; ++k)
        if (frames % k == 0) n = k;
    if (!n) n = 16;  // no good divisor: one turn takes 16 * round(frames / 16) frames
    const std::uint32_t perSegment = std::max(1u, static_cast<std::uint32_t>(std::lround(double(frames) / n)));
    std::vector<glm::vec3> eyes(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        const double a = 2.0 * std::numbers::pi * i / n;
        eyes[i] = centre + glm::vec3(static_cast<float>(dist * std::cos(a)), height, static_cast<float>(dist * std::sin(a)));
    }
    return CameraPath(std::move(eyes), {centre}, perSegment, true);
}

std::uint64_t CameraPath::frameCount() const {
    const std::size_t segments = loop_ ? eyes_.size() : eyes_.size() - 1;
    return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(segments) * framesPerSegment_);
}

void CameraPath::apply(std::uint64_t frame, Camera& camera) const {
    const std::uint64_t total = frameCount();
    const std::size_t segments = loop_ ? eyes_.size() : eyes_.size() - 1;
    std::size_t seg = 0;
    float t = 0.0f;
    if (loop_) frame %= total;
    if (segments == 0) {
        seg = 0;
    } else if (!loop_ && frame >= total) {
        seg = segments - 1;  // clamp: rest on the last waypoint
        t = 1.0f;
    } else {
        seg = static_cast<std::size_t>(frame / framesPerSegment_);
        t = static_cast<float>(frame % framesPerSegment_) / static_cast<float>(framesPerSegment_);
    }
    camera.position = samplePath(eyes_, loop_, seg, t);
    camera.target = targets_.size() == 1 ? targets_[0] : samplePath(targets_, loop_, seg, t);
}

}  // namespace dyncull
