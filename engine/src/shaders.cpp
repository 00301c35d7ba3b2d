// GLSL sources. Lighting is deliberately simple and camera-relative so any model reads
// clearly from any framing: a key light above-left of the eye, a hemispheric ambient and
// a view-facing fill. Normals are turned towards the viewer because meshes drawn
// two-sided (open or inconsistently wound, see surface_orientation.hpp) show their backs.
// The default evaluates it per vertex: on llvmpipe every fragment costs CPU time and a
// dense scene shades each pixel several times, while its triangles are a few pixels big.
#include "shader_program.hpp"

#include <string_view>

namespace dyncull::detail {

// Per-vertex lighting (Shading::Vertex). The light is white, so only its intensity varies
// over a surface: one interpolated float instead of a colour (llvmpipe sets up every
// varying of every triangle, and the swarm's triangles are smaller than a pixel). The
// display gamma is separable, pow(c * i, g) = pow(c, g) * pow(i, g), so the colour's part
// is a uniform (uColour is given already raised to 1 / 1.2 by the renderer).
const char* const kVertexLitVertexShader = R"(#version 450 core
DYNCULL_RANGE_DECLARATION
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
uniform mat4 uViewProj;
uniform mat4 uModel;
uniform mat3 uNormalMat;
uniform vec3 uLightDir;  // towards the light, unit, world space
uniform vec4 uViewer;    // the eye (0, 0, 0, 1: eye-relative) or, orthographic, the direction towards it (w = 0)
out float vIntensity;
invariant gl_Position;  // as kTriangleTestVertexShader's, so a test sees the drawn fragments
void main() {
    vec4 world = uModel * vec4(aPosition, 1.0);  // relative to the eye (camera-relative)
    gl_Position = uViewProj * world;
    vec3 n = normalize(uNormalMat * aNormal);
    float nv = dot(n, normalize(uViewer.xyz - world.xyz * uViewer.w));
    if (nv < 0.0) { n = -n; nv = -nv; }
    float key = max(dot(n, uLightDir), 0.0);
    float hemi = 0.5 + 0.5 * n.y;
    vIntensity = pow(0.18 + 0.12 * hemi + 0.55 * key + 0.22 * nv * nv, 1.0 / 1.2);
    DYNCULL_RANGE;
}
)";

const char* const kVertexLitFragmentShader = R"(#version 450 core
DYNCULL_MARKS_DECLARATION
in float vIntensity;
uniform vec3 uColour;  // already raised to 1 / 1.2
out vec4 fragColour;
void main() {
    fragColour = vec4(min(uColour * vIntensity, vec3(1.0)), 1.0);
    DYNCULL_MARK;
}
)";

// Per-pixel lighting (Shading::Pixel): the same terms evaluated per fragment.
const char* const kLitVertexShader = R"(#version 450 core
DYNCULL_RANGE_DECLARATION
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
uniform mat4 uViewProj;
uniform mat4 uModel;
uniform mat3 uNormalMat;
out vec3 vWorldPos;
out vec3 vNormal;
invariant gl_Position;  // as kTriangleTestVertexShader's, so a test sees the drawn fragments
void main() {
    vec4 world = uModel * vec4(aPosition, 1.0);
    vWorldPos = world.xyz;
    vNormal = uNormalMat * aNormal;
    gl_Position = uViewProj * world;
    DYNCULL_RANGE;
}
)";

const char* const kLitFragmentShader = R"(#version 450 core
DYNCULL_MARKS_DECLARATION
in vec3 vWorldPos;
in vec3 vNormal;
uniform vec3 uColour;
uniform vec4 uViewer;  // the eye (0, 0, 0, 1: eye-relative) or, orthographic, the direction towards it (w = 0)
uniform vec3 uLightDir;  // towards the light, unit, world space
out vec4 fragColour;
void main() {
    vec3 n = normalize(vNormal);
    vec3 v = normalize(uViewer.xyz - vWorldPos * uViewer.w);
    if (dot(n, v) < 0.0) n = -n;
    float key = max(dot(n, uLightDir), 0.0);
    float hemi = 0.5 + 0.5 * n.y;
    float fill = pow(max(dot(n, v), 0.0), 2.0);
    vec3 c = uColour * (0.18 + 0.12 * hemi + 0.55 * key + 0.22 * fill);
    fragColour = vec4(pow(clamp(c, 0.0, 1.0), vec3(1.0 / 1.2)), 1.0);
    DYNCULL_MARK;
}
)";

