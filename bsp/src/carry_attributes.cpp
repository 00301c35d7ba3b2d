// A game's vertex attributes carried through the local BSP's triangle splitting (the split of
// "Two-level BSP for dynamic occlusion culling", section 3.1, adds vertices on edges).
#include <string>

#include "dyncull/bsp/local_bsp.hpp"

namespace dyncull {

Expected<std::vector<float>> carryAttributes(const LocalBsp& bsp, std::span<const float> attributes,
                                             std::uint32_t components) {
    const std::size_t total = bsp.mesh.positions.size();
    if (components == 0) return Error{"carryAttributes: 0 components per vertex"};
    if (std::size_t{bsp.sourceVertexCount} + bsp.splitVertices.size() != total || (total > 0 && bsp.sourceVertexCount == 0))
        return Error{"carryAttributes: model '" + bsp.mesh.name +
                     "' has no split provenance (a BSP made by hand or read from a file); build it with buildLocalBsp"};
    // components x vertices, checked against overflow before multiplying.
    if (total > SIZE_MAX / components) return Error{"carryAttributes: " + std::to_string(components) + " components per vertex overflow"};
    if (attributes.size() != std::size_t{bsp.sourceVertexCount} * components)
        return Error{"carryAttributes: " + std::to_string(attributes.size()) + " floats for " +
                     std::to_string(bsp.sourceVertexCount) + " vertices of " + std::to_string(components) + " components"};
    std::vector<float> out(total * components);
    std::copy(attributes.begin(), attributes.end(), out.begin());
    // In order: a split vertex refers only to earlier vertices, original or split.
    for (std::size_t i = 0; i < bsp.splitVertices.size(); ++i) {
        const SplitVertex& s = bsp.splitVertices[i];
        const float* a = out.data() + std::size_t{s.a} * components;
        const float* b = out.data() + std::size_t{s.b} * components;
        float* v = out.data() + (bsp.sourceVertexCount + i) * components;
        for (std::uint32_t k = 0; k < components; ++k) v[k] = a[k] + s.t * (b[k] - a[k]);
    }
    return out;
}

}  // namespace dyncull
