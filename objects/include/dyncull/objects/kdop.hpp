// Discrete orientation polytopes (k-DOPs) with 14, 18 and 26 fixed directions: k/2
// intervals of the points along fixed directions, and the boundary mesh of the
// intersection of the k half-spaces (what an occlusion query draws).
// Paper: kdop-bounding-volumes-for-occlusion.txt, section 3 (directions of 3.3; boundary
// of the intersected planes, at most 44/60/92 triangles per section 5.3).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/convex_mesh.hpp"

namespace dyncull {

/// The 13 directions of section 3.3, unnormalised (components -1, 0, 1): 0-2 the
/// coordinate axes, 3-6 the cube corners, 7-12 the cube edges.
inline constexpr std::array<std::array<int, 3>, 13> kKdopDirections = {{
    {1, 0, 0}, {0, 1, 0}, {0, 0, 1},                          // axes (the AABB)
    {1, 1, 1}, {1, -1, 1}, {1, 1, -1}, {-1, 1, 1},            // corners
    {1, 1, 0}, {1, 0, 1}, {0, 1, 1}, {1, -1, 0}, {1, 0, -1}, {0, 1, -1},  // edges
}};

/// 14-DOP: axes + corners; 18-DOP: axes + edges; 26-DOP: all 13 directions.
enum class KdopType : std::uint8_t { K14, K18, K26 };
/// k (number of planes) of the type.
int kdopK(KdopType t);
/// Whether direction index i (into kKdopDirections) belongs to the type.
bool kdopUses(KdopType t, int direction);

/// A k-DOP: for each direction i of its type, the interval [lo[i], hi[i]] of
/// dot(kKdopDirections[i], p) over the bounded points (unnormalised directions, so the
/// axis intervals are exactly the AABB). Same coordinate space as the points. Entries of
/// directions the type does not use are ignored.
struct Kdop {
    KdopType type = KdopType::K26;
    bool empty = true;  ///< bounds no point
    std::array<double, 13> lo{}, hi{};

    /// True if every used slab, grown by `eps` (units of length), contains `p`.
    bool contains(const glm::dvec3& p, double eps) const;
    /// The axis slabs as a box.
    Aabb aabb() const;
    /// Largest |coordinate| of the axis slabs: the length scale of this k-DOP's epsilons
    /// (float positions carry errors relative to their magnitude, not to the extent).
    double scale() const;
};

/// The intervals of `points` (any space). Computed in double, exact for float input up
/// to one double rounding. An empty span gives an empty k-DOP.
Kdop computeKdop(KdopType type, std::span<const glm::vec3> points);
/// A 26-DOP's intervals restricted to a sub-type (K14 or K18 take a subset of its
/// directions, so no second pass over the points is needed).
Kdop restrictKdop(const Kdop& k26, KdopType type);

/// A bounding plane: inside is dot(normal, x) <= offset; unit normal.
struct KdopPlane {
    glm::dvec3 normal;
    double offset;
};
/// Distances below this are "on a plane" for the boundary construction (units of length):
/// about 16 float ulps of the k-DOP's coordinates, far above double rounding.
double kdopPlaneEpsilon(const Kdop& k);
/// The k planes (axes first, then the type's other directions; + then - side). Slabs
/// thinner than 4 plane epsilons (planar or collinear point sets, a single point) are
/// widened symmetrically to that thickness, so the boundary is always a solid polytope.
std::vector<KdopPlane> kdopPlanes(const Kdop& k);

/// The boundary of the intersection of kdopPlanes(k): a closed convex mesh with outward
/// counter-clockwise triangles, at most 48 vertices and 92 triangles (26-DOP). Built by
/// clipping the box of the axis slabs with each further plane (Sutherland-Hodgman per
/// face, the cut's cap polygon from the new vertices). Robust on purpose: vertices within
/// kdopPlaneEpsilon of a plane count as on it, so coincident and redundant planes (a cut
/// that only touches a vertex or an edge) change nothing and a cut shallower than the
/// epsilon is skipped — which only ever leaves the polytope larger (conservative).
/// Vertices left on only two faces (collinear on an edge) are removed. An empty k-DOP
/// gives an empty mesh.
ConvexMesh kdopBoundary(const Kdop& k);

/// Brute-force reference for kdopBoundary (the tests' oracle): every intersection point
/// of three of kdopPlanes(k) that lies inside all of them (within `tol`), with points
/// closer than `tol` merged. O(k^4).
std::vector<glm::dvec3> kdopVerticesBruteForce(const Kdop& k, double tol);

}  // namespace dyncull
