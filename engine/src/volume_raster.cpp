// What the GL volume tests share (volume_raster.hpp): a volume's drawn points and
// triangles with its snapping ring, and the raster state they are drawn in.
#include "volume_raster.hpp"

#include <span>

#include "dyncull/objects/convex_mesh.hpp"
#include "depth_convention.hpp"

namespace dyncull::detail {
namespace {

/// Indices of the 2D convex hull of `p` (Andrew's monotone chain), counter-clockwise with
/// y up, collinear and repeated points dropped; a single index for coincident points.
std::uint32_t convexHull(std::span<const glm::dvec2> p, std::array<std::uint8_t, QueryVolume::kMaxVertices>& order,
                         std::array<std::uint8_t, 2 * QueryVolume::kMaxVertices + 1>& hull) {
    const auto n = static_cast<std::uint32_t>(p.size());
    for (std::uint32_t i = 0; i < n; ++i) order[i] = static_cast<std::uint8_t>(i);
    std::sort(order.begin(), order.begin() + n, [&](std::uint8_t a, std::uint8_t b) {
        return p[a].x < p[b].x || (p[a].x == p[b].x && p[a].y < p[b].y);
    });
    auto cross = [&](std::uint8_t o, std::uint8_t a, std::uint8_t b) {
        return (p[a].x - p[o].x) * (p[b].y - p[o].y) - (p[a].y - p[o].y) * (p[b].x - p[o].x);
    };
    std::uint32_t k = 0;
    for (std::uint32_t i = 0; i < n; ++i) {  // lower chain
        while (k >= 2 && cross(hull[k - 2], hull[k - 1], order[i]) <= 0.0) --k;
        hull[k++] = order[i];
    }
    for (std::uint32_t i = n - 1, lower = k + 1; i-- > 0;) {  // upper chain
        while (k >= lower && cross(hull[k - 2], hull[k - 1], order[i]) <= 0.0) --k;
        hull[k++] = order[i];
    }
    return k > 1 ? k - 1 : k;  // the last point repeats the first
}

/// Appends the snapping ring of the volume whose eye-relative points are `rel` (see
/// prepareVolume).
void addRing(std::span<const glm::dvec3> rel, const VolumeView& view, DrawnVolume& out) {
    std::array<glm::dvec2, QueryVolume::kMaxVertices> screen;  // pixels, y up
    double nearest = 0.0;                                     // reversed Z: the largest depth
    for (std::size_t i = 0; i < rel.size(); ++i) {
        const glm::dvec4 clip = view.viewProj * glm::dvec4(rel[i], 1.0);
        screen[i] = {(clip.x / clip.w + 1.0) * 0.5 * view.width, (clip.y / clip.w + 1.0) * 0.5 * view.height};
        nearest = std::max(nearest, clip.z / clip.w);
    }
    std::array<std::uint8_t, QueryVolume::kMaxVertices> order;
    std::array<std::uint8_t, 2 * QueryVolume::kMaxVertices + 1> hull;
    const std::uint32_t h = convexHull({screen.data(), rel.size()}, order, hull);
    const double w = view.ringPixels;
    auto emit = [&](const glm::dvec2& px) {  // a ring point: back to eye-relative space at the nearest depth
        const glm::dvec4 q = view.inverseViewProj * glm::dvec4(px.x / view.width * 2.0 - 1.0, px.y / view.height * 2.0 - 1.0, nearest, 1.0);
        out.points[out.count] = glm::vec3(glm::dvec3(q) / q.w);
        return static_cast<std::uint8_t>(out.count++);
    };
    auto quad = [&](const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& d) {
        const std::uint8_t i0 = emit(a), i1 = emit(b), i2 = emit(c), i3 = emit(d);
        for (std::uint8_t i : {i0, i1, i2, i0, i2, i3}) out.indices[out.indexCount++] = i;  // a, b, c, d counter-clockwise
    };
    if (h == 1 || (h == 2 && screen[hull[0]] == screen[hull[1]])) {  // every point on one spot: a square around it
        const glm::dvec2 c = screen[hull[0]];
        quad(c + glm::dvec2(-w, -w), c + glm::dvec2(w, -w), c + glm::dvec2(w, w), c + glm::dvec2(-w, w));
        return;
    }
    // Each strip straddles its edge: the volume's own snapped edge may recede inside the
    // exact outline, and the strip's inner side is snapped too. A segment (h == 2) is
    // walked both ways.
    for (std::uint32_t k = 0; k < h; ++k) {
        const glm::dvec2 a = screen[hull[k]], b = screen[hull[(k + 1) % h]];
        const glm::dvec2 t = glm::normalize(b - a), n(t.y, -t.x);  // outward for counter-clockwise
        quad(a - w * t + w * n, b + w * t + w * n, b + w * t - w * n, a - w * t - w * n);
    }
}

}  // namespace

bool prepareVolume(const QueryVolume& volume, const VolumeView& view, DrawnVolume& out) {
    std::array<glm::dvec3, QueryVolume::kMaxVertices> rel;
    bool asBox = false;
    out.count = volume.enlargedForRounding(view.eye, rel, asBox);
    for (std::uint32_t i = 0; i < out.count; ++i) {
        if (glm::dot(rel[i], view.forward) < view.nearPlane) return false;
        out.points[i] = glm::vec3(rel[i]);
    }
    const std::span<const std::uint8_t> tris = asBox || volume.isBox() ? std::span<const std::uint8_t>(kBoxTriangles) : volume.triangles();
    // Only front faces are drawn (VolumeTestState): they cover the whole outline of a
    // convex volume seen from outside (one reaching the near plane was answered above),
    // and a back face lies behind the front face of its pixel. Each face is wound outward
    // from the volume's centre here, whatever order it came in (a mirroring object matrix
    // turns outward winding inward).
    glm::dvec3 centre(0.0);
    for (std::uint32_t i = 0; i < out.count; ++i) centre += rel[i];
    centre /= double(out.count);
    for (std::size_t k = 0; k + 2 < tris.size(); k += 3) {
        const glm::dvec3 &a = rel[tris[k]], &b = rel[tris[k + 1]], &c = rel[tris[k + 2]];
        const bool inward = glm::dot(a - centre, glm::cross(b - a, c - a)) < 0.0;
        out.indices[k] = tris[k];
        out.indices[k + 1] = tris[inward ? k + 2 : k + 1];
        out.indices[k + 2] = tris[inward ? k + 1 : k + 2];
    }
    out.indexCount = static_cast<std::uint32_t>(tris.size());
    if (view.ringPixels > 0.0) addRing({rel.data(), out.count}, view, out);
    return true;
}

void VolumeTestState::enter() {
    glGetBooleanv(GL_COLOR_WRITEMASK, colourMask_);
    glGetBooleanv(GL_DEPTH_WRITEMASK, &depthMask_);
    glGetIntegerv(GL_DEPTH_FUNC, &depthFunc_);
    glGetFloatv(GL_POLYGON_OFFSET_FACTOR, &offsetFactor_);
    glGetFloatv(GL_POLYGON_OFFSET_UNITS, &offsetUnits_);
    cull_ = glIsEnabled(GL_CULL_FACE);
    glGetIntegerv(GL_CULL_FACE_MODE, &cullMode_);
    glGetIntegerv(GL_FRONT_FACE, &frontFace_);
    depthTest_ = glIsEnabled(GL_DEPTH_TEST);
    offsetFill_ = glIsEnabled(GL_POLYGON_OFFSET_FILL);

    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glDepthMask(GL_FALSE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(kDepthNearerOrEqual);
    glEnable(GL_CULL_FACE);  // see prepareVolume: front faces suffice, at half the fragments
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    // Pull volumes toward the eye by a few depth-buffer steps (scaled by GL to the face's
    // depth slope and the buffer's resolution): a part lying on its box face, or a
    // coplanar occluder, must not win a depth tie against the volume and hide a visible
    // pixel. Reversed Z: toward the eye is a positive offset. With a float depth buffer one
    // unit is 2^-23 of the face's own largest depth, so the pull stays a few ulps of
    // distance at 1e-3 and at 1e6 alike.
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(kTowardEye * 1.0f, kTowardEye * 4.0f);
}

void VolumeTestState::leave() {
    glColorMask(colourMask_[0], colourMask_[1], colourMask_[2], colourMask_[3]);
    glDepthMask(depthMask_);
    glDepthFunc(static_cast<GLenum>(depthFunc_));
    glPolygonOffset(offsetFactor_, offsetUnits_);
    if (!offsetFill_) glDisable(GL_POLYGON_OFFSET_FILL);
    glCullFace(static_cast<GLenum>(cullMode_));
    glFrontFace(static_cast<GLenum>(frontFace_));
    if (!cull_) glDisable(GL_CULL_FACE);
    if (!depthTest_) glDisable(GL_DEPTH_TEST);
}

}  // namespace dyncull::detail
