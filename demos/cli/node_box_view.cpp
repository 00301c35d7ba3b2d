// Node-box view: trace -> coloured wireframe boxes, stats panel and legend.
#include "node_box_view.hpp"

#include <algorithm>
#include <cstdio>

namespace dyncull::cli {

glm::vec4 nodeStateColour(NodeState s) {
    switch (s) {
        case NodeState::FrustumCulled: return {0.95f, 0.30f, 0.25f, 0.8f};
        case NodeState::Occluded: return {0.30f, 0.55f, 1.00f, 1.0f};
        case NodeState::SmallFeature: return {0.95f, 0.35f, 0.95f, 1.0f};
        case NodeState::VisibleQueried: return {0.30f, 0.95f, 0.35f, 1.0f};
        case NodeState::VisibleHistory: return {1.00f, 0.88f, 0.20f, 1.0f};
        case NodeState::VisibleOccupancy: return {0.20f, 0.95f, 0.95f, 1.0f};
        case NodeState::VisibleNear: return {1.00f, 1.00f, 1.00f, 1.0f};
        case NodeState::VisibleFront: return {1.00f, 0.60f, 0.15f, 1.0f};
        case NodeState::VisibleVfc: return {0.75f, 0.80f, 0.75f, 1.0f};
        case NodeState::VisibleCheaper: return {0.80f, 0.55f, 1.00f, 1.0f};
        case NodeState::VisibleOccluder: return {0.55f, 0.35f, 0.20f, 1.0f};
        case NodeState::ClusterCulled: return {0.45f, 0.45f, 0.85f, 1.0f};
        case NodeState::BudgetCulled: return {1.00f, 0.40f, 0.60f, 1.0f};
    }
    return {1, 1, 1, 1};
}

std::string compactCount(double n) {
    char buf[32];
    if (n >= 1e6)
        std::snprintf(buf, sizeof buf, "%.2fM", n / 1e6);
    else if (n >= 1e4)
        std::snprintf(buf, sizeof buf, "%.1fk", n / 1e3);
    else
        std::snprintf(buf, sizeof buf, "%.0f", n);
    return buf;
}

std::size_t NodeBoxView::drawBoxes(Engine& engine, const NodeBoxFilter& filter) {
    const TwoLevelTree tree(engine.sceneTree(), engine.objects());
    std::size_t drawn = 0;
    for (const NodeTrace& t : trace_) {
        if (t.state == NodeState::FrustumCulled && !filter.frustumCulled) continue;
        const bool visible = t.state >= NodeState::VisibleQueried;
        const bool objectRoot = !t.ref.isSceneNode() && t.ref.node == 0;
        // Parts matter when culled (that is where occlusion happens in a dense swarm).
        if (!filter.parts && !t.ref.isSceneNode() && !objectRoot && visible) continue;
        // A visible inner node is refined further: its children carry the final decisions.
        const bool final = tree.isDrawable(t.ref) || (objectRoot && !filter.parts);
        if (visible && !filter.innerVisible && !final) continue;
        lines_.addBox(t.box, nodeStateColour(t.state));
        ++drawn;
    }
    const glm::ivec2 size = engine.context().size();
    // Thin lines at small sizes so tests' tiny frames stay readable, 2 px otherwise.
    lines_.flush(engine.camera().viewProjection(), size, LineDepth::XRay, size.y >= 400 ? 1.5f : 1.0f, 0.15f);
    return drawn;
}

void NodeBoxView::drawText(Engine& engine, const std::vector<std::string>& lines, bool legend, const std::string& help) {
    const glm::ivec2 size = engine.context().size();
    const int scale = size.y >= 900 ? 3 : size.y >= 300 ? 2 : 1;
    const int pad = 3 * scale;
    const glm::vec4 panel{0.0f, 0.0f, 0.0f, 0.6f};
    const glm::vec4 ink{0.95f, 0.95f, 0.95f, 1.0f};

    std::string block;
    for (std::size_t i = 0; i < lines.size(); ++i) block += (i ? "\n" : "") + lines[i];
    if (!block.empty()) {
        const glm::ivec2 m = TextOverlay::measure(block, scale);
        text_.addRect({0, 0}, m + 2 * pad, panel);
        text_.addText({pad, pad}, block, ink, scale);
    }
    if (legend) {
        static const NodeState kShown[] = {NodeState::Occluded, NodeState::VisibleQueried, NodeState::VisibleHistory,
                                           NodeState::VisibleOccupancy, NodeState::VisibleNear, NodeState::VisibleFront,
                                           NodeState::VisibleVfc, NodeState::VisibleCheaper, NodeState::VisibleOccluder,
                                           NodeState::ClusterCulled, NodeState::BudgetCulled, NodeState::SmallFeature,
                                           NodeState::FrustumCulled};
        static const char* const kLabel[] = {"occluded", "visible (queried)", "visible (history, no query)",
                                             "visible (occupancy, no query)", "visible (near/inside)",
                                             "visible (front-most, no query)", "in frustum (vfc mode)",
                                             "visible (cheaper drawn than tested)", "occluder-only (untested)",
                                             "every cluster culled", "culled within the error budget", "small feature",
                                             "frustum culled"};
        const int rowH = kLineAdvance * scale;
        const int n = static_cast<int>(std::size(kShown));
        const int swatch = kGlyphHeight * scale;
        int widest = 0;
        for (const char* l : kLabel) widest = std::max(widest, TextOverlay::measure(l, scale).x);
        const glm::ivec2 panelSize{pad * 3 + swatch + widest, pad * 2 + n * rowH - (rowH - swatch)};
        const glm::ivec2 origin{0, size.y - panelSize.y};
        text_.addRect(origin, panelSize, panel);
        for (int i = 0; i < n; ++i) {
            const glm::ivec2 row = origin + glm::ivec2(pad, pad + i * rowH);
            text_.addRect(row, {swatch, swatch}, nodeStateColour(kShown[i]));
            text_.addText(row + glm::ivec2(swatch + pad, 0), kLabel[i], ink, scale);
        }
    }
    if (!help.empty()) {
        const glm::ivec2 m = TextOverlay::measure(help, scale);
        const glm::ivec2 origin = size - m - 2 * pad;
        text_.addRect(origin, m + 2 * pad, panel);
        text_.addText(origin + pad, help, {0.8f, 0.85f, 0.9f, 1.0f}, scale);
    }
    text_.flush(size);
}

}  // namespace dyncull::cli
