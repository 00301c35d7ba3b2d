// Wide coloured lines: a geometry shader clips each segment against the near plane and
// expands it into a screen-aligned quad of the requested pixel width (core-profile GL
// rejects glLineWidth > 1 in forward-compatible contexts).
#include "dyncull/viewer/debug_draw.hpp"

#include <cstring>
#include <string>

#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>

#include "depth_convention.hpp"
#include "shader_program.hpp"

namespace dyncull {
namespace {

const char* const kLineVertexShader = R"(#version 450 core
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec4 aColour;
uniform mat4 uViewProj;
out vec4 vColour;
void main() {
    vColour = aColour;
    gl_Position = uViewProj * vec4(aPosition, 1.0);
}
)";

// Near-plane clipping must happen before the divide by w, or segments crossing the eye
// plane would flip to the wrong side of the screen.
const char* const kLineGeometryShader = R"(#version 450 core
layout(lines) in;
layout(triangle_strip, max_vertices = 4) out;
in vec4 vColour[];
out vec4 gColour;
uniform vec2 uViewport;
uniform float uWidth;
void main() {
    vec4 p0 = gl_in[0].gl_Position, p1 = gl_in[1].gl_Position;
    float d0 = p0.w - p0.z, d1 = p1.w - p1.z;  // >= 0 in front of the near plane (reversed Z: z <= w)
    if (d0 < 0.0 && d1 < 0.0) return;
    if (d0 < 0.0) p0 = mix(p0, p1, d0 / (d0 - d1));
    if (d1 < 0.0) p1 = mix(p1, p0, d1 / (d1 - d0));
    vec2 s0 = p0.xy / p0.w * 0.5 * uViewport, s1 = p1.xy / p1.w * 0.5 * uViewport;
    vec2 dir = s1 - s0;
    float len = length(dir);
    dir = len > 1e-4 ? dir / len : vec2(1.0, 0.0);
    vec2 side = vec2(-dir.y, dir.x) * (0.5 * uWidth);
    vec2 along = dir * (0.5 * uWidth);  // square caps close the box corners
    vec2 toClip = 2.0 / uViewport;
    vec2 o[4] = vec2[4](-along - side, -along + side, along - side, along + side);
    for (int i = 0; i < 4; ++i) {
        vec4 p = i < 2 ? p0 : p1;
        gColour = vColour[i < 2 ? 0 : 1];
        gl_Position = vec4(p.xy + o[i] * toClip * p.w, p.zw);
        EmitVertex();
    }
    EndPrimitive();
}
)";

const char* const kLineFragmentShader = R"(#version 450 core
in vec4 gColour;
uniform float uAlpha;
out vec4 fragColour;
void main() { fragColour = vec4(gColour.rgb, gColour.a * uAlpha); }
)";

std::uint32_t compileStage(GLenum type, const char* source, std::string& log) {
    const GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &source, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char buf[1024] = {};
        glGetShaderInfoLog(s, sizeof buf, nullptr, buf);
        log = buf;
        glDeleteShader(s);
        return 0;
    }
    return s;
}

// buildProgram handles vertex + fragment only; this program also has a geometry stage.
std::uint32_t buildLineProgram(std::string& log) {
    const GLuint vs = compileStage(GL_VERTEX_SHADER, kLineVertexShader, log);
    const GLuint gs = vs ? compileStage(GL_GEOMETRY_SHADER, kLineGeometryShader, log) : 0;
    const GLuint fs = gs ? compileStage(GL_FRAGMENT_SHADER, kLineFragmentShader, log) : 0;
    GLuint program = 0;
    if (vs && gs && fs) {
        program = glCreateProgram();
        glAttachShader(program, vs);
        glAttachShader(program, gs);
        glAttachShader(program, fs);
        glLinkProgram(program);
        GLint ok = 0;
        glGetProgramiv(program, GL_LINK_STATUS, &ok);
        if (!ok) {
            char buf[1024] = {};
            glGetProgramInfoLog(program, sizeof buf, nullptr, buf);
            log = buf;
            glDeleteProgram(program);
            program = 0;
        }
    }
    for (GLuint s : {vs, gs, fs})
        if (s) glDeleteShader(s);
    return program;
}

}  // namespace

