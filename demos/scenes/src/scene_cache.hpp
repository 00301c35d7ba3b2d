// On-disk cache of a prepared generated scene (meshes + local BSPs + placements), so the
// power plant reloads in seconds instead of being regenerated. The file is untrusted input:
// every read is bounds-checked and the content validated before anything is returned.
//
// Layout (little-endian): a 40-byte header
//   magic "DYNCSCN\0" | u32 format version | u32 header size (40) | u64 generator
//   parameters hash | u64 payload size | u64 FNV-1a 64 of the payload
// then the payload: u32 model count, per model (name, positions, normals, indices, nodes,
// stats, u8 face mode), u32 object count, per object (model, translation, rotation wxyz, scale, static).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "dyncull/objects/checksum.hpp"
#include "dyncull/objects/error.hpp"
#include "prepared_scene.hpp"

namespace dyncull {

inline constexpr std::uint32_t kSceneCacheVersion = 3;  // 2: face mode per model, leaves in cache order; 3: leaves in meshlet order
inline constexpr std::size_t kSceneCacheHeaderSize = 40;

/// Writes `scene` to `path` (via a temporary file renamed into place, so readers never see
/// a half-written cache). Errors name the path.
Status writeSceneCache(const std::filesystem::path& path, const PreparedScene& scene, std::uint64_t paramsHash);

/// Reads and validates a cache written for `paramsHash`. The one-line error says why the
/// cache is unusable: missing, bad magic, other format version, stale parameters,
/// truncated, checksum mismatch, or malformed payload (counts, indices, tree, transforms).
Expected<PreparedScene> readSceneCache(const std::filesystem::path& path, std::uint64_t paramsHash);

}  // namespace dyncull
