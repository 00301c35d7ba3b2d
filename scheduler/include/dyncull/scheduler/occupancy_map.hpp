// Coarse screen-space bitmap of tiles. Used twice by the scheduler:
//  - "drawn" map: tiles touched by geometry drawn this frame; a node whose screen
//    rectangle touches an unmarked tile is visible without a query (nothing drawn
//    there can hide it) — the occupancy-map fast accept;
//  - "pending" map: rectangles of queries in flight; a query is issued in the same batch
//    only if its rectangle overlaps no pending one.
// Paper: Staneker, Bartz, Straßer, Efficient Multiple Occlusion Queries for Scene Graph
// Systems (2004), sections 3.1-3.2.
#pragma once

#include <cstdint>
#include <vector>

namespace dyncull {

/// Pixel rectangle, inclusive-exclusive: [x0, x1) x [y0, y1), origin bottom-left.
struct ScreenRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool empty() const { return x1 <= x0 || y1 <= y0; }
    int area() const { return empty() ? 0 : (x1 - x0) * (y1 - y0); }
    bool operator==(const ScreenRect&) const = default;
};

class OccupancyMap {
public:
    /// Covers a width x height pixel viewport with tiles of `tileSize` pixels.
    void reset(int width, int height, int tileSize);
    void clear();
    /// The map reset() would make, emptied: its storage is kept when it already has that
    /// shape (the per-frame call).
    void resetOrClear(int width, int height, int tileSize);

    /// Sets every tile the rectangle touches.
    void mark(const ScreenRect& r);
    /// Clears every tile the rectangle touches (used for non-overlapping pending rects).
    void unmark(const ScreenRect& r);
    /// True if every tile the rectangle touches is set.
    bool allSet(const ScreenRect& r) const;
    /// True if any tile the rectangle touches is set.
    bool anySet(const ScreenRect& r) const;

    int tilesX() const { return tilesX_; }
    int tilesY() const { return tilesY_; }
    bool tile(int tx, int ty) const;

private:
    struct TileRange { int tx0, ty0, tx1, ty1; };  // inclusive-exclusive, clamped
    TileRange tiles(const ScreenRect& r) const;
    std::uint64_t rowMask(int word, int tx0, int tx1) const;

    int tileSize_ = 16, tilesX_ = 0, tilesY_ = 0, wordsPerRow_ = 0;
    std::vector<std::uint64_t> bits_;
};

}  // namespace dyncull
