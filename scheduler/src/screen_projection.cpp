// Conservative screen footprints (screen_projection.hpp): camera-relative, in double.
#include "screen_projection.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace dyncull {

bool ScreenProjection::rect(const Aabb& box, ScreenRect& out) const {
    // Project the box clipped to the near plane, so boxes crossing it still get a correct
    // (conservative) rectangle. Returns false if the box crosses the near plane.
    // Double and camera-relative: the near test compares distances along the view direction
    // directly (clip w in perspective) (no depth terms of the projection,
    // which at near 1e-4 and far 1e7 span 11 orders of magnitude).
    const glm::dvec3 eye(view_.camera.position);
    const glm::dvec3 lo3 = glm::dvec3(box.min) - eye, hi3 = glm::dvec3(box.max) - eye;
    // A box this close to the near plane counts as crossing it: the GPU clips a query
    // volume with float vertices relative to the eye, which a backend may also push out by
    // up to 2^-22 of its world coordinates (QueryBackend::issue).
    // 2^-21 of the box's and 2^-22 of the eye-relative magnitude (and of near) cover both
    // roundings with a factor of two to spare.
    auto magnitude = [](const glm::dvec3& a, const glm::dvec3& b) {
        const glm::dvec3 m = glm::max(glm::abs(a), glm::abs(b));
        return std::max({m.x, m.y, m.z});
    };
    const double nearPlane = double(view_.camera.nearPlane);
    const double nearTest = nearPlane + 0x1p-21 * magnitude(glm::dvec3(box.min), glm::dvec3(box.max)) +
                            0x1p-22 * (magnitude(lo3, hi3) + nearPlane);
    glm::dvec4 clip[8];
    double distance[8];  // along the view direction
    bool front[8];  // in front of the near plane itself: part of the rectangle
    bool crosses = false;
    for (int i = 0; i < 8; ++i) {
        const glm::dvec3 c((i & 1) ? hi3.x : lo3.x, (i & 2) ? hi3.y : lo3.y, (i & 4) ? hi3.z : lo3.z);
        clip[i] = view_.viewProjRelative * glm::dvec4(c, 1.0);
        distance[i] = viewDistance(clip[i], c);
        front[i] = distance[i] >= nearPlane;
        crosses |= distance[i] < nearTest;
    }
    glm::dvec2 lo(1e300), hi(-1e300);
    auto addPoint = [&](const glm::dvec4& p) {
        const glm::dvec2 ndc = glm::dvec2(p) / p.w;  // w >= near > 0 (perspective) or 1 for every point added
        lo = glm::min(lo, ndc);
        hi = glm::max(hi, ndc);
    };
    for (int i = 0; i < 8; ++i)
        if (front[i]) addPoint(clip[i]);
    {
        // The 12 edges: pairs of corners differing in exactly one bit, cut at the near plane.
        for (int i = 0; i < 8; ++i)
            for (int bit = 1; bit < 8; bit <<= 1) {
                const int j = i | bit;
                if (j == i || front[i] == front[j]) continue;
                const double t = (distance[i] - nearPlane) / (distance[i] - distance[j]);
                addPoint(clip[i] + (clip[j] - clip[i]) * t);
            }
    }
    if (lo.x > hi.x) {  // nothing in front of the near plane
        out = {};
        return !crosses;
    }
    out = pixelRect(lo, hi);
    return !crosses;
}

ScreenRect ScreenProjection::pixelRect(const glm::dvec2& lo, const glm::dvec2& hi) const {
    // Pixels, rounded outwards and padded by one so rasterisation rules never leave a
    // covered pixel outside the rectangle.
    const double fx = 0.5 * view_.width, fy = 0.5 * view_.height;
    auto clampi = [](double v, int lim) { return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(lim))); };
    return {clampi(std::floor((lo.x + 1.0) * fx) - 1.0, view_.width), clampi(std::floor((lo.y + 1.0) * fy) - 1.0, view_.height),
            clampi(std::ceil((hi.x + 1.0) * fx) + 1.0, view_.width), clampi(std::ceil((hi.y + 1.0) * fy) + 1.0, view_.height)};
}

ScreenRect ScreenProjection::centreRect(const glm::dvec2& lo, const glm::dvec2& hi) const {
    // Pixel i's centre is at i + 0.5 in window coordinates. kSnap: a rasteriser snaps vertices
    // to its sub-pixel grid, at least 4 bits in GL (SUBPIXEL_BITS), so by at most 1/32 pixel.
    constexpr double kSnap = 1.0 / 16.0;
    const double fx = 0.5 * view_.width, fy = 0.5 * view_.height;
    auto clampi = [](double v, int lim) { return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(lim))); };
    return {clampi(std::ceil((lo.x + 1.0) * fx - 0.5 - kSnap), view_.width), clampi(std::ceil((lo.y + 1.0) * fy - 0.5 - kSnap), view_.height),
            clampi(std::floor((hi.x + 1.0) * fx - 0.5 + kSnap) + 1.0, view_.width),
            clampi(std::floor((hi.y + 1.0) * fy - 0.5 + kSnap) + 1.0, view_.height)};
}

glm::mat4 ScreenProjection::clipMatrixOf(const glm::mat4& matrix) const {
    glm::dmat4 relative(matrix);
    relative[3] -= glm::dvec4(glm::dvec3(view_.camera.position), 0.0);  // world minus the eye
    return glm::mat4(view_.viewProjRelative * relative);
}

