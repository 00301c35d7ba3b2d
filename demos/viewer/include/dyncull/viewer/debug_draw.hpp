// Coloured wireframe lines and boxes drawn over a finished frame (the node-box view):
// segments are batched on the CPU and drawn in one call per flush, as screen-space quads
// of a chosen pixel width (core-profile GL only guarantees 1-pixel lines).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"

namespace dyncull {

/// How lines meet the scene's depth buffer.
enum class LineDepth : std::uint8_t {
    Tested,   ///< hidden parts are not drawn
    Overlay,  ///< drawn on top of everything
    XRay,     ///< visible parts full strength, hidden parts faded (see `hiddenAlpha`)
};

/// Owns a program, a VAO and a growable vertex buffer. Needs a current GL 4.5 context for
/// its whole life (construct and destroy with the context current).
class DebugDraw {
public:
    DebugDraw();
    ~DebugDraw();
    DebugDraw(const DebugDraw&) = delete;
    DebugDraw& operator=(const DebugDraw&) = delete;

    /// True if the shaders compiled (fails only on a broken driver); log() says why not.
    bool valid() const { return program_ != 0; }
    const char* log() const { return log_; }

    /// Queues a segment between world-space points, colour RGBA in 0..1.
    void addLine(const glm::vec3& a, const glm::vec3& b, const glm::vec4& colour);
    /// Queues the 12 edges of `box` (in the space `model` maps to world; identity for a world box).
    void addBox(const Aabb& box, const glm::vec4& colour, const glm::mat4& model = glm::mat4(1.0f));
    std::size_t queuedLines() const { return vertices_.size() / 2; }
    void clear() { vertices_.clear(); }

    /// Draws and clears the queue into the currently bound framebuffer with its current
    /// viewport (`viewportPixels` = its size, for the line width). Lines are `widthPixels`
    /// wide, alpha-blended. `viewProjection` is world to clip in Camera's reversed-Z
    /// convention. Leaves the renderer's defaults behind: depth test on with GL_GREATER,
    /// depth writes on, blending off (program and VAO bindings are left changed).
    void flush(const glm::mat4& viewProjection, glm::ivec2 viewportPixels, LineDepth depth = LineDepth::XRay,
               float widthPixels = 2.0f, float hiddenAlpha = 0.3f);

private:
    struct Vertex {
        glm::vec3 position;
        glm::vec4 colour;
    };
    void drawPass(std::uint32_t depthFunc, float alphaScale);

    std::vector<Vertex> vertices_;
    std::uint32_t program_ = 0, vao_ = 0, vbo_ = 0;
    std::size_t capacity_ = 0;  // vertices the VBO holds
    int locViewProj_ = -1, locViewport_ = -1, locWidth_ = -1, locAlpha_ = -1;
    char log_[512] = {};
};

}  // namespace dyncull
