// Per-node record of recent query answers, used to skip queries for nodes that were
// visible recently: the more "visible" answers in the history, the more frames the
// next query is postponed while the node is drawn as visible.
// Paper: Two-level BSP for dynamic occlusion culling, section 3.4 and Figure 3.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "dyncull/bsp/traversal.hpp"

namespace dyncull {

struct HistoryParams {
    /// Frames a query is postponed per "visible" answer among the last 8 queries.
    std::uint32_t skipFramesPerVisible = 1;
    std::uint32_t maxSkipFrames = 8;  ///< cap on the postponement
    /// Answers needed before any skipping starts (1 = skip after one visible answer).
    std::uint32_t minVisibleToSkip = 2;
    /// Spread re-queries over frames with a fixed per-node shortening of the postponement.
    bool jitter = true;
};

/// One node's record. `bits` holds the last 8 answers (bit 0 newest, 1 = visible).
struct NodeHistory {
    std::uint32_t lastQueryFrame = 0;  ///< frame of the newest answer
    std::uint32_t lastVisibleFrame = 0;  ///< last frame the node was known or assumed visible
    std::uint32_t lastTouchedFrame = 0;  ///< last frame the traversal reached the node
    std::uint8_t bits = 0;
    std::uint8_t answers = 0;  ///< number of answers recorded, saturating at 8
    bool lastVisible = false;  ///< outcome the last time the node was reached (false: never seen)
    bool queryInFlight = false;  ///< a query issued in an earlier frame has not been read yet
};

/// Storage for scene-tree and object-tree nodes together. Scene nodes by node index;
/// object nodes in a per-object-slot block sized to the model's node count, reset when
/// the slot is reused by another object (generation changed) or its model changes.
class VisibilityHistory {
public:
    /// Record for `ref`, creating it (never seen: lastVisible false) if needed.
    NodeHistory& at(NodeRef ref, const SceneObjects& objects);
    /// The record for `ref` if there is one for the object as it is now (same generation
    /// and model), else nullptr; never creates one.
    const NodeHistory* find(NodeRef ref, const SceneObjects& objects) const;
    /// One bit per cluster of the object's model (LocalBsp::clusters, in order; bit i of
    /// the span is word i / 64, bit i % 64), kept, created and reset with the object's
    /// node records: the cluster-level history of TwoPhase (SchedulerFeatures::
    /// useClusterHistory), where a set bit means the cluster showed in the last frame its
    /// part was drawn in: its box in the final depth, or with useClusterMarks a fragment of
    /// it when drawn. Empty for a model without clusters. Valid until the next call that
    /// creates records. Read and written through clusterBit / setClusterBit.
    std::span<std::uint64_t> clusterBits(std::uint32_t object, const SceneObjects& objects);
    void clear();

    void recordAnswer(NodeHistory& h, bool visible, std::uint32_t frame) const;
    /// True if the node may be drawn this frame without a query (Algorithm 3,
    /// ExamineRecentQueryResults): it was visible last time and the postponement that its
    /// count of visible answers earns has not run out.
    /// The postponement is shortened by a fixed per-node amount (up to half of it, from a
    /// hash of `ref`) so nodes that became visible together do not all re-query in the
    /// same later frame (which would make every k-th frame a spike of queries).
    bool canSkipQuery(NodeRef ref, const NodeHistory& h, std::uint32_t frame, const HistoryParams& p) const;
    /// How many frames after its last answer a node known visible may go untested: what
    /// its count of visible answers earns, shortened by the per-node jitter (0: test now).
    std::uint32_t postponement(NodeRef ref, const NodeHistory& h, const HistoryParams& p) const;

    std::size_t memoryBytes() const;

private:
    /// Makes `slot`'s block of records and cluster bits current for the object in it.
    void ensureBlock(std::uint32_t slot, const SceneObjects& objects);
    std::vector<NodeHistory> scene_;
    std::vector<NodeHistory> objectNodes_;
    std::vector<std::uint64_t> clusterWords_;
    std::vector<std::uint32_t> objectBase_;  // per slot: first record, or kInvalidIndex
    std::vector<std::uint32_t> objectClusterBase_;  // per slot: first word of its cluster bits
    std::vector<std::uint32_t> objectGen_;   // per slot: generation the block belongs to
    std::vector<std::uint32_t> objectModel_;
};

/// Bit `i` of a VisibilityHistory::clusterBits span.
inline bool clusterBit(std::span<const std::uint64_t> bits, std::uint32_t i) { return (bits[i >> 6] >> (i & 63)) & 1u; }
/// Sets bit `i` of a VisibilityHistory::clusterBits span to `value`.
inline void setClusterBit(std::span<std::uint64_t> bits, std::uint32_t i, bool value) {
    const std::uint64_t bit = std::uint64_t{1} << (i & 63);
    bits[i >> 6] = value ? bits[i >> 6] | bit : bits[i >> 6] & ~bit;
}

}  // namespace dyncull
