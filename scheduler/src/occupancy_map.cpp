// Coarse occupancy bitmap. Paper: Staneker, Bartz, Straßer, Efficient Multiple Occlusion
// Queries for Scene Graph Systems (2004), sections 3.1-3.2.
#include "dyncull/scheduler/occupancy_map.hpp"

#include <algorithm>
#include <cassert>

namespace dyncull {

void OccupancyMap::reset(int width, int height, int tileSize) {
    assert(tileSize > 0 && width >= 0 && height >= 0);
    tileSize_ = tileSize;
    tilesX_ = (width + tileSize - 1) / tileSize;
    tilesY_ = (height + tileSize - 1) / tileSize;
    wordsPerRow_ = (tilesX_ + 63) / 64;
    bits_.assign(static_cast<std::size_t>(wordsPerRow_) * static_cast<std::size_t>(tilesY_), 0);
}

void OccupancyMap::clear() { std::fill(bits_.begin(), bits_.end(), 0); }

void OccupancyMap::resetOrClear(int width, int height, int tileSize) {
    assert(tileSize > 0);
    if (tileSize == tileSize_ && tilesX_ == (width + tileSize - 1) / tileSize && tilesY_ == (height + tileSize - 1) / tileSize)
        clear();
    else
        reset(width, height, tileSize);
}

OccupancyMap::TileRange OccupancyMap::tiles(const ScreenRect& r) const {
    // A pixel rectangle [x0, x1) touches tiles x0/ts .. (x1-1)/ts.
    TileRange t{std::max(r.x0, 0) / tileSize_, std::max(r.y0, 0) / tileSize_, 0, 0};
    t.tx1 = std::min((r.x1 - 1) / tileSize_ + 1, tilesX_);
    t.ty1 = std::min((r.y1 - 1) / tileSize_ + 1, tilesY_);
    if (r.empty()) t.tx1 = t.tx0;
    return t;
}

std::uint64_t OccupancyMap::rowMask(int word, int tx0, int tx1) const {
    const int lo = std::max(tx0 - word * 64, 0);
    const int hi = std::min(tx1 - word * 64, 64);  // exclusive
    if (hi <= lo) return 0;
    const std::uint64_t upper = hi == 64 ? ~0ull : ((1ull << hi) - 1);
    const std::uint64_t lower = (1ull << lo) - 1;
    return upper & ~lower;
}

void OccupancyMap::mark(const ScreenRect& r) {
    const TileRange t = tiles(r);
    for (int ty = t.ty0; ty < t.ty1; ++ty)
        for (int w = t.tx0 / 64; w * 64 < t.tx1; ++w) bits_[ty * wordsPerRow_ + w] |= rowMask(w, t.tx0, t.tx1);
}

void OccupancyMap::unmark(const ScreenRect& r) {
    const TileRange t = tiles(r);
    for (int ty = t.ty0; ty < t.ty1; ++ty)
        for (int w = t.tx0 / 64; w * 64 < t.tx1; ++w) bits_[ty * wordsPerRow_ + w] &= ~rowMask(w, t.tx0, t.tx1);
}

bool OccupancyMap::allSet(const ScreenRect& r) const {
    const TileRange t = tiles(r);
    for (int ty = t.ty0; ty < t.ty1; ++ty)
        for (int w = t.tx0 / 64; w * 64 < t.tx1; ++w) {
            const std::uint64_t m = rowMask(w, t.tx0, t.tx1);
            if ((bits_[ty * wordsPerRow_ + w] & m) != m) return false;
        }
    return true;
}

bool OccupancyMap::anySet(const ScreenRect& r) const {
    const TileRange t = tiles(r);
    for (int ty = t.ty0; ty < t.ty1; ++ty)
        for (int w = t.tx0 / 64; w * 64 < t.tx1; ++w)
            if (bits_[ty * wordsPerRow_ + w] & rowMask(w, t.tx0, t.tx1)) return true;
    return false;
}

bool OccupancyMap::tile(int tx, int ty) const {
    assert(tx >= 0 && ty >= 0 && tx < tilesX_ && ty < tilesY_);
    return (bits_[ty * wordsPerRow_ + tx / 64] >> (tx % 64)) & 1u;
}

}  // namespace dyncull
