// Exact image difference and its largest 4-connected wrong region (see image_compare.hpp).
#include "dyncull/measure/image_compare.hpp"

#include <algorithm>
#include <string>

namespace dyncull {

std::uint64_t largestConnectedRegion(const std::vector<std::uint8_t>& mask, int width, int height) {
    const std::size_t w = static_cast<std::size_t>(std::max(width, 0));
    const std::size_t n = w * static_cast<std::size_t>(std::max(height, 0));
    if (mask.size() < n) return 0;
    std::vector<std::uint8_t> seen(n, 0);
    std::vector<std::size_t> stack;
    std::uint64_t best = 0;
    for (std::size_t start = 0; start < n; ++start) {
        if (!mask[start] || seen[start]) continue;
        std::uint64_t size = 0;
        seen[start] = 1;
        stack.push_back(start);
        while (!stack.empty()) {
            const std::size_t p = stack.back();
            stack.pop_back();
            ++size;
            const std::size_t x = p % w;
            auto visit = [&](std::size_t q) {
                if (mask[q] && !seen[q]) {
                    seen[q] = 1;
                    stack.push_back(q);
                }
            };
            if (x > 0) visit(p - 1);
            if (x + 1 < w) visit(p + 1);
            if (p >= w) visit(p - w);
            if (p + w < n) visit(p + w);
        }
        best = std::max(best, size);
    }
    return best;
}

Expected<ImageDiff> compareImages(const Image& a, const Image& b, std::vector<std::uint8_t>* mask) {
    if (a.width != b.width || a.height != b.height)
        return Error{"compareImages: sizes differ (" + std::to_string(a.width) + "x" + std::to_string(a.height) +
                     " vs " + std::to_string(b.width) + "x" + std::to_string(b.height) + ")"};
    if (a.width < 0 || a.height < 0) return Error{"compareImages: negative size"};
    const std::size_t n = static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height);
    if (a.rgba.size() != n * 4 || b.rgba.size() != n * 4)
        return Error{"compareImages: pixel buffer is not width x height x 4 bytes"};
    std::vector<std::uint8_t> local;
    std::vector<std::uint8_t>& m = mask ? *mask : local;
    m.assign(n, 0);
    ImageDiff d;
    d.totalPixels = n;
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint8_t* pa = a.rgba.data() + 4 * i;
        const std::uint8_t* pb = b.rgba.data() + 4 * i;
        if (pa[0] != pb[0] || pa[1] != pb[1] || pa[2] != pb[2] || pa[3] != pb[3]) {
            m[i] = 1;
            ++d.differingPixels;
        }
    }
    d.percentDiffering = n ? 100.0 * static_cast<double>(d.differingPixels) / static_cast<double>(n) : 0.0;
    d.largestRegion = d.differingPixels ? largestConnectedRegion(m, a.width, a.height) : 0;
    return d;
}

}  // namespace dyncull
