// Total volume and surface area of the query volumes of every object part (local-BSP
// leaf) in world space: the k-DOP paper's Table 5, plus the triangle counts of its
// Table 2, for one volume choice.
// Paper: kdop-bounding-volumes-for-occlusion.txt, sections 5.2-5.3.
#pragma once

#include <array>
#include <cstdint>

#include "dyncull/bsp/scene_objects.hpp"
#include "dyncull/objects/volume_kind.hpp"

namespace dyncull {

struct LeafVolumeTotals {
    std::uint64_t leaves = 0;     ///< non-empty leaves of live objects
    double volume = 0.0;          ///< world units³, summed
    double surfaceArea = 0.0;     ///< world units², summed
    std::uint64_t triangles = 0;  ///< of the leaf volumes (12 per box), summed
    std::uint32_t maxTriangles = 0;
    std::array<std::uint64_t, kVolumeKindCount> leavesByKind{};  ///< which kind each leaf got
};

/// Sums over the non-empty local-BSP leaves of every live object: the volume `choice`
/// gives the leaf (chooseVolume with `autoSaving`) under the object's current matrix.
LeafVolumeTotals leafVolumeTotals(const SceneObjects& objects, VolumeChoice choice, float autoSaving);

}  // namespace dyncull
