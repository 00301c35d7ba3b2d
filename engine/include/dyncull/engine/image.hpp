// CPU-side RGBA8 image (e.g. a read-back frame).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>


namespace dyncull {

/// Owns its pixels. Rows are stored top-down (row 0 is the top of the picture),
/// 4 bytes per pixel (R, G, B, A).
struct Image {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgba;

    glm::u8vec4 at(int x, int y) const {
        const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 4;
        return {rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]};
    }
};

}  // namespace dyncull
