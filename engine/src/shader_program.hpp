// Internal: compile and link a GLSL program (engine only).
#pragma once

#include <cstdint>
#include <string>

namespace dyncull::detail {

/// Returns the program name, or 0 with the driver's log in `log`.
std::uint32_t buildProgram(const char* vertexSource, const char* fragmentSource, std::string& log);

/// GLSL sources of the mesh shaders (lit per vertex, lit per pixel) and of the
/// position-only box shader.
extern const char* const kVertexLitVertexShader;
extern const char* const kVertexLitFragmentShader;
extern const char* const kLitVertexShader;
extern const char* const kLitFragmentShader;
extern const char* const kBoxVertexShader;
extern const char* const kBoxFragmentShader;

}  // namespace dyncull::detail
