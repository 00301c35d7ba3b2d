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

namespace {
// floor and ceil of v, clamped to [lo, hi]: v is clamped first, so that the conversion is
// exact and the rounding one comparison (without SSE4.1 std::floor is a library call, and
// these run twice per cluster, tens of thousands of times a frame).
int floorIn(double v, int lo, int hi) {
    const double c = std::clamp(v, double(lo) - 1.0, double(hi) + 1.0);
    const int t = static_cast<int>(c);  // towards zero
    return std::clamp(t - (c < double(t) ? 1 : 0), lo, hi);
}
int ceilIn(double v, int lo, int hi) {
    const double c = std::clamp(v, double(lo) - 1.0, double(hi) + 1.0);
    const int t = static_cast<int>(c);
    return std::clamp(t + (c > double(t) ? 1 : 0), lo, hi);
}
}  // namespace

ScreenRect ScreenProjection::pixelRect(const glm::dvec2& lo, const glm::dvec2& hi) const {
    // Pixels, rounded outwards and padded by one so rasterisation rules never leave a
    // covered pixel outside the rectangle.
    const double fx = 0.5 * view_.width, fy = 0.5 * view_.height;
    const int w = view_.width, h = view_.height;
    return {floorIn((lo.x + 1.0) * fx, 1, w + 1) - 1, floorIn((lo.y + 1.0) * fy, 1, h + 1) - 1,
            ceilIn((hi.x + 1.0) * fx, -1, w - 1) + 1, ceilIn((hi.y + 1.0) * fy, -1, h - 1) + 1};
}

