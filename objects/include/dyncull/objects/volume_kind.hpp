// Names of the bounding-volume types a node can be queried with, and the user's choice
// among them (one fixed type, or `auto`, which picks per node).
// Paper: Tighter bounding volumes for better occlusion culling (kdop-bounding-volumes-for-
// occlusion.txt), sections 2-3: AABB, OBB and the 14-, 18- and 26-DOPs.
#pragma once

#include <cstdint>
#include <string>

#include "dyncull/objects/error.hpp"

namespace dyncull {

/// A concrete volume type. Aabb and Obb are boxes (8 corners, 12 triangles); the k-DOPs
/// are convex polyhedra of up to 44, 60 and 92 triangles.
enum class VolumeKind : std::uint8_t { Aabb, Obb, Kdop14, Kdop18, Kdop26 };
inline constexpr std::uint32_t kVolumeKindCount = 5;

/// What a caller asks for: one kind for every node, or Auto (a per-node rule, see the
/// scheduler's SchedulerParams::autoVolumeSaving).
enum class VolumeChoice : std::uint8_t { Aabb, Obb, Kdop14, Kdop18, Kdop26, Auto };

const char* toString(VolumeKind k);
const char* toString(VolumeChoice c);
/// "aabb", "obb", "kdop14", "kdop18", "kdop26" or "auto"; the error lists the names.
Expected<VolumeChoice> parseVolumeChoice(const std::string& s);
/// The kind a fixed choice names (Auto has none: asserts).
VolumeKind kindOf(VolumeChoice c);

}  // namespace dyncull
