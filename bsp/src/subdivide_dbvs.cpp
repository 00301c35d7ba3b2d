// D-BVS: dimension-oriented bounding volume subdivision.
// Paper: Scene subdivision for occlusion culling, section 3.1. A node's box is cut along
// its largest dimension into n = largest / second-largest dimension slabs (equation 1), so
// the pieces approach cubes. Two refinements keep boxes tight without splitting triangles
// (which the paper does occasionally and we never do: a triangle goes to the slab holding
// its barycentre and stretches that slab's box instead):
//  - each plane moves by up to `planeMove` of a slab width to where it cuts the fewest
//    triangles (the paper's Figure 3), counted on a fine histogram of triangle extents;
//  - triangles longer than `pullUpWidths` slab widths along the axis (a factory floor)
//    are "pulled up" into their own child next to the slabs, so they no longer inflate
//    every box below; that child is subdivided on its own like any node.
#include <algorithm>
#include <cmath>

#include "subdivision_builder.hpp"

namespace dyncull {
namespace detail {
namespace {

constexpr std::uint32_t kMaxSlabs = 16;     // flat, long nodes: the rest is cut one level down
constexpr std::uint32_t kFinePerSlab = 64;  // histogram resolution for moving planes

class DbvsSplitter final : public Splitter {
public:
    DbvsSplitter(const SoupData& soup, const SubdivisionParams& p) : soup_(soup), p_(p) {}

    void split(std::span<std::uint32_t> tris, const Aabb&, std::uint32_t, std::vector<ChildPart>& out) override {
        Aabb box;
        for (std::uint32_t t : tris) box.extend(soup_.box[t]);
        const glm::vec3 e = box.extent();
        const int axis = box.longestAxis();
        const float largest = e[axis];
        const float second = std::max(e[(axis + 1) % 3], e[(axis + 2) % 3]);
        if (!(largest > 0.0f)) return splitInHalf(tris, out);  // every triangle is one point
        std::uint32_t slabs = kMaxSlabs;
        if (second > 0.0f) slabs = static_cast<std::uint32_t>(std::clamp(std::lround(largest / second), 2l, long(kMaxSlabs)));
        const float width = largest / float(slabs);
        const float lo = box.min[axis];

        // Pull up long triangles (only when some, but not all, are long).
        std::size_t pulled = 0;
        if (p_.pullUpWidths > 0.0f) {
            const float limit = p_.pullUpWidths * width;
            auto isLong = [&](std::uint32_t t) { return soup_.box[t].max[axis] - soup_.box[t].min[axis] > limit; };
            pulled = static_cast<std::size_t>(std::partition(tris.begin(), tris.end(), isLong) - tris.begin());
            if (pulled == tris.size()) pulled = 0;
        }
        const std::span<std::uint32_t> rest = tris.subspan(pulled);

        // Fine histogram of where the remaining triangles start and end along the axis:
        // a plane at fine boundary b cuts the triangles starting before b and ending at or after it.
        const std::uint32_t fine = kFinePerSlab * slabs;
        const float toFine = float(fine) / largest;
        auto fineOf = [&](float x) { return std::min<std::uint32_t>(fine - 1, static_cast<std::uint32_t>(std::max(0.0f, (x - lo) * toFine))); };
        starts_.assign(fine + 1, 0);
        ends_.assign(fine + 1, 0);
        for (std::uint32_t t : rest) {
            ++starts_[fineOf(soup_.box[t].min[axis]) + 1];
            ++ends_[fineOf(soup_.box[t].max[axis]) + 1];
        }
        for (std::uint32_t b = 1; b <= fine; ++b) {  // prefix sums: starts_[b] = # starting in bins < b
            starts_[b] += starts_[b - 1];
            ends_[b] += ends_[b - 1];
        }
        auto cuts = [&](std::uint32_t b) { return starts_[b] - ends_[b]; };
        planes_.clear();
        const auto window = static_cast<std::uint32_t>(p_.planeMove * float(kFinePerSlab));
        std::uint32_t prev = 0;
        for (std::uint32_t k = 1; k < slabs; ++k) {
            const std::uint32_t home = k * kFinePerSlab;
            const std::uint32_t from = std::max(prev + 1, home - window), to = home + window;
            std::uint32_t best = std::max(home, from);
            for (std::uint32_t b = from; b <= to; ++b) {
                const std::uint32_t db = b > home ? b - home : home - b, dbest = best > home ? best - home : home - best;
                if (cuts(b) < cuts(best) || (cuts(b) == cuts(best) && db < dbest)) best = b;
            }
            planes_.push_back(lo + float(best) / toFine);
            prev = best;
        }
        auto slabOf = [&](std::uint32_t t) {
            return static_cast<std::uint32_t>(std::upper_bound(planes_.begin(), planes_.end(), soup_.centroid[t][axis]) - planes_.begin());
        };
        if (pulled > 0) out.push_back({static_cast<std::uint32_t>(pulled), {}});
        auto begin = rest.begin();
        for (std::uint32_t k = 0; k < slabs && begin != rest.end(); ++k) {
            const auto end = k + 1 == slabs ? rest.end() : std::partition(begin, rest.end(), [&](std::uint32_t t) { return slabOf(t) <= k; });
            if (end != begin) out.push_back({static_cast<std::uint32_t>(end - begin), {}});
            begin = end;
        }
        if (out.size() >= 2) return;
        // All barycentres in one slab (a few triangles far off stretch the box): median plane.
        out.clear();
        const auto mid = tris.begin() + static_cast<std::ptrdiff_t>(tris.size() / 2);
        std::nth_element(tris.begin(), mid, tris.end(), AxisLess{&soup_, axis});
        splitInHalf(tris, out);
    }

    std::size_t scratchBytes() const override {
        return (starts_.capacity() + ends_.capacity()) * sizeof(std::uint32_t) + planes_.capacity() * sizeof(float);
    }

private:
    const SoupData& soup_;
    const SubdivisionParams& p_;
    std::vector<std::uint32_t> starts_, ends_;
    std::vector<float> planes_;
};

}  // namespace

std::unique_ptr<Splitter> makeDbvsSplitter(const SoupData& soup, const SubdivisionParams& params) {
    return std::make_unique<DbvsSplitter>(soup, params);
}

}  // namespace detail
}  // namespace dyncull