ScreenRect ScreenProjection::centreRect(const glm::dvec2& lo, const glm::dvec2& hi) const {
    // Pixel i's centre is at i + 0.5 in window coordinates, and a rasteriser's snapping may
    // move a vertex across it (DepthPyramid::kSnapPixels).
    constexpr double kSnap = DepthPyramid::kSnapPixels;
    const double fx = 0.5 * view_.width, fy = 0.5 * view_.height;
    const int w = view_.width, h = view_.height;
    return {ceilIn((lo.x + 1.0) * fx - 0.5 - kSnap, 0, w), ceilIn((lo.y + 1.0) * fy - 0.5 - kSnap, 0, h),
            floorIn((hi.x + 1.0) * fx - 0.5 + kSnap, -1, w - 1) + 1, floorIn((hi.y + 1.0) * fy - 0.5 + kSnap, -1, h - 1) + 1};
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

ObjectProjection ScreenProjection::objectProjection(const glm::mat4& matrix) const { return objectProjection(glm::dmat4(matrix)); }

ObjectProjection ScreenProjection::objectProjection(const glm::dmat4& matrix) const {
    ObjectProjection p;
    p.toWorld = matrix;
    const glm::dvec3 c0(p.toWorld[0]), c1(p.toWorld[1]), c2(p.toWorld[2]);
    const double det = std::abs(glm::dot(c0, glm::cross(c1, c2)));
    const double a0 = glm::length(glm::cross(c1, c2)), a1 = glm::length(glm::cross(c2, c0)), a2 = glm::length(glm::cross(c0, c1));
    p.faceScale = {a0 > 0.0 ? det / a0 : 0.0, a1 > 0.0 ? det / a1 : 0.0, a2 > 0.0 ? det / a2 : 0.0};
    glm::dmat4 relative = p.toWorld;
    relative[3] -= glm::dvec4(glm::dvec3(view_.camera.position), 0.0);  // world minus the eye
    p.toClip = view_.viewProjRelative * relative;
    for (int j = 0; j < 4; ++j) p.toDistance[j] = glm::dot(distanceRow_, relative[j]);
    p.absLinear = glm::dmat3(glm::abs(c0), glm::abs(c1), glm::abs(c2));
    // In orthographic views the faces a box shows depend on the view direction, not the
    // eye's position: no planes there.
    if (det > 0.0 && !view_.camera.orthographic()) {
        const glm::dmat3 linear(c0, c1, c2);
        p.eyeLocal = glm::inverse(linear) * (glm::dvec3(view_.camera.position) - glm::dvec3(p.toWorld[3]));
        p.eyeKnown = true;
    }
    return p;
}

ScreenProjection::BoxNdc ScreenProjection::boxNdc(const ObjectProjection& object, const Aabb& local, glm::dvec2& ndcLo, glm::dvec2& ndcHi,
                                                  double& nearestDepth, BoxCorners* corners) const {
    // QueryVolume::enlargedForRounding for a box: its vertices' magnitude sets the margin,
    // and each face is pushed out by it through a scale about the centre by k.
    const glm::dvec3 lo(local.min), hi(local.max);
    const glm::dvec3 centre = 0.5 * (lo + hi);
    const glm::dvec3 half = 0.5 * (hi - lo);
    const glm::dvec3 worldCentre = glm::dvec3(object.toWorld[3]) + glm::dmat3(object.toWorld) * centre;
    const glm::dvec3 axesReach = object.absLinear * half;  // sum over the half axes of |toWorld axis * half|
    const glm::dvec3 reach = glm::abs(worldCentre) + axesReach;
    const double magnitude = std::max({reach.x, reach.y, reach.z});  // of the farthest corner, per coordinate
    const double push = magnitude * 0x1p-22 * std::sqrt(3.0);
    const double nearest = std::min({half.x * object.faceScale.x, half.y * object.faceScale.y, half.z * object.faceScale.z});
    if (!(nearest > 4.0 * push)) return BoxNdc::Thin;
    const double k = 1.0 + push / nearest;
    // The corners are the centre plus or minus each scaled axis, and the projection is
    // linear: the centre and the three axes are projected once, the corners summed in clip
    // space (what pointsDepth does per corner, in a fraction of the arithmetic).
    const glm::dvec3 relCentre = worldCentre - glm::dvec3(view_.camera.position);
    // The largest coordinate of any corner: per axis the centre's plus the spread, exactly
    // as the corners' (the sign pattern that reaches it is one of the eight).
    const glm::dvec3 far = glm::abs(relCentre) + k * axesReach;
    const double nearPlane = double(view_.camera.nearPlane);
    const double nearTest = nearPlane + 0x1p-21 * std::max({far.x, far.y, far.z}) + 0x1p-22 * nearPlane;
    const glm::dvec4 c = object.toClip * glm::dvec4(centre, 1.0);
    const glm::dvec3 scaled = k * half;
    const glm::dvec4 p0 = object.toClip[0] * scaled.x, p1 = object.toClip[1] * scaled.y, p2 = object.toClip[2] * scaled.z;
    const double dc = glm::dot(object.toDistance, glm::dvec4(centre, 1.0));
    const double d0 = object.toDistance.x * scaled.x, d1 = object.toDistance.y * scaled.y, d2 = object.toDistance.z * scaled.z;
    // The nearest corner along the view decides the near test for all eight.
    if (dc - std::abs(d0) - std::abs(d1) - std::abs(d2) < nearTest) return BoxNdc::Crossing;
    ndcLo = glm::dvec2(1e300);
    ndcHi = glm::dvec2(-1e300);
    nearestDepth = 0.0;
    if (corners) {
        corners->centre = centre;
        corners->half = k * half;
        corners->valid = true;
    }
    for (int i = 0; i < 8; ++i) {
        const glm::dvec4 clip = c + ((i & 1) ? p0 : -p0) + ((i & 2) ? p1 : -p1) + ((i & 4) ? p2 : -p2);
        const double inv = 1.0 / clip.w;
        const glm::dvec2 ndc = glm::dvec2(clip) * inv;
        ndcLo = glm::min(ndcLo, ndc);
        ndcHi = glm::max(ndcHi, ndc);
        nearestDepth = std::max(nearestDepth, clip.z * inv);
        if (corners) corners->window[static_cast<std::size_t>(i)] = {ndc, clip.z * inv};
    }
    return BoxNdc::InFront;
}

void ScreenProjection::outline(const std::array<glm::dvec3, 8>& corners, DepthPlanes& out) const {
    // The box lies in front of the eye, so its projection is the convex hull of its
    // corners' (Andrew's monotone chain, counter-clockwise; collinear corners dropped).
    const double fx = 0.5 * view_.width, fy = 0.5 * view_.height;
    std::array<glm::dvec2, 8> p;
    for (std::size_t i = 0; i < 8; ++i) p[i] = {(corners[i].x + 1.0) * fx, (corners[i].y + 1.0) * fy};
    std::sort(p.begin(), p.end(), [](const glm::dvec2& u, const glm::dvec2& v) { return u.x < v.x || (u.x == v.x && u.y < v.y); });
    auto turnsLeft = [](const glm::dvec2& o, const glm::dvec2& u, const glm::dvec2& v) {
        return (u.x - o.x) * (v.y - o.y) - (u.y - o.y) * (v.x - o.x) > 0.0;
    };
    std::array<glm::dvec2, 16> hull;
    std::size_t k = 0;
    for (std::size_t i = 0; i < 8; ++i) {  // lower chain
        while (k >= 2 && !turnsLeft(hull[k - 2], hull[k - 1], p[i])) --k;
        hull[k++] = p[i];
    }
    for (std::size_t i = 7, lower = k + 1; i-- > 0;) {  // upper chain
        while (k >= lower && !turnsLeft(hull[k - 2], hull[k - 1], p[i])) --k;
        hull[k++] = p[i];
    }
    // hull[k - 1] repeats hull[0]. Fewer than two distinct points: no outline (all of the
    // footprint may be covered); two: the segment's two sides.
    const std::size_t n = k - 1;
    if (n < 2) return;
    for (std::size_t i = 0; i < n && out.edgeCount < DepthPlanes::kMaxEdges; ++i) {
        const glm::dvec2 a = hull[i], d = hull[i + 1] - a;
        // Left of a -> a + d: d.y x - d.x y <= d.y a.x - d.x a.y.
        out.edges[out.edgeCount++] = {d.y, -d.x, d.y * a.x - d.x * a.y};
    }
}

void ScreenProjection::frontFacePlanes(const ObjectProjection& object, const BoxCorners& box, DepthPlanes& out) const {
    // A face is front-facing when the eye lies outside its plane, judged in object space
    // with a margin of 2^-20 of the magnitudes (far above the rounding of the inverse): a
    // back face taken for a front one would bound the depth by the box's far side, so
    // a face too close to call is left out.
    out.count = 0;
    out.edgeCount = 0;
    if (!box.valid) return;
    const std::array<glm::dvec3, 8>& corners = box.window;
    const double fx = 0.5 * view_.width, fy = 0.5 * view_.height;
    outline(corners, out);
    if (!object.eyeKnown) return;
    const glm::dvec3& centre = box.centre;
    const glm::dvec3& half = box.half;
    for (int a = 0; a < 3; ++a) {
        const double outside = std::abs(object.eyeLocal[a] - centre[a]) - half[a];
        if (!(outside > 0x1p-20 * (std::abs(object.eyeLocal[a]) + std::abs(centre[a]) + half[a]))) continue;
        // Three corners of the face the eye is outside of: its plane's depth through them.
        const int base = object.eyeLocal[a] > centre[a] ? 1 << a : 0;
        const int b = 1 << ((a + 1) % 3), c = 1 << ((a + 2) % 3);
        const glm::dvec3& q0 = corners[static_cast<std::size_t>(base)];
        const glm::dvec3& q1 = corners[static_cast<std::size_t>(base | b)];
        const glm::dvec3& q2 = corners[static_cast<std::size_t>(base | c)];
        const double x0 = (q0.x + 1.0) * fx, y0 = (q0.y + 1.0) * fy;
        const double dx1 = (q1.x - q0.x) * fx, dy1 = (q1.y - q0.y) * fy, dd1 = q1.z - q0.z;
        const double dx2 = (q2.x - q0.x) * fx, dy2 = (q2.y - q0.y) * fy, dd2 = q2.z - q0.z;
        // Seen nearly edge-on, the plane's slopes are ill-conditioned: left out when the
        // face's projected area is below 2^-20 of its terms'.
        const double det = dx1 * dy2 - dx2 * dy1;
        if (!(std::abs(det) > 0x1p-20 * (std::abs(dx1 * dy2) + std::abs(dx2 * dy1)))) continue;
        const double slopeX = (dd1 * dy2 - dd2 * dy1) / det, slopeY = (dx1 * dd2 - dx2 * dd1) / det;
        out.planes[out.count++] = {slopeX, slopeY, q0.z - slopeX * x0 - slopeY * y0};
    }
}

bool ScreenProjection::boxDepth(const ObjectProjection& object, const Aabb& local, DepthFootprint& out, bool planes) const {
    if (const std::optional<bool> inFront = frameBoxDepth(object, local, out, planes)) return *inFront;
    // Too thin: as a box of boxes; the float matrix is toWorld rounded back, exactly.
    return volumeDepth(QueryVolume::fromTransformedBox(glm::mat4(object.toWorld), local), out);
}

std::optional<bool> ScreenProjection::frameBoxDepth(const ObjectProjection& object, const Aabb& local, DepthFootprint& out,
                                                    bool planes) const {
    glm::dvec2 lo, hi;
    double nearest = 0.0;
    BoxCorners corners;
    switch (boxNdc(object, local, lo, hi, nearest, planes ? &corners : nullptr)) {
    case BoxNdc::Crossing: return false;
    case BoxNdc::Thin: return std::nullopt;
    case BoxNdc::InFront: break;
    }
    out.planesLeftOut = !planes;
    if (planes) {
        frontFacePlanes(object, corners, out.planes);
    } else {
        out.planes.count = 0;
        out.planes.edgeCount = 0;
    }
    out.rect = pixelRect(lo, hi);
    out.centres = centreRect(lo, hi);
    out.nearest = static_cast<float>(nearest);
    return true;
}

bool ScreenProjection::boxCentres(const ObjectProjection& object, const Aabb& local, ScreenRect& centres, float& nearestDepth,
                                  BoxCorners* corners) const {
    glm::dvec2 lo, hi;
    double nearest = 0.0;
    if (corners) corners->valid = false;
    switch (boxNdc(object, local, lo, hi, nearest, corners)) {
    case BoxNdc::Crossing: return false;
    case BoxNdc::Thin: {
        DepthFootprint fp;
        if (!volumeDepth(QueryVolume::fromTransformedBox(glm::mat4(object.toWorld), local), fp)) return false;
        centres = fp.centres;
        nearestDepth = fp.nearest;
        return true;
    }
    case BoxNdc::InFront: break;
    }
    centres = centreRect(lo, hi);
    nearestDepth = static_cast<float>(nearest);
    return true;
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
    out.planes.count = 0;
    out.planes.edgeCount = 0;
    out.planesLeftOut = false;  // a volume has none to make
    return true;
}

}  // namespace dyncull
