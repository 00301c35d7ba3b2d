// Internal: what every GL test of a query volume shares, so a hardware query
// (GlQueryBackend::issue) and the batched raster test (batched_raster_test.cpp) draw the
// same pixels and give the same answer.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

#include <epoxy/gl.h>
#include <glm/glm.hpp>

#include "dyncull/scheduler/query_backend.hpp"

namespace dyncull::detail {

/// A query volume ready to draw, as eye-relative float points and 8-bit triangle indices:
/// the volume grown by its float rounding (QueryVolume::enlargedForRounding), and around
/// its screen outline a ring for the rasteriser's vertex snapping (see prepareVolume).
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
/// width of the snapping ring in pixels (ringWidth; 0: no ring).
struct VolumeView {
    glm::dvec3 eye{0.0};
    glm::dvec3 forward{0.0, 0.0, -1.0};
    double nearPlane = 0.0;
    glm::dmat4 viewProj{1.0};
    glm::dmat4 inverseViewProj{1.0};
    double width = 1.0, height = 1.0;
    double ringPixels = 0.0;
};

/// The snapping ring's width for a rasteriser with `subpixelBits` (GL_SUBPIXEL_BITS): GL
/// snaps window coordinates to 2^-subpixelBits of a pixel, so a part's edge may move out by
/// half a step and its volume's edge in by half a step (together at most sqrt(2) steps
/// diagonally); four steps cover both with room to spare.
inline double ringWidth(int subpixelBits) { return 4.0 / double(1u << std::min(std::max(subpixelBits, 0), 16)); }

/// Fills `out` and returns true, or returns false when the grown volume reaches the near
/// plane: clipped there it could answer "occluded" for visible geometry, so such a volume
/// is answered Visible without being drawn.
///
/// The ring: a part's snapped triangle can cover a pixel centre just outside its exact
/// outline, and so just outside its tight volume's snapped outline (seen on the bunny
/// swarm: 0.0013 px). Growing the volume in world space would also move its faces toward
/// the eye and cull less than it must; instead a flat strip is laid along the volume's
/// screen outline (its points' 2D convex hull), reaching `view.ringPixels` to both sides
/// of each edge and past both of its ends (so the corners are covered), at the volume's
/// nearest depth. A fragment of a snapped triangle takes a convex combination of its vertices'
/// depths, and the part's vertices lie inside the volume, so no part fragment under the
/// ring is nearer than the ring: it is as conservative as the volume, only wider.
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
