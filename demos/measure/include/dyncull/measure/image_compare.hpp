// Exact comparison of two rendered frames: which pixels differ (any RGBA byte) and the
// largest 4-connected region of differing pixels, so "0.02% wrong" can be told apart
// from "one missing bunny" when measuring approximate culling settings.
#pragma once

#include <cstdint>
#include <vector>

#include "dyncull/engine/image.hpp"
#include "dyncull/objects/error.hpp"

namespace dyncull {

struct ImageDiff {
    std::uint64_t totalPixels = 0;
    std::uint64_t differingPixels = 0;
    double percentDiffering = 0.0;   ///< 100 * differing / total (0 for empty images)
    std::uint64_t largestRegion = 0;  ///< pixels in the largest 4-connected differing region
};

/// Compares `a` and `b` pixel by pixel (exact RGBA). Error if the sizes differ or a
/// buffer does not hold width x height x 4 bytes. When `mask` is given it receives one
/// byte per pixel (top-down), 1 where the images differ.
Expected<ImageDiff> compareImages(const Image& a, const Image& b, std::vector<std::uint8_t>* mask = nullptr);

/// Size of the largest 4-connected region of non-zero bytes in `mask` (width x height,
/// row-major). Iterative flood fill: no recursion depth limit on large regions.
std::uint64_t largestConnectedRegion(const std::vector<std::uint8_t>& mask, int width, int height);

}  // namespace dyncull
