// Internal: what every GL test of a query volume shares, so a hardware query
// (GlQueryBackend::issue) and the batched raster test (batched_raster_test.cpp) draw the
// same pixels and give the same answer.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include <epoxy/gl.h>
#include <glm/glm.hpp>

#include "dyncull/scheduler/query_backend.hpp"

namespace dyncull::detail {

/// A query volume ready to draw: eye-relative float points of the volume grown by its
/// float rounding (QueryVolume::enlargedForRounding), and whether it is drawn by its own
/// triangles (`mesh`) or as an 8-corner box.
struct DrawnVolume {
    std::array<glm::vec3, QueryVolume::kMaxVertices> points;
    std::uint32_t count = 0;
    bool mesh = false;
};

/// The camera a frame's volumes are drawn from: world-space eye, unit view direction and
/// near-plane distance (world units), and how far every face is pushed out for the
/// rasteriser's vertex snapping (world units per unit of distance; snapGrowth).
struct VolumeView {
    glm::dvec3 eye{0.0};
    glm::dvec3 forward{0.0, 0.0, -1.0};
    double nearPlane = 0.0;
    double growPerDistance = 0.0;
};

/// World units per unit of distance that cover the rasteriser's vertex snapping: GL snaps
/// window coordinates to 2^-subpixelBits of a pixel, so a part's edge and its volume's edge
/// may each move by half a step, the volume's inward and the part's outward, and a pixel
/// centre just outside the part's exact outline can be covered by the part and not by its
/// volume. Two whole steps, in the larger of the pixel's two sides at unit distance.
inline double snapGrowth(int subpixelBits, double fovYRadians, double aspect, int width, int height) {
    const double tanHalf = std::tan(0.5 * fovYRadians);
    const double pixel = std::max(2.0 * tanHalf / double(height), 2.0 * tanHalf * aspect / double(width));
    return std::ldexp(2.0, -std::clamp(subpixelBits, 0, 16)) * pixel;
}

/// Fills `out` and returns true, or returns false when the grown volume reaches the near
/// plane: clipped there it could answer "occluded" for visible geometry, so such a volume
/// is answered Visible without being drawn.
inline bool prepareVolume(const QueryVolume& volume, const VolumeView& view, DrawnVolume& out) {
    std::array<glm::dvec3, QueryVolume::kMaxVertices> rel;
    bool asBox = false;
    out.count = volume.enlargedForRounding(view.eye, rel, asBox, view.growPerDistance);
    out.mesh = !asBox && !volume.isBox();
    for (std::uint32_t i = 0; i < out.count; ++i) {
        if (glm::dot(rel[i], view.forward) < view.nearPlane) return false;
        out.points[i] = glm::vec3(rel[i]);
    }
    return true;
}

/// The raster state of a volume test, entered and left around the draws: colour and depth
/// writes off, depth test nearer-or-equal (a face coplanar with drawn geometry counts as
/// visible), both sides drawn, and the volume pulled toward the eye by a few depth steps.
/// Saves what it changes and restores it.
class VolumeTestState {
public:
    void enter();
    void leave();

private:
    GLboolean colourMask_[4] = {GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE};
    GLboolean depthMask_ = GL_TRUE;
    GLint depthFunc_ = 0;
    GLfloat offsetFactor_ = 0.0f, offsetUnits_ = 0.0f;
    bool cull_ = false, depthTest_ = false, offsetFill_ = false;
};

}  // namespace dyncull::detail
