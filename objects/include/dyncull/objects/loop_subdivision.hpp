// Loop subdivision of a triangle mesh (C. Loop, "Smooth Subdivision Surfaces Based on
// Triangles", 1987): each level splits every triangle into four and smooths positions.
// Used to refine the low-resolution public-domain bunny (3,674 triangles) to 58,784.
#pragma once

#include "dyncull/objects/mesh.hpp"

namespace dyncull {

/// Returns `levels` levels of Loop subdivision of `mesh` (object space; normals
/// recomputed). Boundary edges use the standard boundary rules (cubic B-spline);
/// non-manifold edges (more than two triangles) and the vertices on them are treated
/// as creases. Degenerate triangles are subdivided like any other (they stay degenerate).
Mesh loopSubdivide(const Mesh& mesh, int levels);

}  // namespace dyncull
