// FNV-1a 64-bit: the checksum of dyncull's binary files (scene cache, subdivision files).
// Detects corruption and truncation, not tampering.
#pragma once

#include <cstddef>
#include <cstdint>

namespace dyncull {

inline constexpr std::uint64_t kFnv1a64Seed = 0xcbf29ce484222325ull;

/// FNV-1a 64-bit over `size` bytes, continuing from `hash` (chunks may be fed in turn).
inline std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t hash = kFnv1a64Seed) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
        hash ^= p[i];
        hash *= 0x100000001b3ull;
    }
    return hash;
}

}  // namespace dyncull
