// Capping the holes of a scanned surface, so that a solid that the scanner could not see
// all around (the Stanford bunny's base) becomes closed and its back faces may be culled
// exactly (see surface_orientation.hpp).
#pragma once

#include <cstddef>

#include "dyncull/objects/mesh.hpp"

namespace dyncull {

struct HoleCapping {
    std::size_t holes = 0;           ///< boundary loops capped
    std::size_t triangles = 0;       ///< triangles added (one per boundary edge of a capped loop)
    std::size_t skippedLoops = 0;    ///< loops left open: longer than the limit, or not simple
};

/// Caps every simple boundary loop of at most `maxLoopEdges` edges with a fan of triangles
/// from one new vertex at the loop's centroid, wound like the surface around the loop (each
/// boundary edge is used once more, in the opposite direction). Topology is on welded
/// vertices, as in analyseSurface. A loop that passes a vertex twice (holes touching at a
/// corner) or belongs to an inconsistently wound or non-manifold rim is left open. The new
/// vertex gets the normalised sum of its cap's face normals when the mesh has normals.
/// Meant for small holes of scanned solids: a fan over a large or strongly curved loop
/// can cross the surface. Precondition: validateMesh(mesh) is empty.
HoleCapping capHoles(Mesh& mesh, std::size_t maxLoopEdges);

}  // namespace dyncull
