// Internal (engine): the one convention for which faces are drawn, shared by the renderer
// and the ID pass so ground truth sees exactly what was drawn. A mesh whose surface allows
// it (FaceMode::CullBack) has its back faces culled; an object whose matrix mirrors
// (negative determinant) turns its counter-clockwise front faces clockwise.
#pragma once

#include <epoxy/gl.h>
#include <glm/glm.hpp>

namespace dyncull::detail {

// The caller keeps the GL culling state as last set here (`enabled`, `frontCcw`), so draws
// switch only what changes.

/// Culling off, back faces as the culled side, counter-clockwise fronts: the state a pass
/// starts from and leaves behind.
inline void resetFaceCulling(bool& enabled, bool& frontCcw) {
    glDisable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    enabled = false;
    frontCcw = true;
}

/// Before drawing a mesh with `cull` (its FaceMode is CullBack) under `objectToWorld`.
inline void setFaceCulling(bool& enabled, bool& frontCcw, bool cull, const glm::mat3& objectToWorld) {
    if (cull != enabled) {
        cull ? glEnable(GL_CULL_FACE) : glDisable(GL_CULL_FACE);
        enabled = cull;
    }
    if (!cull) return;  // the front face matters only while culling
    const bool ccw = glm::determinant(objectToWorld) > 0.0f;
    if (ccw != frontCcw) {
        glFrontFace(ccw ? GL_CCW : GL_CW);
        frontCcw = ccw;
    }
}

}  // namespace dyncull::detail