DebugDraw::DebugDraw() {
    std::string log;
    program_ = buildLineProgram(log);
    if (!program_) {
        std::strncpy(log_, log.c_str(), sizeof log_ - 1);
        return;
    }
    locViewProj_ = glGetUniformLocation(program_, "uViewProj");
    locViewport_ = glGetUniformLocation(program_, "uViewport");
    locWidth_ = glGetUniformLocation(program_, "uWidth");
    locAlpha_ = glGetUniformLocation(program_, "uAlpha");
    glCreateVertexArrays(1, &vao_);
    glEnableVertexArrayAttrib(vao_, 0);
    glVertexArrayAttribFormat(vao_, 0, 3, GL_FLOAT, GL_FALSE, offsetof(Vertex, position));
    glVertexArrayAttribBinding(vao_, 0, 0);
    glEnableVertexArrayAttrib(vao_, 1);
    glVertexArrayAttribFormat(vao_, 1, 4, GL_FLOAT, GL_FALSE, offsetof(Vertex, colour));
    glVertexArrayAttribBinding(vao_, 1, 0);
}

DebugDraw::~DebugDraw() {
    if (vao_) glDeleteVertexArrays(1, &vao_);
    if (vbo_) glDeleteBuffers(1, &vbo_);
    if (program_) glDeleteProgram(program_);
}

void DebugDraw::addLine(const glm::vec3& a, const glm::vec3& b, const glm::vec4& colour) {
    vertices_.push_back({a, colour});
    vertices_.push_back({b, colour});
}

void DebugDraw::addBox(const Aabb& box, const glm::vec4& colour, const glm::mat4& model) {
    if (box.empty()) return;
    // Corner i has x = bit 0, y = bit 1, z = bit 2 of i; edges join corners one bit apart.
    glm::vec3 c[8];
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 local((i & 1) ? box.max.x : box.min.x, (i & 2) ? box.max.y : box.min.y,
                              (i & 4) ? box.max.z : box.min.z);
        c[i] = glm::vec3(model * glm::vec4(local, 1.0f));
    }
    for (int i = 0; i < 8; ++i)
        for (int bit = 1; bit < 8; bit <<= 1)
            if (!(i & bit)) addLine(c[i], c[i | bit], colour);
}

void DebugDraw::drawPass(std::uint32_t depthFunc, float alphaScale) {
    if (depthFunc == GL_ALWAYS) {
        glDisable(GL_DEPTH_TEST);
    } else {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(depthFunc);
    }
    glUniform1f(locAlpha_, alphaScale);
    glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(vertices_.size()));
}

void DebugDraw::flush(const glm::mat4& viewProjection, glm::ivec2 viewportPixels, LineDepth depth, float widthPixels,
                      float hiddenAlpha) {
    if (!program_ || vertices_.empty()) {
        vertices_.clear();
        return;
    }
    if (vertices_.size() > capacity_) {
        if (vbo_) glDeleteBuffers(1, &vbo_);
        capacity_ = vertices_.size() * 2;  // grow geometrically: the box count changes every frame
        glCreateBuffers(1, &vbo_);
        glNamedBufferStorage(vbo_, static_cast<GLsizeiptr>(capacity_ * sizeof(Vertex)), nullptr, GL_DYNAMIC_STORAGE_BIT);
        glVertexArrayVertexBuffer(vao_, 0, vbo_, 0, sizeof(Vertex));
    }
    glNamedBufferSubData(vbo_, 0, static_cast<GLsizeiptr>(vertices_.size() * sizeof(Vertex)), vertices_.data());

    const GLboolean cull = glIsEnabled(GL_CULL_FACE);
    glDisable(GL_CULL_FACE);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(program_);
    glUniformMatrix4fv(locViewProj_, 1, GL_FALSE, glm::value_ptr(viewProjection));
    glUniform2f(locViewport_, static_cast<float>(viewportPixels.x), static_cast<float>(viewportPixels.y));
    glUniform1f(locWidth_, widthPixels);
    glBindVertexArray(vao_);
    switch (depth) {
        case LineDepth::Tested: drawPass(detail::kDepthNearerOrEqual, 1.0f); break;
        case LineDepth::Overlay: drawPass(GL_ALWAYS, 1.0f); break;
        case LineDepth::XRay:
            drawPass(detail::kDepthFarther, hiddenAlpha);
            drawPass(detail::kDepthNearerOrEqual, 1.0f);
            break;
    }
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(detail::kDepthNearer);
    glDepthMask(GL_TRUE);
    if (cull) glEnable(GL_CULL_FACE);
    vertices_.clear();
}

}  // namespace dyncull
