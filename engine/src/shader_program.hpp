// Internal: compile and link a GLSL program (engine only).
#pragma once

#include <cstdint>
#include <string>

namespace dyncull::detail {

/// Returns the program name, or 0 with the driver's log in `log`.
std::uint32_t buildProgram(const char* vertexSource, const char* fragmentSource, std::string& log);

/// GLSL sources of the mesh shaders (lit per vertex, lit per pixel) and of the
/// position-only box shader. The lit fragment shaders hold two placeholders,
/// DYNCULL_MARKS_DECLARATION and DYNCULL_MARK, that litFragmentSource() fills; the lit
/// vertex shaders two, DYNCULL_RANGE_DECLARATION and DYNCULL_RANGE, for litVertexSource().
extern const char* const kVertexLitVertexShader;
extern const char* const kVertexLitFragmentShader;
extern const char* const kLitVertexShader;
extern const char* const kLitFragmentShader;
extern const char* const kTriangleTestVertexShader;
extern const char* const kTriangleTestFragmentShader;  // a lit fragment shader's placeholders, marking only
extern const char* const kMarksDeclaration;
extern const char* const kMarkStatement;
/// What a lit program's fragments mark: nothing, one slot per draw (uMarkSlot), or one
/// slot per range of a multi-draw (uMarkSlot + the range's index in the draw; needs
/// ARB_shader_draw_parameters).
enum class MarkKind : std::uint8_t { None, Draw, Range };
/// `source` (a lit fragment shader) with its placeholders filled for `marks`.
std::string litFragmentSource(const char* source, MarkKind marks);
/// `source` (a lit vertex shader) with its placeholders filled for `marks`: only
/// MarkKind::Range needs the vertex stage (it passes the range's index on).
std::string litVertexSource(const char* source, MarkKind marks);
/// Storage-buffer binding point of the marks (kMarksDeclaration).
inline constexpr std::uint32_t kMarksBinding = 1;
extern const char* const kBoxVertexShader;
extern const char* const kBoxFragmentShader;

}  // namespace dyncull::detail
