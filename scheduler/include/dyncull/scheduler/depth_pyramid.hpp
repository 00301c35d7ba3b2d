// Farthest-depth pyramid (hierarchical Z) of a depth buffer, and the conservative test of a
// screen rectangle against it: the cheap occlusion test of the two-phase method (draw last
// frame's visible parts, build the pyramid from their depth, test everything else). Plain
// C++ on a depth buffer read back from the GPU (or made by a test); no OpenGL.
//
// Conservative by construction, for any width and height (not only powers of two): texel
// (x, y) of level k holds the farthest depth of exactly the level-0 pixels
// [x 2^k, (x + 1) 2^k) x [y 2^k, (y + 1) 2^k) that lie on the screen, and a rectangle is
// tested at the finest level where it spans at most kMaxSpan texels a side, reading every
// texel it touches, so every pixel it covers lies under a texel read (the step niagara and
// Bevy got wrong, see ../shared/notes/batched-occlusion-tests.md).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "dyncull/scheduler/occupancy_map.hpp"

namespace dyncull {

/// Planes that bound a convex volume's nearest window depth pixel by pixel, where one
/// nearest depth for its whole footprint is loose (a long wall seen at a slant, a box whose
/// near corner pokes out beside an occluder). Each is the window depth of one of the
/// volume's front faces' planes, an affine function of window coordinates in pixels
/// (origin at the lower left, pixel (x, y)'s centre at (x + 0.5, y + 0.5)):
/// depth = a x + b y + c. A ray enters a convex volume through its front faces, and the
/// entry is the last of those planes it crosses: at every point whose ray meets the volume,
/// its nearest depth is at most each plane's depth there (reversed Z, nearer is greater).
/// Any subset of the front faces' planes is such a bound, so a face too close to edge-on
/// to be trusted is left out. Filled by ScreenProjection::boxDepth.
/// With them, the volume's outline: the convex hull of its projected corners, as the
/// half-planes a x + b y <= c in the same pixel coordinates. The volume covers no point
/// outside it, so a pixel whose centre (grown as the bounds are) lies outside one of them
/// is not the volume's, whatever its depth. No edges: the whole footprint may be covered.
struct DepthPlanes {
    static constexpr std::size_t kMax = 3;  ///< a box shows at most three faces
    std::array<std::array<double, 3>, kMax> planes{};  ///< {a, b, c}; [0, count) used
    std::uint32_t count = 0;
    static constexpr std::size_t kMaxEdges = 8;  ///< a hull of 8 corners
    std::array<std::array<double, 3>, kMaxEdges> edges{};  ///< {a, b, c}; [0, edgeCount) used
    std::uint32_t edgeCount = 0;
};

/// Depths are window depths in dyncull's reversed-Z convention (objects/camera.hpp): 1 at
/// the near plane, 0 at the far plane (and the cleared value), nearer is greater; the
/// "farthest" of a set of depths is its minimum.
class DepthPyramid {
public:
    /// Builds the pyramid of `depth`: width x height window depths, row by row from the
    /// bottom row (as glReadPixels returns them). Reuses its memory across calls.
    /// Preconditions (asserted): width, height >= 1, depth.size() == width * height.
    void build(std::span<const float> depth, int width, int height);
    /// The same without copying the depth buffer: level 0 becomes `depth`'s storage, and
    /// `depth` gets the storage level 0 had (its contents unspecified), for the next read.
    /// Preconditions as build.
    void adopt(std::vector<float>& depth, int width, int height);

    int width() const { return width_; }
    int height() const { return height_; }
    int levels() const { return static_cast<int>(levels_.size()); }
    /// Texel (x, y) of `level` (0 is the depth buffer itself); for tests and debug views.
    float texel(int level, int x, int y) const;

    /// Texels a tested rectangle may span per axis. 2 is the classic HZB test (four reads);
    /// 4 reads up to 16 texels of a level two steps finer, a bound on 1/4 of the area
    /// around the rectangle, which culls the swarm's small parts far better.
    static constexpr int kMaxSpan = 4;

    /// Farthest depth over a superset of the pixels of `rect` (clamped to the screen): at
    /// most kMaxSpan^2 texel reads. An empty rectangle, or one wholly off screen, covers no pixel
    /// and gives 1 (the near plane), the farthest of nothing.
    float farthestIn(const ScreenRect& rect) const;

