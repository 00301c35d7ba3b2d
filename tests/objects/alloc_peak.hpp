// Peak heap bytes allocated through operator new while a PeakAllocation is alive.
// objects_tests replaces the global operator new/delete (alloc_peak.cpp) to count them;
// deterministic, unlike RSS, because it does not depend on the allocator's page reuse.
#pragma once

#include <cstddef>

namespace dyncull::test {

std::size_t liveHeapBytes();

class PeakAllocation {
public:
    PeakAllocation();
    PeakAllocation(const PeakAllocation&) = delete;
    PeakAllocation& operator=(const PeakAllocation&) = delete;
    /// Highest live operator-new bytes since construction, minus those live at construction.
    std::size_t peakBytes() const;
};

}  // namespace dyncull::test
