// Welding by exact position: open addressing over representative vertex indices.
#include "vertex_weld.hpp"

#include <bit>

namespace dyncull::detail {
namespace {

constexpr std::uint32_t kNone = 0xffffffffu;

std::uint32_t floatBits(float f) {
    return std::bit_cast<std::uint32_t>(f == 0.0f ? 0.0f : f);  // -0.0 and +0.0 are one position
}

std::uint32_t mix(std::uint32_t h) {  // murmur3 finaliser
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    return h ^ (h >> 16);
}

}  // namespace

std::vector<std::uint32_t> weldVertices(const std::vector<glm::vec3>& pos, std::size_t& weldedCount) {
    std::size_t cap = 16;
    while (cap < 2 * pos.size()) cap <<= 1;
    std::vector<std::uint32_t> slots(cap, kNone);
    std::vector<std::uint32_t> id(pos.size());
    std::uint32_t next = 0;
    for (std::uint32_t v = 0; v < pos.size(); ++v) {
        const std::uint32_t x = floatBits(pos[v].x), y = floatBits(pos[v].y), z = floatBits(pos[v].z);
        std::size_t s = mix(x ^ mix(y ^ mix(z))) & (cap - 1);
        for (;; s = (s + 1) & (cap - 1)) {
            const std::uint32_t r = slots[s];
            if (r == kNone) {
                slots[s] = v;
                id[v] = next++;
                break;
            }
            if (floatBits(pos[r].x) == x && floatBits(pos[r].y) == y && floatBits(pos[r].z) == z) {
                id[v] = id[r];
                break;
            }
        }
    }
    weldedCount = next;
    return id;
}

}  // namespace dyncull::detail
