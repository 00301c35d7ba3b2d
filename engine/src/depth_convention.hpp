// The engine's side of the reversed-Z depth convention (objects/camera.hpp): every pass
// that depth-tests against the scene uses these instead of GL_LESS / GL_LEQUAL / clear 1.
// Nearer means a greater depth value: clip z / w is 1 at the near plane, 0 at the far plane.
#pragma once

#include <epoxy/gl.h>

namespace dyncull::detail {

inline constexpr GLenum kDepthNearer = GL_GREATER;        ///< keep the nearer fragment (was GL_LESS)
inline constexpr GLenum kDepthNearerOrEqual = GL_GEQUAL;  ///< ties pass (was GL_LEQUAL)
inline constexpr GLenum kDepthFarther = GL_LESS;          ///< hidden behind the scene (was GL_GREATER)
inline constexpr GLfloat kDepthCleared = 0.0f;            ///< the far plane (was 1)
/// glPolygonOffset's sign that moves a polygon toward the eye (was negative).
inline constexpr GLfloat kTowardEye = 1.0f;

/// Clip z / w used as depth unchanged (no [-1, 1] to [0, 1] remap, which would round away
/// the small depths of distant geometry). Context state: set once per context and again
/// by each pass that starts a frame, in case a game changed it in between.
inline void useReversedDepth() { glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE); }

}  // namespace dyncull::detail
