// Ear-clipping triangulation of one polygon face (OBJ and PLY faces with more than three
// corners, and polygons streamed from files larger than memory).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace dyncull {

enum class Triangulation : std::uint8_t {
    Ok,          ///< ear-clipped (for a convex polygon: the fan from corner 0)
    ZeroArea,    ///< all corners on one line or point: no triangles, it covers no surface
    Tangled,     ///< crosses itself: ears clipped while any exist, the rest fan-triangulated
                 ///< (a self-intersecting polygon without reflex corners, e.g. a pentagram,
                 ///< is not detected and comes out as the fan, reported Ok)
    TooComplex,  ///< the ear search would exceed its work budget: nothing emitted
};

/// Reusable buffers, so a loader triangulating millions of quads does not allocate per face.
struct TriangulationScratch {
    std::vector<glm::dvec2> points;
    std::vector<std::uint32_t> prev, next, reflex;
};

/// Triangulates the polygon whose corners are `corners`, in order (their winding gives
/// the front face, which the triangles keep). Appends 3 indices into `corners` per
/// triangle to `out`; duplicate and collinear corners are kept in the output wherever
/// they are needed to avoid T-junctions, but never become zero-area ears.
Triangulation triangulatePolygon(std::span<const glm::vec3> corners, std::vector<std::uint32_t>& out,
                                 TriangulationScratch& scratch);

}  // namespace dyncull