// Marks (renderer.hpp, Renderer::drawRange's `markSlot`): the variant of a lit fragment
// shader that also records whether its draw drew a sample that passed the depth test. With
// early depth testing only passing fragments run, so a store means a visible sample; the
// shaders neither discard nor write depth, so testing early changes no pixel. The plain
// variant leaves the placeholders out. Marks per range (MarkKind::Range) give each range
// of a multi-draw its own slot: the vertex stage hands the range's index in the draw
// (gl_DrawIDARB, ARB_shader_draw_parameters, core in GL 4.6) to the fragment stage, flat.
const char* const kMarksDeclaration = R"(
layout(early_fragment_tests) in;
layout(std430, binding = 1) writeonly buffer Marks { uint marks[]; };
uniform uint uMarkSlot;
)";
const char* const kMarkStatement = "marks[uMarkSlot] = 1u";
namespace {
const char* const kRangeInput = "flat in uint vRange;\n";  // after kMarksDeclaration
const char* const kRangeMarkStatement = "marks[uMarkSlot + vRange] = 1u";
const char* const kRangeVertexDeclaration = R"(#extension GL_ARB_shader_draw_parameters : require
flat out uint vRange;
)";
const char* const kRangeVertexStatement = "vRange = uint(gl_DrawIDARB)";

void fill(std::string& s, std::string_view placeholder, std::string_view text) {
    const std::size_t at = s.find(placeholder);
    if (at != std::string::npos) s.replace(at, placeholder.size(), text);
}
}  // namespace

std::string litFragmentSource(const char* source, MarkKind marks) {
    std::string s(source);
    // The declaration first: DYNCULL_MARK is its prefix.
    const std::string declaration = marks == MarkKind::None ? "" : std::string(kMarksDeclaration) + (marks == MarkKind::Range ? kRangeInput : "");
    fill(s, "DYNCULL_MARKS_DECLARATION", declaration);
    fill(s, "DYNCULL_MARK", marks == MarkKind::Draw ? kMarkStatement : marks == MarkKind::Range ? kRangeMarkStatement : "");
    return s;
}

std::string litVertexSource(const char* source, MarkKind marks) {
    std::string s(source);
    fill(s, "DYNCULL_RANGE_DECLARATION", marks == MarkKind::Range ? kRangeVertexDeclaration : "");
    fill(s, "DYNCULL_RANGE", marks == MarkKind::Range ? kRangeVertexStatement : "");
    return s;
}

// The triangle test (Renderer::testRange): the lit shaders' position, computed by the same
// expression and declared invariant in all three, so a test rasterises exactly the
// fragments a draw would; and only the mark in the fragment stage.
const char* const kTriangleTestVertexShader = R"(#version 450 core
layout(location = 0) in vec3 aPosition;
uniform mat4 uViewProj;
uniform mat4 uModel;
invariant gl_Position;
void main() {
    vec4 world = uModel * vec4(aPosition, 1.0);
    gl_Position = uViewProj * world;
}
)";
const char* const kTriangleTestFragmentShader = R"(#version 450 core
DYNCULL_MARKS_DECLARATION
void main() { DYNCULL_MARK; }
)";

const char* const kBoxVertexShader = R"(#version 450 core
layout(location = 0) in vec3 aPosition;
uniform mat4 uMvp;
void main() { gl_Position = uMvp * vec4(aPosition, 1.0); }
)";

const char* const kBoxFragmentShader = R"(#version 450 core
out vec4 fragColour;
void main() { fragColour = vec4(1.0); }
)";

}  // namespace dyncull::detail
