// Octree subdivisions: eight children per node, triangles assigned by barycentre, never split.
//  - "octree", load-balanced: Scene subdivision for occlusion culling, section 3.4 (SGI's
//    opoptimize: "choosing subdivision planes so that the rendering loads of the resulting
//    parts are similar"). The node is halved at the median barycentre on x, each half at
//    its own median on y, each quarter on z: eight children of n/8 triangles.
//  - "grid", regular: section 3.3 (ORSD), with the triangle count in place of the relevant
//    cell load. Cells are the octants of a cube around the model; node boxes bound the
//    geometry, not the octant (as in the paper's Figure 9). Empty octants make no node.
#include <algorithm>

#include "subdivision_builder.hpp"

namespace dyncull {
namespace detail {
namespace {

class OctreeSplitter final : public Splitter {
public:
    explicit OctreeSplitter(const SoupData& soup) : soup_(soup) {}

    void split(std::span<std::uint32_t> tris, const Aabb&, std::uint32_t, std::vector<ChildPart>& out) override {
        // Ranges of the eight children, refined axis by axis: [bounds[i], bounds[i + 1]).
        std::size_t bounds[9] = {0, tris.size()};
        std::size_t parts = 1;
        for (int axis = 0; axis < 3; ++axis) {
            std::size_t next[9];
            next[0] = 0;
            for (std::size_t i = 0; i < parts; ++i) {
                const auto b = tris.begin() + static_cast<std::ptrdiff_t>(bounds[i]);
                const auto e = tris.begin() + static_cast<std::ptrdiff_t>(bounds[i + 1]);
                const auto mid = b + (e - b) / 2;
                if (b != e) std::nth_element(b, mid, e, AxisLess{&soup_, axis});
                next[2 * i + 1] = static_cast<std::size_t>(mid - tris.begin());
                next[2 * i + 2] = bounds[i + 1];
            }
            parts *= 2;
            std::copy(next, next + parts + 1, bounds);
        }
        for (std::size_t i = 0; i < 8; ++i)
            if (bounds[i + 1] > bounds[i]) out.push_back({static_cast<std::uint32_t>(bounds[i + 1] - bounds[i]), {}});
    }

    std::size_t scratchBytes() const override { return 0; }

private:
    const SoupData& soup_;
};

class GridSplitter final : public Splitter {
public:
    explicit GridSplitter(const SoupData& soup) : soup_(soup) {}

    void split(std::span<std::uint32_t> tris, const Aabb& cell, std::uint32_t, std::vector<ChildPart>& out) override {
        const glm::vec3 mid = cell.center();
        // Octant o has bit a set when the barycentre is at or above the middle on axis a.
        std::size_t bounds[9] = {0, tris.size()};
        std::size_t parts = 1;
        for (int axis = 2; axis >= 0; --axis) {  // z first, so octant index bit 0 is x
            std::size_t next[9];
            next[0] = 0;
            for (std::size_t i = 0; i < parts; ++i) {
                const auto b = tris.begin() + static_cast<std::ptrdiff_t>(bounds[i]);
                const auto e = tris.begin() + static_cast<std::ptrdiff_t>(bounds[i + 1]);
                const auto m = std::partition(b, e, [&](std::uint32_t t) { return soup_.centroid[t][axis] < mid[axis]; });
                next[2 * i + 1] = static_cast<std::size_t>(m - tris.begin());
                next[2 * i + 2] = bounds[i + 1];
            }
            parts *= 2;
            std::copy(next, next + parts + 1, bounds);
        }
        for (std::size_t o = 0; o < 8; ++o) {
            if (bounds[o + 1] == bounds[o]) continue;
            Aabb c = cell;
            for (int a = 0; a < 3; ++a) (((o >> a) & 1) ? c.min[a] : c.max[a]) = mid[a];
            out.push_back({static_cast<std::uint32_t>(bounds[o + 1] - bounds[o]), c});
        }
    }

    std::size_t scratchBytes() const override { return 0; }

private:
    const SoupData& soup_;
};

}  // namespace

std::unique_ptr<Splitter> makeOctreeSplitter(const SoupData& soup, const SubdivisionParams&) {
    return std::make_unique<OctreeSplitter>(soup);
}

std::unique_ptr<Splitter> makeGridSplitter(const SoupData& soup, const SubdivisionParams&) {
    return std::make_unique<GridSplitter>(soup);
}

}  // namespace detail
}  // namespace dyncull
