// Compiles/links GLSL programs and reports the driver's log instead of failing silently.
#include "shader_program.hpp"

#include <epoxy/gl.h>

namespace dyncull::detail {

namespace {

GLuint compile(GLenum stage, const char* source, std::string& log) {
    const GLuint s = glCreateShader(stage);
    glShaderSource(s, 1, &source, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (ok) return s;
    char buf[1024] = {};
    glGetShaderInfoLog(s, sizeof buf, nullptr, buf);
    log = std::string(stage == GL_VERTEX_SHADER ? "vertex" : "fragment") + " shader: " + buf;
    glDeleteShader(s);
    return 0;
}

}  // namespace

std::uint32_t buildProgram(const char* vertexSource, const char* fragmentSource, std::string& log) {
    const GLuint vs = compile(GL_VERTEX_SHADER, vertexSource, log);
    if (!vs) return 0;
    const GLuint fs = compile(GL_FRAGMENT_SHADER, fragmentSource, log);
    if (!fs) {
        glDeleteShader(vs);
        return 0;
    }
    const GLuint p = glCreateProgram();
    glAttachShader(p, vs);
    glAttachShader(p, fs);
    glLinkProgram(p);
    glDeleteShader(vs);  // flagged; freed with the program
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (ok) return p;
    char buf[1024] = {};
    glGetProgramInfoLog(p, sizeof buf, nullptr, buf);
    log = std::string("link: ") + buf;
    glDeleteProgram(p);
    return 0;
}

}  // namespace dyncull::detail
