// LeafCache (leaf_cache.hpp). One mutex guards the residency table; chunks are read and
// decoded outside it, so the render thread's hits never wait for the disk.
// Paper: Out-of-core interactive display of large meshes using an oriented bounding
// box-based hardware depth query, section 5 (LRU replacement of per-node memory).
#include "dyncull/streaming/leaf_cache.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

namespace dyncull {

struct LeafCache::State {
    GeometryFile file;
    std::vector<StreamedLeaf> leaves;  // the node file's table (chunk sizes, for the budget)
    std::size_t budget = 0;

    mutable std::mutex mutex;
    std::condition_variable wake, idle, loaded;
    struct Entry {
        std::unique_ptr<CompactLeaf> geometry;  // null: not resident
        std::uint32_t pins = 0;
        std::uint64_t used = 0;      // clock of the last acquire
        bool loading = false;        // being read by some thread
    };
    std::vector<Entry> entries;
    std::vector<std::uint32_t> wanted;  // the read-ahead list
    /// Per leaf: its position in the read-ahead list, kNotWanted if not in it. Eviction
    /// takes unwanted leaves first (least recently used first), then the furthest down.
    std::vector<std::uint32_t> rank;
    static constexpr std::uint32_t kNotWanted = 0xffffffffu;
    std::vector<std::uint32_t> residentList;  // leaves with geometry, in no order
    std::size_t next = 0;               // position in `wanted`
    std::uint64_t clock = 0;
    bool busy = false, stop = false;
    LeafCacheStats stats;
    std::thread loader;

    explicit State(GeometryFile f) : file(std::move(f)) {}

