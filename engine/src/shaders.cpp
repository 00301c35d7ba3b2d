// GLSL sources. Lighting is deliberately simple and camera-relative so any model reads
// clearly from any framing: a key light above-left of the eye, a hemispheric ambient and
// a view-facing fill; normals are flipped towards the viewer because scanned/CAD meshes
// often have inconsistent winding and we draw without back-face culling.
#include "shader_program.hpp"

namespace dyncull::detail {

const char* const kLitVertexShader = R"(#version 450 core
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
uniform mat4 uViewProj;
uniform mat4 uModel;
uniform mat3 uNormalMat;
out vec3 vWorldPos;
out vec3 vNormal;
void main() {
    vec4 world = uModel * vec4(aPosition, 1.0);
    vWorldPos = world.xyz;
    vNormal = uNormalMat * aNormal;
    gl_Position = uViewProj * world;
}
)";

const char* const kLitFragmentShader = R"(#version 450 core
in vec3 vWorldPos;
in vec3 vNormal;
uniform vec3 uColour;
uniform vec3 uEye;
uniform vec3 uLightDir;  // towards the light, unit, world space
out vec4 fragColour;
void main() {
    vec3 n = normalize(vNormal);
    vec3 v = normalize(uEye - vWorldPos);
    if (dot(n, v) < 0.0) n = -n;
    float key = max(dot(n, uLightDir), 0.0);
    float hemi = 0.5 + 0.5 * n.y;
    float fill = pow(max(dot(n, v), 0.0), 2.0);
    vec3 c = uColour * (0.18 + 0.12 * hemi + 0.55 * key + 0.22 * fill);
    fragColour = vec4(pow(clamp(c, 0.0, 1.0), vec3(1.0 / 1.2)), 1.0);
}
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
