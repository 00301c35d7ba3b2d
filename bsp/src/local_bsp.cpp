// Local axis-aligned BSP of one mesh with triangle splitting.
// Paper: Two-level BSP for dynamic occlusion culling, section 3.1 (object partitioning:
// recursive axis-aligned planes until a part has fewer triangles than a threshold,
// triangles crossing a plane are split). Optional split cost: Scene subdivision for
// occlusion culling, section 3.2 (p-HBVO surface-area heuristic).
#include "dyncull/bsp/local_bsp.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>
#include <cmath>
#include <span>
#include <string>

#include "split_plane.hpp"
#include "triangle_clipper.hpp"

namespace dyncull {

namespace {

using detail::Triangle;

// Depth-first builder. Triangles of the node being built sit at the top of `pool_`
// ([begin, pool_.size())); a split rewrites them in place as [above | below] so the
// below child is again at the top, and each call leaves pool_ truncated to `begin`.
// Node ids are preorder, so subtrees are contiguous in `nodes` and leaves emit their
// triangles into the index buffer in the same order.
class Builder {
public:
    Builder(const LocalBspParams& params, LocalBsp& out)
        : params_(params), out_(out), splitter_(out.mesh.positions, out.mesh.normals, out.splitVertices) {}

    void run(const std::vector<std::uint32_t>& indices) {
        const std::size_t n = indices.size() / 3;
        pool_.reserve(n + n / 4 + 16);
        for (std::size_t t = 0; t < n; ++t) pool_.push_back({indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]});
        out_.mesh.indices.clear();
        out_.mesh.indices.reserve(indices.size() + indices.size() / 4);
        build(0, 0);
    }

private:
    std::uint32_t build(std::size_t begin, std::uint32_t depth) {
        const auto self = static_cast<std::uint32_t>(out_.nodes.size());
        out_.nodes.emplace_back();
        out_.nodes[self].depth = static_cast<std::uint8_t>(depth);
        out_.nodes[self].firstIndex = static_cast<std::uint32_t>(out_.mesh.indices.size());

        const std::span<const Triangle> tris(pool_.data() + begin, pool_.size() - begin);
        detail::SplitPlane plane;
        if (tris.size() > params_.maxLeafTriangles && depth < params_.maxDepth && choosePlane(tris, plane)) {
            splitInto(begin, plane);  // pool_: [begin, +nAbove) above, then below
            const std::size_t aboveEnd = begin + nAboveScratch_;
            LocalBspNode& node = out_.nodes[self];
            node.axis = static_cast<std::uint8_t>(plane.axis);
            node.split = plane.position;
            const std::uint32_t below = build(aboveEnd, depth + 1);
            const std::uint32_t above = build(begin, depth + 1);
            LocalBspNode& n2 = out_.nodes[self];  // build() may have reallocated `nodes`
            n2.children[0] = below;
            n2.children[1] = above;
            n2.box = merge(out_.nodes[below].box, out_.nodes[above].box);
        } else {
            LocalBspNode& leaf = out_.nodes[self];
            for (const Triangle& t : tris) {
                for (const std::uint32_t v : t) {
                    out_.mesh.indices.push_back(v);
                    leaf.box.extend(out_.mesh.positions[v]);
                }
            }
            if (tris.size() > params_.maxLeafTriangles && depth < params_.maxDepth) ++out_.stats.stalledLeaves;
            ++out_.stats.leaves;
            out_.stats.depth = std::max(out_.stats.depth, depth);
            pool_.resize(begin);
        }
        LocalBspNode& node = out_.nodes[self];
        node.indexCount = static_cast<std::uint32_t>(out_.mesh.indices.size()) - node.firstIndex;
        node.subtreeSize = static_cast<std::uint32_t>(out_.nodes.size()) - self;
        return self;
    }

    // Picks a plane that gives both children fewer triangles than the node: the method's
    // plane first, then the spatial median of the other axes by decreasing extent.
    // Returns false (make a leaf) when none does; this is what stops degenerate input.
    bool choosePlane(std::span<const Triangle> tris, detail::SplitPlane& out) {
        const std::vector<glm::vec3>& pos = out_.mesh.positions;
        Aabb box;
        for (const Triangle& t : tris)
            for (const std::uint32_t v : t) box.extend(pos[v]);
        eps_ = detail::planeEpsilon(box);
        const glm::vec3 ext = box.extent();

        detail::SplitPlane first{box.longestAxis(), 0.0f};
        first.position = box.center()[first.axis];
        if (params_.method == SplitMethod::Sah && !planner_.sah(tris, pos, first)) return false;

        std::array<int, 3> axes{first.axis, (first.axis + 1) % 3, (first.axis + 2) % 3};
        if (ext[axes[2]] > ext[axes[1]]) std::swap(axes[1], axes[2]);
        for (int i = 0; i < 3; ++i) {
            const int axis = axes[i];
            if (!(ext[axis] > 2.0f * eps_)) continue;  // flat along this axis: nothing to separate
            const float start = i == 0 ? first.position : box.center()[axis];
            planner_.loadAxis(tris, pos, axis);
            detail::SplitCount counts;
            const float p = planner_.nudge(start, params_.nudgeFraction * ext[axis], box.min[axis],
                                           box.max[axis], eps_, counts);
            if (counts.belowTriangles < tris.size() && counts.aboveTriangles < tris.size()) {
                out = {axis, p};
                expected_ = counts;
                return true;
            }
        }
        return false;
    }

