// The raster state shared by the GL volume tests (volume_raster.hpp).
#include "volume_raster.hpp"

#include "depth_convention.hpp"

namespace dyncull::detail {

void VolumeTestState::enter() {
    glGetBooleanv(GL_COLOR_WRITEMASK, colourMask_);
    glGetBooleanv(GL_DEPTH_WRITEMASK, &depthMask_);
    glGetIntegerv(GL_DEPTH_FUNC, &depthFunc_);
    glGetFloatv(GL_POLYGON_OFFSET_FACTOR, &offsetFactor_);
    glGetFloatv(GL_POLYGON_OFFSET_UNITS, &offsetUnits_);
    cull_ = glIsEnabled(GL_CULL_FACE);
    depthTest_ = glIsEnabled(GL_DEPTH_TEST);
    offsetFill_ = glIsEnabled(GL_POLYGON_OFFSET_FILL);

    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glDepthMask(GL_FALSE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(kDepthNearerOrEqual);
    glDisable(GL_CULL_FACE);
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
    if (cull_) glEnable(GL_CULL_FACE);
    if (!depthTest_) glDisable(GL_DEPTH_TEST);
}

}  // namespace dyncull::detail
