// Load-time surface analysis: may a mesh's back faces be culled? (issue 21, item 2)
//
// Back-face culling is only invisible when no back face can ever reach the screen: every
// shell closed (watertight), consistently wound and facing outwards. Loaders cannot know
// that, so this looks at the topology once per mesh, fixes shells that are wound inwards
// as a whole, and says which face mode to draw with. Plain C++, no OpenGL.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "dyncull/objects/mesh.hpp"

namespace dyncull {

enum class FaceMode : std::uint8_t {
    CullBack,  ///< every shell closed, consistently wound and facing outwards: back faces are never seen
    TwoSided,  ///< open, non-manifold, inconsistently wound, zero-volume, ambiguous or empty: draw both sides
};

/// What analyseSurface / orientSurface found. Topology is on *welded* vertices (equal
/// positions are one vertex), so loaders' duplicates at normal/UV seams do not open a mesh.
struct SurfaceReport {
    std::size_t triangles = 0;            ///< all triangles of the mesh
    std::size_t degenerateTriangles = 0;  ///< repeat a welded vertex; ignored for topology
    std::size_t weldedVertices = 0;       ///< distinct positions (-0.0 == +0.0)
    std::size_t edges = 0;                ///< undirected edges of non-degenerate triangles
    std::size_t boundaryEdges = 0;        ///< used by one triangle
    std::size_t nonManifoldEdges = 0;     ///< used by more than two triangles
    std::size_t misorientedEdges = 0;     ///< two triangles traverse the edge in the same direction
    std::size_t holes = 0;                ///< connected groups of boundary edges (boundary loops)
    std::uint32_t shells = 0;             ///< triangles connected through shared edges
    std::uint32_t closedShells = 0;       ///< no boundary or non-manifold edge
    std::uint32_t flippedShells = 0;      ///< closed, consistent, inwards and not a cavity: flipped
    std::uint32_t cavityShells = 0;       ///< closed, consistent, inwards inside an outward shell: kept
    std::uint32_t zeroVolumeShells = 0;   ///< closed and consistent but flat (see surface_orientation.cpp)
    std::uint32_t ambiguousShells = 0;    ///< inwards, but nesting could not be decided: left alone
    /// Sum of the shells' signed volumes after flipping, object units^3 (each shell's
    /// relative to its own box centre, which only matters for open shells).
    double signedVolume = 0.0;
    double analyseMs = 0.0;  ///< wall time of the analysis (and flipping)
    FaceMode mode = FaceMode::TwoSided;

    bool closed() const { return boundaryEdges == 0 && nonManifoldEdges == 0; }
    bool consistent() const { return misorientedEdges == 0; }
    /// One line for `dyncull inspect`, e.g. "closed, consistent, outward: cull back faces" or
    /// "open (223 boundary edges in 5 holes): two-sided".
    std::string summary() const;
};

/// Analyses `mesh` and flips (swaps the last two indices of) the triangles of every closed,
/// consistently wound shell that faces inwards (negative volume) and is not a cavity of
/// another shell, i.e. does not lie inside a closed shell that faces outwards. Returns what
/// it found (after flipping) and the face mode to draw with. Positions and normals are not
/// changed: normals derived from the old winding need computeNormals again. Precondition:
/// validateMesh(mesh) is empty. O(n) expected time; nesting tests have a budget
/// proportional to the triangle count, and a shell they cannot decide counts as ambiguous.
SurfaceReport orientSurface(Mesh& mesh);

/// The same analysis without changing `mesh`: flippedShells counts the shells orientSurface
/// would flip, and signedVolume and mode are as they would be after flipping.
SurfaceReport analyseSurface(const Mesh& mesh);

}  // namespace dyncull
