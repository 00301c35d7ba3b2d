// Replaces the global operator new/delete of objects_tests with malloc/free plus a count
// of live bytes (malloc_usable_size) and their high-water mark. The array, nothrow and
// sized forms of the standard library forward to these.
#include "objects/alloc_peak.hpp"

#include <malloc.h>

#include <atomic>
#include <cstdlib>
#include <new>

namespace {

std::atomic<std::size_t> gLive{0};
std::atomic<std::size_t> gPeak{0};
std::atomic<std::size_t> gBase{0};

void* countedAlloc(std::size_t n) {
    void* p = std::malloc(n == 0 ? 1 : n);
    if (!p) throw std::bad_alloc();
    const std::size_t live = gLive.fetch_add(malloc_usable_size(p)) + malloc_usable_size(p);
    std::size_t peak = gPeak.load();
    while (live > peak && !gPeak.compare_exchange_weak(peak, live)) {
    }
    return p;
}

void countedFree(void* p) {
    if (!p) return;
    gLive.fetch_sub(malloc_usable_size(p));
    std::free(p);
}

}  // namespace

void* operator new(std::size_t n) { return countedAlloc(n); }
void operator delete(void* p) noexcept { countedFree(p); }
void operator delete(void* p, std::size_t) noexcept { countedFree(p); }

namespace dyncull::test {

std::size_t liveHeapBytes() { return gLive.load(); }

PeakAllocation::PeakAllocation() {
    gBase = gLive.load();
    gPeak = gBase.load();
}

std::size_t PeakAllocation::peakBytes() const { return gPeak.load() - gBase.load(); }

}  // namespace dyncull::test
