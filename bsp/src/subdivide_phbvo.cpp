// p-HBVO: polygon-based hierarchical bounding volume optimisation.
// Paper: Scene subdivision for occlusion culling, section 3.2. A node's triangles are
// sorted along each axis by barycentre; every position of each sorted list is a candidate
// plane, and the one minimising
//     C = S(left)/S(H) * |left| + S(right)/S(H) * |right|
// (S: surface area of the box over whole triangles, |.|: triangle count) splits the node
// in two. No triangle is split. Nodes above `exactBelow` triangles evaluate the same cost
// at `sahBins` bin boundaries per axis instead (allowed by the issue, and what makes a
// 13M-triangle soup take seconds instead of minutes); smaller nodes get the exact sweep.
// Candidates between equal barycentres are skipped, so every split is a real plane.
#include <algorithm>
#include <array>
#include <limits>

#include "subdivision_builder.hpp"

namespace dyncull {
namespace detail {
namespace {

/// Exact sweep over `tris` (any order). Fills sorted[axis] with the ids sorted on each
/// axis; uses `area` as scratch. Ties: lowest cost, then lowest axis, then fewest left.
PhbvoSplit sweepSorted(std::span<const std::uint32_t> tris, const SoupData& soup,
                       std::array<std::vector<std::uint32_t>, 3>& sorted, std::vector<float>& area) {
    const std::size_t n = tris.size();
    PhbvoSplit best;
    best.cost = std::numeric_limits<float>::infinity();
    if (n < 2) return {-1, 0, 0.0f};
    area.resize(n);
    for (int axis = 0; axis < 3; ++axis) {
        std::vector<std::uint32_t>& s = sorted[axis];
        s.assign(tris.begin(), tris.end());
        std::sort(s.begin(), s.end(), AxisLess{&soup, axis});
        Aabb acc;
        for (std::size_t i = 0; i < n; ++i) {
            acc.extend(soup.box[s[i]]);
            area[i] = acc.surfaceArea();  // S of the first i + 1 triangles
        }
        acc = Aabb{};
        PhbvoSplit axisBest;
        axisBest.cost = std::numeric_limits<float>::infinity();
        for (std::size_t i = n - 1; i >= 1; --i) {  // left = s[0, i), right = s[i, n)
            acc.extend(soup.box[s[i]]);
            if (!(soup.centroid[s[i - 1]][axis] < soup.centroid[s[i]][axis])) continue;
            const float cost = area[i - 1] * float(i) + acc.surfaceArea() * float(n - i);
            if (cost <= axisBest.cost) axisBest = {axis, static_cast<std::uint32_t>(i), cost};
        }
        if (axisBest.axis >= 0 && axisBest.cost < best.cost) best = axisBest;
    }
    if (best.axis < 0) best.cost = 0.0f;
    return best;
}

class PhbvoSplitter final : public Splitter {
public:
    PhbvoSplitter(const SoupData& soup, const SubdivisionParams& p) : soup_(soup), p_(p) {}

    void split(std::span<std::uint32_t> tris, const Aabb&, std::uint32_t, std::vector<ChildPart>& out) override {
        if (tris.size() <= p_.exactBelow) {
            const PhbvoSplit s = sweepSorted(tris, soup_, sorted_, area_);
            if (s.axis < 0) return splitInHalf(tris, out);
            std::copy(sorted_[s.axis].begin(), sorted_[s.axis].end(), tris.begin());
            out.push_back({s.left, {}});
            out.push_back({static_cast<std::uint32_t>(tris.size()) - s.left, {}});
            return;
        }
        binned(tris, out);
    }

    std::size_t scratchBytes() const override {
        return (sorted_[0].capacity() + sorted_[1].capacity() + sorted_[2].capacity()) * sizeof(std::uint32_t) +
               area_.capacity() * sizeof(float);
    }

private:
    void binned(std::span<std::uint32_t> tris, std::vector<ChildPart>& out) {
        const std::uint32_t bins = p_.sahBins;
        Aabb cb;
        for (std::uint32_t t : tris) cb.extend(soup_.centroid[t]);
        std::array<float, 3> lo{}, scale{};
        bool any = false;
        for (int a = 0; a < 3; ++a) {
            lo[a] = cb.min[a];
            const float ext = cb.max[a] - cb.min[a];
            scale[a] = ext > 0.0f ? float(bins) / ext : 0.0f;
            any |= ext > 0.0f;
        }
        if (!any) return splitInHalf(tris, out);
        auto binOf = [&](std::uint32_t t, int a) {
            return std::min<std::uint32_t>(bins - 1, static_cast<std::uint32_t>((soup_.centroid[t][a] - lo[a]) * scale[a]));
        };
        for (int a = 0; a < 3; ++a) {
            counts_[a].assign(bins, 0);
            boxes_[a].assign(bins, Aabb{});
        }
        for (std::uint32_t t : tris) {
            const Aabb& b = soup_.box[t];
            for (int a = 0; a < 3; ++a) {
                if (scale[a] == 0.0f) continue;
                const std::uint32_t k = binOf(t, a);
                ++counts_[a][k];
                boxes_[a][k].extend(b);
            }
        }
        float bestCost = std::numeric_limits<float>::infinity();
        int bestAxis = -1;
        std::uint32_t bestBin = 0;
        rightCost_.resize(bins);
        for (int a = 0; a < 3; ++a) {
            if (scale[a] == 0.0f) continue;
            Aabb acc;
            std::uint32_t m = 0;
            for (std::uint32_t k = bins - 1; k > 0; --k) {
                acc.extend(boxes_[a][k]);
                m += counts_[a][k];
                rightCost_[k] = m ? acc.surfaceArea() * float(m) : -1.0f;
            }
            acc = Aabb{};
            m = 0;
            for (std::uint32_t k = 0; k + 1 < bins; ++k) {  // left = bins [0, k]
                acc.extend(boxes_[a][k]);
                m += counts_[a][k];
                if (m == 0 || rightCost_[k + 1] < 0.0f) continue;  // one side empty
                const float cost = acc.surfaceArea() * float(m) + rightCost_[k + 1];
                if (cost < bestCost) {
                    bestCost = cost;
                    bestAxis = a;
                    bestBin = k + 1;
                }
            }
        }
        if (bestAxis < 0) return splitInHalf(tris, out);
        const auto mid = std::partition(tris.begin(), tris.end(), [&](std::uint32_t t) { return binOf(t, bestAxis) < bestBin; });
        const auto left = static_cast<std::uint32_t>(mid - tris.begin());
        out.push_back({left, {}});
        out.push_back({static_cast<std::uint32_t>(tris.size()) - left, {}});
    }

    const SoupData& soup_;
    const SubdivisionParams& p_;
    std::array<std::vector<std::uint32_t>, 3> sorted_;
    std::vector<float> area_;
    std::array<std::vector<std::uint32_t>, 3> counts_;
    std::array<std::vector<Aabb>, 3> boxes_;
    std::vector<float> rightCost_;
};

}  // namespace

std::unique_ptr<Splitter> makePhbvoSplitter(const SoupData& soup, const SubdivisionParams& params) {
    return std::make_unique<PhbvoSplitter>(soup, params);
}

}  // namespace detail

PhbvoSplit phbvoBestSplitSorted(const Mesh& mesh, std::span<const std::uint32_t> tris) {
    detail::SoupData soup;
    detail::computeSoupData(mesh, 1, soup);
    std::array<std::vector<std::uint32_t>, 3> sorted;
    std::vector<float> area;
    return detail::sweepSorted(tris, soup, sorted, area);
}

}  // namespace dyncull