    void splitInto(std::size_t begin, const detail::SplitPlane& plane) {
        const std::vector<glm::vec3>& pos = out_.mesh.positions;
        below_.clear();
        above_.clear();
        splitter_.reset(plane.axis, plane.position);
        for (std::size_t i = begin; i < pool_.size(); ++i) {
            const Triangle t = pool_[i];
            std::array<int, 3> s;
            for (int k = 0; k < 3; ++k) s[k] = detail::planeSide(pos[t[k]][plane.axis], plane.position, eps_);
            const int lo = std::min({s[0], s[1], s[2]}), hi = std::max({s[0], s[1], s[2]});
            if (hi <= 0) {
                below_.push_back(t);  // includes triangles lying in the plane (deterministic)
            } else if (lo >= 0) {
                above_.push_back(t);
            } else {
                detail::clipTriangle(t, s, splitter_, below_, above_);  // may grow `pos`
            }
        }
        // SplitPlanner::count uses the same planeSide test on the same floats.
        assert(below_.size() == expected_.belowTriangles && above_.size() == expected_.aboveTriangles);
        pool_.resize(begin);
        pool_.insert(pool_.end(), above_.begin(), above_.end());
        pool_.insert(pool_.end(), below_.begin(), below_.end());
        nAboveScratch_ = above_.size();
    }

    const LocalBspParams& params_;
    LocalBsp& out_;
    detail::EdgeSplitter splitter_;
    detail::SplitPlanner planner_;
    std::vector<Triangle> pool_, below_, above_;  // reused by every node
    detail::SplitCount expected_;
    std::size_t nAboveScratch_ = 0;
    float eps_ = 0.0f;
};

std::string checkParams(const LocalBspParams& p) {
    if (p.maxLeafTriangles == 0) return "LocalBspParams.maxLeafTriangles must be > 0";
    if (p.maxDepth > kLocalBspMaxDepth)
        return "LocalBspParams.maxDepth " + std::to_string(p.maxDepth) + " exceeds the limit of " +
               std::to_string(kLocalBspMaxDepth);
    if (!(p.nudgeFraction >= 0.0f && p.nudgeFraction <= 0.5f))
        return "LocalBspParams.nudgeFraction " + std::to_string(p.nudgeFraction) + " is outside [0, 0.5]";
    if (p.method != SplitMethod::SpatialMedian && p.method != SplitMethod::Sah)
        return "LocalBspParams.method has an unknown value";
    return {};
}

}  // namespace

Expected<LocalBsp> buildLocalBsp(const Mesh& mesh, const LocalBspParams& params) {
    const auto start = std::chrono::steady_clock::now();
    if (std::string msg = validateMesh(mesh); !msg.empty())
        return Error{"buildLocalBsp: mesh '" + mesh.name + "': " + msg};
    if (std::string msg = checkParams(params); !msg.empty()) return Error{"buildLocalBsp: " + msg};

    LocalBsp bsp;
    bsp.mesh.name = mesh.name;
    bsp.mesh.positions = mesh.positions;
    bsp.mesh.normals = mesh.normals;
    bsp.mesh.indices = mesh.indices;
    bsp.sourceVertexCount = static_cast<std::uint32_t>(mesh.positions.size());
    // Orientation is decided on the whole input surface: the split mesh has T-junctions
    // where a plane cut one triangle but not its neighbour, which would read as holes.
    if (params.faces != FacePolicy::TwoSided) {
        const SurfaceReport surface = orientSurface(bsp.mesh);
        bsp.faces = params.faces == FacePolicy::CullBack ? FaceMode::CullBack : surface.mode;
    }
    if (bsp.mesh.normals.empty()) computeNormals(bsp.mesh);  // from the oriented triangles
    bsp.stats.trianglesBefore = mesh.triangleCount();
    {
        const std::vector<std::uint32_t> input = std::move(bsp.mesh.indices);
        Builder builder(params, bsp);
        builder.run(input);
    }
    if (params.optimizeOrder) optimizeLeafOrder(bsp, params.clusterOrder);
    bsp.stats.trianglesAfter = bsp.mesh.triangleCount();
    bsp.volumes = buildNodeVolumes(bsp.mesh, bsp.nodes);
    bsp.clusters = clustersOf(bsp.mesh, bsp.nodes);
    bsp.stats.buildMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return bsp;
}

Expected<LocalBsp> buildBoundsModel(const Aabb& bounds, std::uint32_t triangles) {
    if (bounds.empty() || !bounds.finite()) return Error{"buildBoundsModel: the bounds are empty or not finite"};
    if (triangles == 0) return Error{"buildBoundsModel: a draw costs at least one triangle"};
    Mesh box;
    box.name = "bounds";
    for (int i = 0; i < 8; ++i)
        box.positions.push_back({i & 1 ? bounds.max.x : bounds.min.x, i & 2 ? bounds.max.y : bounds.min.y,
                                 i & 4 ? bounds.max.z : bounds.min.z});
    // Two counter-clockwise (outward) triangles per face: -x, +x, -y, +y, -z, +z.
    box.indices = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
                   2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
    LocalBspParams single;
    single.maxLeafTriangles = 12;  // one leaf: the whole object is one part
    auto bsp = buildLocalBsp(box, single);
    if (!bsp) return bsp.error();
    bsp->drawTriangles = triangles;
    return bsp;
}

}  // namespace dyncull
