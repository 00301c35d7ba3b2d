// Draws boxes into the depth test only (colour and depth writes off): the proxy geometry
// of hardware occlusion queries. Query begin/end is the caller's business.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"

namespace dyncull {

/// Owns a unit-cube VAO/IBO and a position-only program. Needs a current GL 4.5 context
/// for its whole life (construct and destroy with the context current).
class BoxDrawer {
public:
    BoxDrawer();
    ~BoxDrawer();
    BoxDrawer(const BoxDrawer&) = delete;
    BoxDrawer& operator=(const BoxDrawer&) = delete;

    /// True if the shader compiled (fails only on a broken driver); log() says why not.
    bool valid() const { return program_ != 0; }
    const char* log() const { return log_; }

    /// Rasterises `box` (coordinates in the space `model` maps to world; identity for a
    /// world box) against the bound framebuffer's depth buffer with no writes. Faces are
    /// not culled, so a box seen from any side yields samples. Restores colour/depth masks.
    void drawDepthTestOnly(const Aabb& box, const glm::mat4& model, const glm::mat4& viewProjection);

private:
    std::uint32_t program_ = 0, vao_ = 0, vbo_ = 0, ibo_ = 0;
    int locMvp_ = -1;
    char log_[512] = {};
};

}  // namespace dyncull
