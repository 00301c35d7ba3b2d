// Leaves of a streamed model resident in main memory under a byte budget: a loader thread
// reads ahead the leaves the caller predicts it will need, least-recently-used leaves make
// room, and a leaf needed now and not resident is read at once on the caller's thread
// (the stall the conservative mode pays). The paper's runtime memory management
// ("Out-of-core interactive display of large meshes using an oriented bounding box-based
// hardware depth query", section 5: chunks per node, LRU replacement), with the read-ahead
// it leaves out.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "dyncull/objects/error.hpp"
#include "dyncull/objects/mesh.hpp"
#include "dyncull/streaming/compact_leaf.hpp"
#include "dyncull/streaming/streamed_model.hpp"

namespace dyncull {

/// Counters since the cache was made (the caller differences them per frame).
struct LeafCacheStats {
    std::uint64_t loads = 0;         ///< leaves read from the geometry file (either thread)
    std::uint64_t prefetchLoads = 0; ///< of them, by the loader thread
    std::uint64_t evictions = 0;
    std::uint64_t bytesRead = 0;     ///< chunk bytes read from the geometry file
    std::uint64_t hits = 0;          ///< acquire() found the leaf resident
    std::uint64_t misses = 0;        ///< acquire() did not: read at once, or not at all (tryAcquire)
    double stallMs = 0.0;            ///< time acquire() spent reading on the caller's thread
    std::size_t residentBytes = 0;   ///< now (CompactLeaf::bytes of every resident leaf)
    std::size_t peakResidentBytes = 0;
};

/// Thread-safe. Leaves are handed out pinned: a pinned leaf is never evicted or changed
/// until release(), so the caller may read it (e.g. upload it) without holding a lock.
class LeafCache {
public:
    /// Opens `model`'s geometry file; `budgetBytes` bounds the bytes of the resident leaves
    /// (CompactLeaf: leaves are kept compact, and compactLeafBytes tells their size before
    /// they are read) at every moment. Error: a leaf alone larger than the budget (naming it and
    /// the budget it needs), or the file not opening.
    static Expected<std::unique_ptr<LeafCache>> create(const StreamedModel& model, std::size_t budgetBytes);
    ~LeafCache();
    LeafCache(const LeafCache&) = delete;
    LeafCache& operator=(const LeafCache&) = delete;

    /// Replaces the read-ahead list: the loader thread reads these leaves in order (most
    /// wanted first) while the budget allows, evicting leaves not in the list (least
    /// recently used first), then those further down it, never pinned ones; it stops at the
    /// first leaf that does not fit. A leaf needed now evicts in the same order. Returns at once.
    void prefetch(std::span<const std::uint32_t> leaves);
    /// The leaf's geometry (compact: expandLeaf decodes it), pinned; read at once on this
    /// thread when not resident (counted as a miss and stall time). Errors: the leaf's chunk
    /// is corrupt (naming the file and the leaf), or the budget is full of pinned leaves.
    Expected<const CompactLeaf*> acquire(std::uint32_t leaf);
    /// The leaf's geometry pinned if resident, else nullptr (a miss; nothing is read).
    const CompactLeaf* tryAcquire(std::uint32_t leaf);
    /// Unpins a leaf acquire() or tryAcquire() returned.
    void release(std::uint32_t leaf);
    /// Whether the leaf is resident now (no pin, no counting).
    bool resident(std::uint32_t leaf) const;
    /// Waits until the loader thread has nothing left to do that fits (tests, and `bench`
    /// runs that preload). 
    void drain();

    LeafCacheStats stats() const;
    std::size_t budget() const;

private:
    struct State;
    explicit LeafCache(std::unique_ptr<State> s);
    std::unique_ptr<State> s_;
};

}  // namespace dyncull
