// Internal: what every GL test of a query volume shares, so a hardware query
// (GlQueryBackend::issue) and the batched raster test (batched_raster_test.cpp) draw the
// same pixels and give the same answer.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

#include <epoxy/gl.h>
#include <glm/glm.hpp>

#include "dyncull/engine/gl_query_backend.hpp"
#include "dyncull/scheduler/query_backend.hpp"

namespace dyncull::detail {

/// A query volume ready to draw, as eye-relative float points and 8-bit triangle indices:
/// the volume grown by its float rounding (QueryVolume::enlargedForRounding), and its
/// screen outline widened for the rasteriser's vertex snapping (see prepareVolume).
struct DrawnVolume {
    /// The volume's points, then 4 per edge of its screen outline (at most one per point).
    static constexpr std::uint32_t kMaxPoints = 5 * QueryVolume::kMaxVertices;
    static constexpr std::uint32_t kMaxIndices = 3 * (QueryVolume::kMaxTriangles + 2 * QueryVolume::kMaxVertices);
    static_assert(kMaxPoints <= 256, "8-bit indices");
    std::array<glm::vec3, kMaxPoints> points;
    std::uint32_t count = 0;
    std::array<std::uint8_t, kMaxIndices> indices;
    std::uint32_t indexCount = 0;
};

/// The camera a frame's volumes are drawn from: world-space eye, unit view direction and
/// near-plane distance (world units), the camera-relative view-projection
/// (Camera::viewProjectionRelativeDouble) and its inverse, the viewport in pixels, and the
/// snapping margin: how, and by how many pixels (marginWidth), outlines are widened.
struct VolumeView {
    glm::dvec3 eye{0.0};
    glm::dvec3 forward{0.0, 0.0, -1.0};
    double nearPlane = 0.0;
    glm::dmat4 viewProj{1.0};
    glm::dmat4 inverseViewProj{1.0};
    double width = 1.0, height = 1.0;
    SnappingMargin margin = SnappingMargin::GrowBoxes;
    double marginPixels = 0.0;
    /// World units a pixel spans at clip w = 1, in the worst direction across the view
    /// (unitsPerPixelAcrossView): a disc across the view of this radius times w covers a
    /// pixel wherever it lies.
    double unitsPerPixel = 0.0;

    /// Fills the fields from a frame's camera, viewport and margin.
    static VolumeView of(const FrameView& frame, SnappingMargin margin, int subpixelBits);
};

/// The snapping margin's width for a rasteriser with `subpixelBits` (GL_SUBPIXEL_BITS): GL
/// snaps window coordinates to 2^-subpixelBits of a pixel, so a part's edge may move out by
/// half a step and its volume's edge in by half a step (together at most sqrt(2) steps
/// diagonally); four steps cover both with room to spare.
inline double marginWidth(int subpixelBits) { return 4.0 / double(1u << std::min(std::max(subpixelBits, 0), 16)); }

/// World units per pixel at clip w = 1 for the camera-relative `viewProj`, largest over the
/// directions across the unit view direction `forward`: 1 / the smallest singular value of
/// the map from such a direction to pixels. For a perspective camera clip w is the depth
/// along `forward`, for an orthographic one 1, and either way a direction across the view
/// does not change w, so a disc across the view at w projects to at least an ellipse whose
/// smaller radius is its radius / (w * unitsPerPixel).
double unitsPerPixelAcrossView(const glm::dmat4& viewProj, const glm::dvec3& forward, double width, double height);

/// Fills `out` and returns true, or returns false when the grown volume reaches the near
/// plane: clipped there it could answer "occluded" for visible geometry, so such a volume
/// is answered Visible without being drawn.
///
/// The snapping margin: a part's snapped triangle can cover a pixel centre just outside its
/// exact outline, and so just outside its tight volume's snapped outline (seen on the bunny
/// swarm: 0.0013 px). Growing the volume by a ball would also move its faces toward the eye
/// and cull less than it must (reversed Z separates 1e-5 of the depth; a ball of
/// `marginPixels` moves faces by 4e-5 at 640x360). So:
/// - A box is grown by a disc across the view direction, of radius marginPixels *
///   unitsPerPixel * (its farthest clip w): every point's disc then covers that many pixels
///   around its image. Each pair of faces moves out by the disc's support along its normal
///   n, radius * sqrt(1 - (n . forward)^2): a face facing the eye does not move, an oblique
///   one moves toward the eye by at most half the radius.
/// - Other volumes (k-DOPs) get a ring: a flat strip along the screen outline (the points'
///   2D convex hull), reaching `marginPixels` to both sides of each edge and past both of
///   its ends (so the corners are covered), at the volume's nearest depth. A fragment of a
///   snapped triangle takes a convex combination of its vertices' depths, and the part's
///   vertices lie inside the volume, so no part fragment under the ring is nearer than the
///   ring: it is as conservative as the volume, only wider. It doubles a box's triangles,
///   which is why boxes are grown instead.
bool prepareVolume(const QueryVolume& volume, const VolumeView& view, DrawnVolume& out);

/// The raster state of a volume test, entered and left around the draws: colour and depth
/// writes off, depth test nearer-or-equal (a face coplanar with drawn geometry counts as
/// visible), back faces culled (counter-clockwise fronts in window coordinates, y up, as
/// prepareVolume orients them), and the volume pulled toward the eye by a few depth steps.
/// Saves what it changes and restores it.
class VolumeTestState {
public:
    void enter();
    void leave();

private:
    GLboolean colourMask_[4] = {GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE};
    GLboolean depthMask_ = GL_TRUE;
    GLint depthFunc_ = 0, cullMode_ = GL_BACK, frontFace_ = GL_CCW;
    GLfloat offsetFactor_ = 0.0f, offsetUnits_ = 0.0f;
    bool cull_ = false, depthTest_ = false, offsetFill_ = false;
};

}  // namespace dyncull::detail
