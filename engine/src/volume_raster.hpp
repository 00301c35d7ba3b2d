// Internal: what every GL test of a query volume shares, so a hardware query
// (GlQueryBackend::issue) and the batched raster test (batched_raster_test.cpp) draw the
// same pixels and give the same answer.
#pragma once

#include <array>
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
/// near-plane distance (world units).
struct VolumeView {
    glm::dvec3 eye{0.0};
    glm::dvec3 forward{0.0, 0.0, -1.0};
    double nearPlane = 0.0;
};

/// Fills `out` and returns true, or returns false when the grown volume reaches the near
/// plane: clipped there it could answer "occluded" for visible geometry, so such a volume
/// is answered Visible without being drawn.
inline bool prepareVolume(const QueryVolume& volume, const VolumeView& view, DrawnVolume& out) {
    std::array<glm::dvec3, QueryVolume::kMaxVertices> rel;
    bool asBox = false;
    out.count = volume.enlargedForRounding(view.eye, rel, asBox);
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
