// What the GL volume tests share (volume_raster.hpp): a volume's drawn points and
// triangles with its snapping margin, and the raster state they are drawn in.
#include "volume_raster.hpp"

#include <cmath>
#include <limits>
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

/// Grows the box whose eye-relative corners are `rel` (corner i at centre +- half-edges
/// a0, a1, a2 by the bits of i) by a disc across the view (see prepareVolume). The corners
/// move, not a rebuilt box: they are a parallelepiped only to within their float rounding,
/// which enlargedForRounding covered, and moving each face as a whole keeps that cover.
/// False, unchanged, if the box has no three independent edges (it then gets the ring).
bool growBoxAcrossView(std::span<glm::dvec3, 8> rel, const VolumeView& view) {
    const glm::dvec3 a[3] = {0.5 * (rel[1] - rel[0]), 0.5 * (rel[2] - rel[0]), 0.5 * (rel[4] - rel[0])};
    double farthestW = 0.0;
    for (const glm::dvec3& p : rel) farthestW = std::max(farthestW, (view.viewProj * glm::dvec4(p, 1.0)).w);
    const double radius = view.marginPixels * view.unitsPerPixel * farthestW;
    if (!std::isfinite(radius)) return false;
    const double volume = std::abs(glm::dot(a[0], glm::cross(a[1], a[2])));
    glm::dvec3 move[3];
    for (int i = 0; i < 3; ++i) {
        const glm::dvec3 across = glm::cross(a[(i + 1) % 3], a[(i + 2) % 3]);  // the normal of faces +-i, unnormalised
        const double area = glm::length(across);
        if (!(area > 0.0 && volume > 0.0)) return false;
        // Faces +-i lie volume / area from the centre; moving them out by `push` along
        // their normal is moving their corners by push / that along a_i.
        const double cosine = glm::dot(across, view.forward) / area;
        const double push = radius * std::sqrt(std::max(0.0, 1.0 - cosine * cosine));
        move[i] = a[i] * (push * area / volume);
    }
    for (std::uint32_t c = 0; c < 8; ++c)
        rel[c] += ((c & 1u) ? move[0] : -move[0]) + ((c & 2u) ? move[1] : -move[1]) + ((c & 4u) ? move[2] : -move[2]);
    return true;
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
    const double w = view.marginPixels;
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

VolumeView VolumeView::of(const FrameView& frame, SnappingMargin margin, int subpixelBits) {
    VolumeView v;
    const Camera& camera = frame.camera;
    v.eye = glm::dvec3(camera.position);
    v.forward = glm::dvec3(camera.forward());
    v.nearPlane = double(camera.nearPlane);
    v.viewProj = frame.viewProjRelative;
    v.inverseViewProj = frame.inverseViewProjRelative;
    v.width = frame.width;
    v.height = frame.height;
    v.margin = margin;
    v.marginPixels = margin == SnappingMargin::None ? 0.0 : marginWidth(subpixelBits);
    v.unitsPerPixel = unitsPerPixelAcrossView(v.viewProj, v.forward, v.width, v.height);
    return v;
}

double unitsPerPixelAcrossView(const glm::dmat4& viewProj, const glm::dvec3& forward, double width, double height) {
    // Rows 0 and 1 (pixels per unit of clip x, y / w), without their part along `forward`.
    const glm::dvec3 row0(viewProj[0][0], viewProj[1][0], viewProj[2][0]), row1(viewProj[0][1], viewProj[1][1], viewProj[2][1]);
    const glm::dvec3 x = 0.5 * width * (row0 - glm::dot(row0, forward) * forward);
    const glm::dvec3 y = 0.5 * height * (row1 - glm::dot(row1, forward) * forward);
    // The smallest singular value: the square root of the Gram matrix's smaller eigenvalue.
    const double xx = glm::dot(x, x), yy = glm::dot(y, y), xy = glm::dot(x, y);
    const double half = 0.5 * (xx + yy), det = xx * yy - xy * xy;
    const double smallest = det / (half + std::sqrt(std::max(0.0, half * half - det)));  // no cancellation
    return smallest > 0.0 ? 1.0 / std::sqrt(smallest) : std::numeric_limits<double>::infinity();
}

bool prepareVolume(const QueryVolume& volume, const VolumeView& view, DrawnVolume& out) {
    std::array<glm::dvec3, QueryVolume::kMaxVertices> rel;
    bool asBox = false;
    out.count = volume.enlargedForRounding(view.eye, rel, asBox);
    const bool box = asBox || volume.isBox();
    const bool grown = box && view.margin == SnappingMargin::GrowBoxes && view.marginPixels > 0.0 &&
                       growBoxAcrossView(std::span<glm::dvec3, 8>(rel.data(), 8), view);
    for (std::uint32_t i = 0; i < out.count; ++i) {
        if (glm::dot(rel[i], view.forward) < view.nearPlane) return false;
        out.points[i] = glm::vec3(rel[i]);
    }
    const std::span<const std::uint8_t> tris = box ? std::span<const std::uint8_t>(kBoxTriangles) : volume.triangles();
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
    if (!grown && view.marginPixels > 0.0) addRing({rel.data(), out.count}, view, out);
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