bool ScreenProjection::roughBoxDepth(const glm::mat4& objectToClip, const Aabb& local, ScreenRect& centres, float& nearestDepth) const {
    glm::vec2 lo(1e30f), hi(-1e30f);
    float nearest = 0.0f;
    for (int i = 0; i < 8; ++i) {
        const glm::vec4 corner((i & 1) ? local.max.x : local.min.x, (i & 2) ? local.max.y : local.min.y,
                               (i & 4) ? local.max.z : local.min.z, 1.0f);
        const glm::vec4 clip = objectToClip * corner;
        // Reversed Z: window depth 1 at the near plane, above it in front of it.
        if (clip.w <= 0.0f || clip.z >= clip.w) return false;
        const glm::vec2 ndc = glm::vec2(clip) / clip.w;
        lo = glm::min(lo, ndc);
        hi = glm::max(hi, ndc);
        nearest = std::max(nearest, clip.z / clip.w);
    }
    centres = centreRect(glm::dvec2(lo), glm::dvec2(hi));
    nearestDepth = nearest;
    return true;
}

bool ScreenProjection::volumeDepth(const QueryVolume& volume, DepthFootprint& out) const {
    // The volume grown by the rounding of its float vertices, projected in double; any
    // point within the near-plane margin makes it "crossing" (visible), as in projectRect.
    std::array<glm::dvec3, QueryVolume::kMaxVertices> rel;
    bool asBox = false;
    const std::uint32_t n = volume.enlargedForRounding(glm::dvec3(view_.camera.position), rel, asBox);
    return pointsDepth(rel.data(), n, out);
}

ObjectProjection ScreenProjection::objectProjection(const glm::mat4& matrix) const {
    ObjectProjection p;
    p.toWorld = glm::dmat4(matrix);
    const glm::dvec3 c0(p.toWorld[0]), c1(p.toWorld[1]), c2(p.toWorld[2]);
    const double det = std::abs(glm::dot(c0, glm::cross(c1, c2)));
    const double a0 = glm::length(glm::cross(c1, c2)), a1 = glm::length(glm::cross(c2, c0)), a2 = glm::length(glm::cross(c0, c1));
    p.faceScale = {a0 > 0.0 ? det / a0 : 0.0, a1 > 0.0 ? det / a1 : 0.0, a2 > 0.0 ? det / a2 : 0.0};
    return p;
}

bool ScreenProjection::boxDepth(const ObjectProjection& object, const Aabb& local, DepthFootprint& out) const {
    // QueryVolume::enlargedForRounding for a box: its vertices' magnitude sets the margin,
    // and each face is pushed out by it through a scale about the centre by k.
    const glm::dvec3 lo(local.min), hi(local.max);
    const glm::dvec4 centre(0.5 * (lo + hi), 1.0);
    const glm::dvec3 half = 0.5 * (hi - lo);
    const glm::dvec3 worldCentre(object.toWorld * centre);
    const glm::dvec3 axis[3] = {glm::dvec3(object.toWorld[0]) * half.x, glm::dvec3(object.toWorld[1]) * half.y,
                                glm::dvec3(object.toWorld[2]) * half.z};
    const glm::dvec3 reach = glm::abs(worldCentre) + glm::abs(axis[0]) + glm::abs(axis[1]) + glm::abs(axis[2]);
    const double magnitude = std::max({reach.x, reach.y, reach.z});  // of the farthest corner, per coordinate
    const double push = magnitude * 0x1p-22 * std::sqrt(3.0);
    const double nearest = std::min({half.x * object.faceScale.x, half.y * object.faceScale.y, half.z * object.faceScale.z});
    if (!(nearest > 4.0 * push))  // thin: as a box of boxes; the float matrix is toWorld rounded back, exactly
        return volumeDepth(QueryVolume::fromTransformedBox(glm::mat4(object.toWorld), local), out);
    const double k = 1.0 + push / nearest;
    const glm::dvec3 relCentre = worldCentre - glm::dvec3(view_.camera.position);
    std::array<glm::dvec3, 8> rel;
    for (int i = 0; i < 8; ++i)
        rel[static_cast<std::size_t>(i)] =
            relCentre + k * ((i & 1) ? axis[0] : -axis[0]) + k * ((i & 2) ? axis[1] : -axis[1]) + k * ((i & 4) ? axis[2] : -axis[2]);
    return pointsDepth(rel.data(), 8, out);
}

bool ScreenProjection::pointsDepth(const glm::dvec3* rel, std::uint32_t n, DepthFootprint& out) const {
    double magnitude = 0.0;
    for (std::uint32_t i = 0; i < n; ++i)
        magnitude = std::max({magnitude, std::abs(rel[i].x), std::abs(rel[i].y), std::abs(rel[i].z)});
    const double nearPlane = double(view_.camera.nearPlane);
    const double nearTest = nearPlane + 0x1p-21 * magnitude + 0x1p-22 * nearPlane;
    glm::dvec2 lo(1e300), hi(-1e300);
    double nearest = 0.0;
    for (std::uint32_t i = 0; i < n; ++i) {
        const glm::dvec4 clip = view_.viewProjRelative * glm::dvec4(rel[i], 1.0);
        if (viewDistance(clip, rel[i]) < nearTest) return false;
        const glm::dvec2 ndc = glm::dvec2(clip) / clip.w;
        lo = glm::min(lo, ndc);
        hi = glm::max(hi, ndc);
        nearest = std::max(nearest, clip.z / clip.w);
    }
    out.rect = pixelRect(lo, hi);
    out.centres = centreRect(lo, hi);
    out.nearest = static_cast<float>(nearest);
    return true;
}

}  // namespace dyncull
