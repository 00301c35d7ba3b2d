// Collapsing a subdivision tree to a wider one (binary p-HBVO to 4-ary).
// Paper: Scene subdivision for occlusion culling, section 4 (Summary): p-HBVO's binary
// tree has many intermediate entities that each cost an occlusion test; "once this
// binary tree was re-build into a quad tree representation, we achieved a frame rate
// increase of approximately 20%". A node adopts its grandchildren through the child with
// the largest box surface (the one most likely to be tested and passed) while its child
// count stays within the limit; order is kept, so triangle ranges stay contiguous.
#include <cassert>

#include "dyncull/bsp/subdivision.hpp"

namespace dyncull {

void collapseSubdivision(Subdivision& sub, std::uint32_t maxChildren) {
    assert(maxChildren >= 2);
    if (sub.nodes.empty()) return;
    const std::vector<SubdivisionNode>& old = sub.nodes;
    std::vector<SubdivisionNode> out;
    out.reserve(old.size());
    out.push_back(old[0]);
    struct Open {
        std::uint32_t oldNode, newNode;
    };
    std::vector<Open> stack{{0, 0}};
    std::vector<std::uint32_t> kids;
    while (!stack.empty()) {
        const Open o = stack.back();
        stack.pop_back();
        const SubdivisionNode& v = old[o.oldNode];
        if (v.isLeaf()) continue;
        kids.clear();
        for (std::uint32_t c = 0; c < v.childCount; ++c) kids.push_back(v.firstChild + c);
        for (;;) {
            std::size_t pick = kids.size();
            float area = -1.0f;
            for (std::size_t i = 0; i < kids.size(); ++i) {
                const SubdivisionNode& k = old[kids[i]];
                if (k.isLeaf() || kids.size() - 1 + k.childCount > maxChildren) continue;
                if (k.box.surfaceArea() > area) {
                    area = k.box.surfaceArea();
                    pick = i;
                }
            }
            if (pick == kids.size()) break;
            const SubdivisionNode& k = old[kids[pick]];
            std::vector<std::uint32_t> grand;
            for (std::uint32_t c = 0; c < k.childCount; ++c) grand.push_back(k.firstChild + c);
            kids.erase(kids.begin() + static_cast<std::ptrdiff_t>(pick));
            kids.insert(kids.begin() + static_cast<std::ptrdiff_t>(pick), grand.begin(), grand.end());
        }
        const auto first = static_cast<std::uint32_t>(out.size());
        out[o.newNode].firstChild = first;
        out[o.newNode].childCount = static_cast<std::uint32_t>(kids.size());
        for (std::uint32_t k : kids) out.push_back(old[k]);
        for (std::size_t i = kids.size(); i-- > 0;) stack.push_back({kids[i], first + static_cast<std::uint32_t>(i)});
    }
    sub.nodes = std::move(out);
}

}  // namespace dyncull
