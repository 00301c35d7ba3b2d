// QueryScheduler::pixelsFromShowing: how far a hidden box lay from showing, for streaming's
// read-ahead. A box is disoccluded when a silhouette in front of it moves across it, so one
// hidden just behind a silhouette (its rectangle, grown a few pixels, reaches depth farther
// than its own) is far likelier to show next than one deep behind a wall. Paper: Out-of-core
// interactive display of large meshes using an oriented bounding box-based hardware depth
// query, section 5 (prefetching by predicted visibility).
#include <algorithm>

#include "dyncull/scheduler/query_scheduler.hpp"
#include "screen_projection.hpp"

namespace dyncull {

std::optional<float> QueryScheduler::pixelsFromShowing(const Aabb& box, int maxPixels) const {
    if (!pyramidView_) return std::nullopt;
    const FrameView& view = *pyramidView_;
    const ScreenProjection screen(view);
    ScreenRect centres;
    float nearest = 1.0f;
    // A guess needs no rounding margins: the corners in float, as cluster history does.
    if (!screen.roughBoxDepth(screen.clipMatrixOf(glm::mat4(1.0f)), box, centres, nearest)) return 0.0f;
    if (centres.empty()) return std::nullopt;
    if (!pyramid_.occluded(centres, nearest)) return 0.0f;
    for (int grow = 1; grow <= maxPixels; grow *= 2) {
        const ScreenRect grown{std::max(centres.x0 - grow, 0), std::max(centres.y0 - grow, 0),
                               std::min(centres.x1 + grow, view.width), std::min(centres.y1 + grow, view.height)};
        if (!pyramid_.occluded(grown, nearest)) return float(grow);
    }
    return kFarFromShowing;
}

}  // namespace dyncull
