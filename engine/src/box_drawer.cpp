// Occlusion-query proxy boxes: a unit cube scaled onto the box, depth-tested, no writes.
#include "dyncull/engine/box_drawer.hpp"

#include <cstring>
#include <string>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "shader_program.hpp"

namespace dyncull {

BoxDrawer::BoxDrawer() {
    std::string log;
    program_ = detail::buildProgram(detail::kBoxVertexShader, detail::kBoxFragmentShader, log);
    if (!program_) {
        std::strncpy(log_, log.c_str(), sizeof log_ - 1);
        return;
    }
    locMvp_ = glGetUniformLocation(program_, "uMvp");

    // Corner i has x = bit 0, y = bit 1, z = bit 2 of i.
    float corners[8 * 3];
    for (int i = 0; i < 8; ++i) {
        corners[i * 3 + 0] = static_cast<float>(i & 1);
        corners[i * 3 + 1] = static_cast<float>((i >> 1) & 1);
        corners[i * 3 + 2] = static_cast<float>((i >> 2) & 1);
    }
    // Two triangles per face, counter-clockwise seen from outside (winding is irrelevant
    // since culling is off, but keeps the cube usable elsewhere).
    const std::uint8_t indices[36] = {0, 2, 1, 1, 2, 3,  4, 5, 6, 5, 7, 6,  0, 1, 4, 1, 5, 4,
                                      2, 6, 3, 3, 6, 7,  0, 4, 2, 2, 4, 6,  1, 3, 5, 3, 7, 5};
    glCreateBuffers(1, &vbo_);
    glNamedBufferStorage(vbo_, sizeof corners, corners, 0);
    glCreateBuffers(1, &ibo_);
    glNamedBufferStorage(ibo_, sizeof indices, indices, 0);
    glCreateVertexArrays(1, &vao_);
    glVertexArrayVertexBuffer(vao_, 0, vbo_, 0, 3 * sizeof(float));
    glVertexArrayElementBuffer(vao_, ibo_);
    glEnableVertexArrayAttrib(vao_, 0);
    glVertexArrayAttribFormat(vao_, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao_, 0, 0);
}

BoxDrawer::~BoxDrawer() {
    if (vao_) glDeleteVertexArrays(1, &vao_);
    if (vbo_) glDeleteBuffers(1, &vbo_);
    if (ibo_) glDeleteBuffers(1, &ibo_);
    if (program_) glDeleteProgram(program_);
}

void BoxDrawer::drawDepthTestOnly(const Aabb& box, const glm::mat4& model, const glm::mat4& viewProjection) {
    if (!program_ || box.empty()) return;
    const glm::mat4 unitToBox = glm::scale(glm::translate(glm::mat4(1.0f), box.min), box.extent());
    const glm::mat4 mvp = viewProjection * model * unitToBox;

    GLboolean colourMask[4], depthMask = GL_TRUE;
    glGetBooleanv(GL_COLOR_WRITEMASK, colourMask);
    glGetBooleanv(GL_DEPTH_WRITEMASK, &depthMask);
    const GLboolean cull = glIsEnabled(GL_CULL_FACE);

    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glDepthMask(GL_FALSE);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glUseProgram(program_);
    glUniformMatrix4fv(locMvp_, 1, GL_FALSE, glm::value_ptr(mvp));
    glBindVertexArray(vao_);
    glDrawElements(GL_TRIANGLES, 36, GL_UNSIGNED_BYTE, nullptr);

    glColorMask(colourMask[0], colourMask[1], colourMask[2], colourMask[3]);
    glDepthMask(depthMask);
    if (cull) glEnable(GL_CULL_FACE);
}

}  // namespace dyncull