    /// True only if a surface whose nearest window depth is `nearestDepth` and whose
    /// fragments all fall inside `rect` is hidden at every pixel: it lies behind the
    /// farthest depth of the rectangle by more than the rasteriser's rounding
    /// (kDepthSlack). False for an empty or off-screen rectangle (no evidence either way)
    /// and before the first build. The caller must have called the volume visible already if
    /// it crosses the near plane (then it has no meaningful nearest depth).
    bool occluded(const ScreenRect& rect, float nearestDepth) const { return occluded(rect, nearestDepth, kMaxSpan); }
    /// The same at the finest level where the rectangle spans at most `maxSpan` texels a
    /// side (at most maxSpan^2 reads; maxSpan >= 2): a larger span costs more reads and is
    /// hidden more often.
    bool occluded(const ScreenRect& rect, float nearestDepth, int maxSpan) const;

    /// The same test as occluded(rect, nearestDepth, 2) first, then, where that cannot
    /// decide, texel by texel down the pyramid with the surface's depth bounded over each
    /// texel by `planes` (and by nearestDepth): a texel whose pixels the surface lies
    /// behind is settled, one it may not be is split into its four finer texels, and a
    /// pixel it may not be behind makes it visible. `rect` holds the pixels whose centres
    /// the surface can cover (DepthFootprint::centres); each bound is taken over their
    /// centres grown by kSnapPixels, where a rasteriser's snapping may move a surface
    /// point. A texel whose pixels all lie outside the planes' outline is settled too.
    /// Gives up, answering visible, after `maxTexels` texels (>= 1). With no planes it
    /// reads down to single pixels too, against nearestDepth alone.
    bool occludedPerTexel(const ScreenRect& rect, float nearestDepth, const DepthPlanes& planes, int maxTexels) const;

    /// How far a rasteriser may move a vertex when it snaps it to its sub-pixel grid, in
    /// pixels: GL's at least 4 sub-pixel bits move it by at most 1/32; twice that.
    static constexpr double kSnapPixels = 1.0 / 16.0;

    /// Relative margin on depths: the GPU's depth of a surface point and the CPU's exact
    /// depth of the volume around it differ by float rounding (a few ulp, 2^-23 each); the
    /// margin is 2^-16 of the depth, far above that and far below any real separation.
    static constexpr float kDepthSlack = 0x1p-16f;

private:
    /// The finest level where inclusive pixel bounds span at most `maxSpan` texels a side,
    /// looking from level `from` up (a level where they span at most more texels).
    /// (At the top level, 1x1, any rectangle spans one texel.)
    static int levelSpanning(int x0, int y0, int x1, int y1, int maxSpan, int from = 0) {
        int k = from;
        while ((x1 >> k) - (x0 >> k) >= maxSpan || (y1 >> k) - (y0 >> k) >= maxSpan) ++k;
        return k;
    }
    /// farthestIn for inclusive pixel bounds already clamped to the screen.
    float farthestInPixels(int x0, int y0, int x1, int y1, int maxSpan = kMaxSpan) const;
    /// Whether a surface at `nearestDepth` lies behind every texel of `level` over the
    /// clamped pixel bounds (stops at the first it does not).
    bool hiddenAt(int level, int x0, int y0, int x1, int y1, float nearestDepth) const;

    /// Builds levels 1 and up from base_.
    void buildLevels();
    /// Level `k`'s texels, row-major from the bottom row.
    const float* levelData(std::size_t k) const { return k == 0 ? base_.data() : texels_.data() + levels_[k].offset; }

    struct Level {
        std::size_t offset = 0;  // into texels_ (levels 1 and up)
        int width = 0, height = 0;
    };
    std::vector<float> base_;    // level 0: the depth buffer
    std::vector<float> texels_;  // levels 1 and up, each row-major from the bottom row
    std::vector<Level> levels_;
    int width_ = 0, height_ = 0;
};

/// The oracle of occludedPerTexel, pixel by pixel: true only if at every pixel of `rect`
/// (clamped to the screen) the surface's bound (nearestDepth, and each plane's depth over
/// the pixel's centre grown by DepthPyramid::kSnapPixels) lies behind the pixel's depth by
/// more than DepthPyramid::kDepthSlack, or that grown centre lies outside the outline.
bool occludedPerPixelBruteForce(std::span<const float> depth, int width, int height, const ScreenRect& rect, float nearestDepth,
                                const DepthPlanes& planes);

/// The oracle: farthest depth over exactly the pixels of `rect` (clamped to the screen),
/// by looking at each one; 1 for an empty or off-screen rectangle, as farthestIn.
float farthestInBruteForce(std::span<const float> depth, int width, int height, const ScreenRect& rect);

}  // namespace dyncull
