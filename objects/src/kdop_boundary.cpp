// Boundary mesh of a k-DOP: the box of its axis slabs clipped by each further bounding
// plane. Paper: kdop-bounding-volumes-for-occlusion.txt, section 3.3 (the boundary of
// the intersection of the k planes; the paper goes through duality and a convex hull,
// clipping gives the same polytope with simpler degeneracy handling) and 5.3 (at most
// 44, 60 and 92 triangles for the 14-, 18- and 26-DOP).
#include <algorithm>
#include <cassert>
#include <cmath>
#include <map>
#include <utility>

#include "dyncull/objects/kdop.hpp"

namespace dyncull {
namespace {

/// A convex polytope as shared vertices and face loops, counter-clockwise seen from outside.
struct Polytope {
    std::vector<glm::dvec3> verts;
    std::vector<std::vector<std::uint32_t>> faces;
};

Polytope boxPolytope(const std::vector<KdopPlane>& planes) {
    // planes[0..5] are +x, -x, +y, -y, +z, -z (kdopPlanes puts the axes first).
    const glm::dvec3 lo(-planes[1].offset, -planes[3].offset, -planes[5].offset);
    const glm::dvec3 hi(planes[0].offset, planes[2].offset, planes[4].offset);
    Polytope p;
    for (int i = 0; i < 8; ++i) p.verts.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
    // The quads of kBoxTriangles, outward.
    p.faces = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    return p;
}

/// Keeps the part of `p` with dot(n, x) <= offset. Vertices within `eps` of the plane
/// are on it; nothing happens unless some vertex is more than `eps` outside.
void clip(Polytope& p, const KdopPlane& plane, double eps) {
    const std::size_t nv = p.verts.size();
    std::vector<double> dist(nv);
    std::vector<int> side(nv);
    bool anyOut = false, anyIn = false;
    for (std::size_t i = 0; i < nv; ++i) {
        dist[i] = glm::dot(plane.normal, p.verts[i]) - plane.offset;
        side[i] = dist[i] > eps ? 1 : (dist[i] < -eps ? -1 : 0);
        anyOut |= side[i] > 0;
        anyIn |= side[i] < 0;
    }
    // No vertex clearly outside: the plane is redundant or touches a face, edge or vertex.
    // None clearly inside cannot happen for planes that bound the polytope's points (the
    // slabs are at least 4 eps thick); keeping the polytope is the conservative answer.
    if (!anyOut || !anyIn) return;

    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> cutOf;  // edge -> new vertex
    std::vector<std::uint32_t> cap;
    auto onCap = [&](std::uint32_t v) {
        if (std::find(cap.begin(), cap.end(), v) == cap.end()) cap.push_back(v);
    };
    auto cut = [&](std::uint32_t a, std::uint32_t b) {
        const auto key = std::minmax(a, b);
        const auto it = cutOf.find(key);
        if (it != cutOf.end()) return it->second;
        // Interpolate from the inside end: the same edge seen from both faces gives one vertex.
        const std::uint32_t in = side[a] < 0 ? a : b, out = in == a ? b : a;
        const double t = dist[in] / (dist[in] - dist[out]);
        const auto id = static_cast<std::uint32_t>(p.verts.size());
        p.verts.push_back(p.verts[in] + t * (p.verts[out] - p.verts[in]));
        cutOf.emplace(key, id);
        return id;
    };
    std::vector<std::vector<std::uint32_t>> faces;
    for (const std::vector<std::uint32_t>& f : p.faces) {
        std::vector<std::uint32_t> kept;
        bool anyInside = false;
        for (std::size_t k = 0; k < f.size(); ++k) {
            const std::uint32_t a = f[k], b = f[(k + 1) % f.size()];
            if (side[a] <= 0) {
                kept.push_back(a);
                anyInside |= side[a] < 0;
                if (side[a] == 0) onCap(a);
            }
            if (side[a] * side[b] < 0) {
                const std::uint32_t x = cut(a, b);
                kept.push_back(x);
                onCap(x);
            }
        }
        // A face with no vertex strictly inside lies in both its plane and the cutting
        // plane, i.e. on their common line: nothing is left of it.
        if (kept.size() >= 3 && anyInside) faces.push_back(std::move(kept));
    }
    if (cap.size() >= 3) {
        // The cap is convex (a section of a convex polytope): sort its vertices by angle
        // about their centroid, counter-clockwise seen from outside (along +normal).
        glm::dvec3 c(0.0);
        for (std::uint32_t v : cap) c += p.verts[v];
        c /= static_cast<double>(cap.size());
        const glm::dvec3 n = plane.normal;
        const glm::dvec3 helper = std::abs(n.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
        const glm::dvec3 u = glm::normalize(glm::cross(helper, n)), w = glm::cross(n, u);  // u x w = n
        std::vector<std::pair<double, std::uint32_t>> byAngle;
        for (std::uint32_t v : cap) {
            const glm::dvec3 d = p.verts[v] - c;
            byAngle.push_back({std::atan2(glm::dot(d, w), glm::dot(d, u)), v});
        }
        std::sort(byAngle.begin(), byAngle.end());
        std::vector<std::uint32_t> loop;
        for (const auto& [angle, v] : byAngle) loop.push_back(v);
        faces.push_back(std::move(loop));
    }
    p.faces = std::move(faces);
}

/// Drops unreferenced vertices and vertices on fewer than three faces (they sit on a
/// straight edge between two faces), renumbering the rest.
void compact(Polytope& p) {
    std::vector<std::uint32_t> uses(p.verts.size(), 0);
    for (const auto& f : p.faces)
        for (std::uint32_t v : f) ++uses[v];
    std::vector<std::uint32_t> remap(p.verts.size(), UINT32_MAX);
    std::vector<glm::dvec3> verts;
    for (std::size_t i = 0; i < p.verts.size(); ++i)
        if (uses[i] >= 3) {
            remap[i] = static_cast<std::uint32_t>(verts.size());
            verts.push_back(p.verts[i]);
        }
    std::vector<std::vector<std::uint32_t>> faces;
    for (const auto& f : p.faces) {
        std::vector<std::uint32_t> g;
        for (std::uint32_t v : f)
            if (remap[v] != UINT32_MAX) g.push_back(remap[v]);
        if (g.size() >= 3) faces.push_back(std::move(g));
    }
    p.verts = std::move(verts);
    p.faces = std::move(faces);
}

}  // namespace

ConvexMesh kdopBoundary(const Kdop& k) {
    ConvexMesh mesh;
    const std::vector<KdopPlane> planes = kdopPlanes(k);
    if (planes.empty()) return mesh;
    const double eps = kdopPlaneEpsilon(k);
    Polytope p = boxPolytope(planes);
    for (std::size_t i = 6; i < planes.size(); ++i) {
        clip(p, planes[i], eps);
        compact(p);
    }
    std::size_t triangles = 0;
    for (const auto& f : p.faces) triangles += f.size() - 2;
    if (p.verts.size() > 48 || triangles > 92) {
        // Cannot happen for a simple polytope of at most 26 faces (V <= 2F - 4); kept as a
        // conservative guard: the box of the axis slabs bounds the same points.
        assert(false && "k-DOP boundary exceeds 48 vertices or 92 triangles");
        p = boxPolytope(planes);
    }
    for (const glm::dvec3& v : p.verts) mesh.vertices.push_back(glm::vec3(v));
    for (const auto& f : p.faces)
        for (std::size_t i = 1; i + 1 < f.size(); ++i) {  // fan: the faces are convex
            mesh.indices.push_back(static_cast<std::uint8_t>(f[0]));
            mesh.indices.push_back(static_cast<std::uint8_t>(f[i]));
            mesh.indices.push_back(static_cast<std::uint8_t>(f[i + 1]));
        }
    return mesh;
}

}  // namespace dyncull