    /// Bytes a leaf will take once read: known from the node file without reading it.
    std::size_t bytesOf(std::uint32_t leaf) const { return compactLeafBytes(leaves[leaf]); }
    /// Evicts unpinned leaves until `bytes` more fit: first those not in the read-ahead
    /// list (least recently used first), then those furthest down it; read-ahead of the leaf
    /// at position `keepUpTo` never displaces one at or before it (a leaf needed now,
    /// `keepUpTo` < 0, may displace any). Lock held. false if they cannot be
    /// made to fit. A scan of the resident leaves: an eviction reads a chunk, which costs
    /// far more.
    bool makeRoom(std::size_t bytes, std::int64_t keepUpTo) {
        while (stats.residentBytes + bytes > budget) {
            std::size_t victim = SIZE_MAX;
            for (std::size_t k = 0; k < residentList.size(); ++k) {
                const std::uint32_t i = residentList[k];
                const Entry& e = entries[i];
                if (e.pins || (rank[i] != kNotWanted && std::int64_t{rank[i]} <= keepUpTo)) continue;
                if (victim == SIZE_MAX) {
                    victim = k;
                    continue;
                }
                const std::uint32_t v = residentList[victim];
                if (rank[i] > rank[v] || (rank[i] == rank[v] && e.used < entries[v].used)) victim = k;
            }
            if (victim == SIZE_MAX) return false;
            const std::uint32_t v = residentList[victim];
            stats.residentBytes -= entries[v].geometry->bytes();
            entries[v].geometry.reset();
            residentList[victim] = residentList.back();
            residentList.pop_back();
            ++stats.evictions;
        }
        return true;
    }
    /// The read-ahead of the leaf at list position `r` displaces only leaves further down
    /// than this: the list is re-ranked every frame and the leaves near the budget's edge
    /// trade places by a little each time, so a leaf is not read in place of one barely
    /// worse placed (each swap costs a read, and gains nothing unless the order was right).
    static std::int64_t keptAhead(std::uint32_t r) { return std::int64_t{r} + std::int64_t{r} / 4 + 256; }
    /// Reads a leaf outside the lock (the caller marked it loading, and unlocks around
    /// this), then publishes it if room allows. Lock held on entry and exit.
    Status load(std::unique_lock<std::mutex>& lock, std::uint32_t leaf, bool prefetching) {
        const std::size_t bytes = bytesOf(leaf);
        if (!makeRoom(bytes, prefetching ? keptAhead(rank[leaf]) : -1)) return Error{"leaf cache: the budget is full of leaves in use", ErrorCode::OutOfMemory};
        // Reserve the bytes before reading, so two threads cannot both count on them.
        stats.residentBytes += bytes;
        entries[leaf].loading = true;
        lock.unlock();
        auto compact = std::make_unique<CompactLeaf>();
        Status st;
        {
            Mesh decoded;
            std::vector<unsigned char> scratch;
            st = file.readCompact(leaf, *compact, decoded, scratch);
        }
        lock.lock();
        entries[leaf].loading = false;
        loaded.notify_all();
        if (!st) {
            stats.residentBytes -= bytes;
            return st;
        }
        entries[leaf].geometry = std::move(compact);
        residentList.push_back(leaf);
        ++stats.loads;
        if (prefetching) ++stats.prefetchLoads;
        stats.bytesRead += leaves[leaf].chunkBytes;
        stats.peakResidentBytes = std::max(stats.peakResidentBytes, stats.residentBytes);
        return {};
    }
    void run() {
        std::unique_lock lock(mutex);
        for (;;) {
            wake.wait(lock, [&] { return stop || next < wanted.size(); });
            if (stop) return;
            busy = true;
            const std::uint32_t leaf = wanted[next];
            ++next;
            Entry& e = entries[leaf];
            if (!e.geometry && !e.loading) {
                // Full of wanted leaves: nothing further down the list may displace them. (A
                // bad chunk is skipped here and reported when the leaf is acquired.)
                if (Status st = load(lock, leaf, true); !st && st.error().code == ErrorCode::OutOfMemory)
                    next = wanted.size();
            }
            busy = next < wanted.size();
            if (!busy) idle.notify_all();
        }
    }
};

LeafCache::LeafCache(std::unique_ptr<State> s) : s_(std::move(s)) {
    s_->loader = std::thread([st = s_.get()] { st->run(); });
}

LeafCache::~LeafCache() {
    {
        std::lock_guard lock(s_->mutex);
        s_->stop = true;
    }
    s_->wake.notify_all();
    s_->loader.join();
}

Expected<std::unique_ptr<LeafCache>> LeafCache::create(const StreamedModel& model, std::size_t budgetBytes) {
    auto file = GeometryFile::open(model);
    if (!file) return file.error();
    auto s = std::make_unique<State>(file.take());
    s->leaves = model.leaves;
    s->budget = budgetBytes;
    for (std::uint32_t i = 0; i < s->leaves.size(); ++i)
        if (s->bytesOf(i) > budgetBytes)
            return Error{"leaf " + std::to_string(i) + " of " + model.nodePath.string() + " needs " +
                             std::to_string((s->bytesOf(i) + (1 << 20) - 1) >> 20) + " MB, more than the whole budget of " +
                             std::to_string(budgetBytes >> 20) + " MB",
                         ErrorCode::BadArgument};
    s->entries.resize(s->leaves.size());
    s->rank.assign(s->leaves.size(), State::kNotWanted);
    return std::unique_ptr<LeafCache>(new LeafCache(std::move(s)));
}

void LeafCache::prefetch(std::span<const std::uint32_t> leaves) {
    {
        std::lock_guard lock(s_->mutex);
        for (std::uint32_t l : s_->wanted) s_->rank[l] = State::kNotWanted;
        s_->wanted.clear();
        for (std::uint32_t l : leaves)
            if (l < s_->entries.size() && s_->rank[l] == State::kNotWanted) {
                s_->rank[l] = static_cast<std::uint32_t>(s_->wanted.size());
                s_->wanted.push_back(l);
            }
        s_->next = 0;
    }
    s_->wake.notify_all();
}

Expected<const CompactLeaf*> LeafCache::acquire(std::uint32_t leaf) {
    State& s = *s_;
    if (leaf >= s.entries.size()) return Error{"leaf cache: no leaf " + std::to_string(leaf), ErrorCode::BadArgument};
    std::unique_lock lock(s.mutex);
    State::Entry& e = s.entries[leaf];
    e.used = ++s.clock;
    if (e.geometry) {
        ++s.stats.hits;
        ++e.pins;
        return e.geometry.get();
    }
    ++s.stats.misses;
    const auto t0 = std::chrono::steady_clock::now();
    // The loader thread is reading it: wait for that read rather than read it twice.
    s.loaded.wait(lock, [&] { return !e.loading; });
    Status st;
    if (!e.geometry) st = s.load(lock, leaf, false);
    s.stats.stallMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (!st) return st.error();
    ++e.pins;
    return e.geometry.get();
}

const CompactLeaf* LeafCache::tryAcquire(std::uint32_t leaf) {
    State& s = *s_;
    if (leaf >= s.entries.size()) return nullptr;
    std::lock_guard lock(s.mutex);
    State::Entry& e = s.entries[leaf];
    e.used = ++s.clock;
    if (!e.geometry) {
        ++s.stats.misses;
        return nullptr;
    }
    ++s.stats.hits;
    ++e.pins;
    return e.geometry.get();
}

void LeafCache::release(std::uint32_t leaf) {
    std::lock_guard lock(s_->mutex);
    if (leaf < s_->entries.size() && s_->entries[leaf].pins > 0) --s_->entries[leaf].pins;
}

bool LeafCache::resident(std::uint32_t leaf) const {
    std::lock_guard lock(s_->mutex);
    return leaf < s_->entries.size() && s_->entries[leaf].geometry != nullptr;
}

void LeafCache::drain() {
    std::unique_lock lock(s_->mutex);
    s_->idle.wait(lock, [&] { return s_->next >= s_->wanted.size() && !s_->busy; });
}

LeafCacheStats LeafCache::stats() const {
    std::lock_guard lock(s_->mutex);
    return s_->stats;
}

std::size_t LeafCache::budget() const { return s_->budget; }

}  // namespace dyncull
