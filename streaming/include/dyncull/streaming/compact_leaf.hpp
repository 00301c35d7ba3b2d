// A streamed leaf as main memory keeps it: positions quantised to 16 bits an axis inside the
// leaf's box, unit normals in octahedral form at 16 bits a component, indices in 16 bits
// where the vertex count allows. 10 bytes a vertex and 6 (or 12) a triangle, against 24 and
// 12 decoded, so a memory budget holds over twice the leaves; a leaf is expanded only to be
// uploaded. The file keeps full precision: every reader that shows a leaf (the draw, and
// the measurements' ground truth) goes through compactLeaf and expandLeaf, so all of them
// see the same geometry.
#pragma once

#include <cstdint>
#include <vector>

#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/mesh.hpp"

namespace dyncull {

struct StreamedLeaf;

struct CompactLeaf {
    Aabb box;  ///< the box the positions are quantised in (the leaf's, model space)
    std::uint32_t vertexCount = 0, triangleCount = 0;
    bool wideIndices = false;  ///< indices take two 16-bit words (more than 65,536 vertices)
    /// Positions (3 words a vertex), then normals (2), then indices (3 a triangle, each one
    /// or two words, low word first).
    std::vector<std::uint16_t> words;

    std::size_t bytes() const { return words.size() * sizeof(std::uint16_t); }
};

/// The bytes compactLeaf gives a leaf of the node file, known before it is read.
std::size_t compactLeafBytes(const StreamedLeaf& leaf);

/// Encodes `mesh` into `out` (its storage reused). Preconditions (asserted): one normal per
/// position. Positions outside `box` are clamped into it, so every expanded position lies
/// in the box; a box with no extent along an axis gives that axis exactly. Each position
/// comes back within half a step (the box's extent / 65,535) of its own along each axis, and
/// each normal within 0.01 degrees of its direction.
void compactLeaf(const Mesh& mesh, const Aabb& box, CompactLeaf& out);

/// Decodes `leaf` into `out` (its storage reused; name left as it is): positions in the
/// box, unit normals, the indices exactly.
void expandLeaf(const CompactLeaf& leaf, Mesh& out);

}  // namespace dyncull
