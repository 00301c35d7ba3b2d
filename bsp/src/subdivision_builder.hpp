// Shared machinery of the subdivision methods: per-triangle data and the interface a
// method implements (partition one node's triangles into consecutive children). The
// builder (subdivision_builder.cpp) owns recursion, node layout, threads and boxes.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "dyncull/bsp/subdivision.hpp"

namespace dyncull::detail {

/// Per-triangle data indexed by triangle id: barycentre and box (mesh space). 36 bytes
/// per triangle; with the 4-byte order array this is the builder's memory per triangle.
struct SoupData {
    std::vector<glm::vec3> centroid;
    std::vector<Aabb> box;
};

/// Fills `soup` for every triangle of `mesh` on `threads` threads.
void computeSoupData(const Mesh& mesh, unsigned threads, SoupData& soup);

/// One child a method made: its triangle count (> 0) and, for the regular octree, its
/// cell (the octant); other methods leave the cell empty.
struct ChildPart {
    std::uint32_t count = 0;
    Aabb cell;
};

/// A subdivision method. split() partitions `tris` (triangle ids) in place so that the
/// children are consecutive ranges, and appends them to `out` in that order (each with
/// count > 0). Fewer than two children means "no split": none is a leaf; one child with a
/// different cell (regular octree) is followed without making a node. An instance holds
/// scratch memory and is used by one thread at a time.
class Splitter {
public:
    virtual ~Splitter() = default;
    virtual void split(std::span<std::uint32_t> tris, const Aabb& cell, std::uint32_t depth,
                       std::vector<ChildPart>& out) = 0;
    /// Bytes of scratch currently held (for SubdivisionStats::workBytes).
    virtual std::size_t scratchBytes() const = 0;
};

std::unique_ptr<Splitter> makePhbvoSplitter(const SoupData& soup, const SubdivisionParams& params);
std::unique_ptr<Splitter> makeDbvsSplitter(const SoupData& soup, const SubdivisionParams& params);
std::unique_ptr<Splitter> makeOctreeSplitter(const SoupData& soup, const SubdivisionParams& params);
std::unique_ptr<Splitter> makeGridSplitter(const SoupData& soup, const SubdivisionParams& params);

/// Strict total order of triangles along `axis`: barycentre, then id (so sorts and
/// medians are reproducible whatever the library's algorithm).
struct AxisLess {
    const SoupData* soup;
    int axis;
    bool operator()(std::uint32_t a, std::uint32_t b) const {
        const float ca = soup->centroid[a][axis], cb = soup->centroid[b][axis];
        return ca != cb ? ca < cb : a < b;
    }
};

/// Splits `tris` at its middle in their current order: the fallback when no plane
/// separates the barycentres (all equal), so leaf limits still hold.
void splitInHalf(std::span<std::uint32_t> tris, std::vector<ChildPart>& out);

}  // namespace dyncull::detail
