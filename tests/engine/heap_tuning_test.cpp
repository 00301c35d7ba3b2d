// keepFreedHeapMemory: applied on glibc, and freed memory at the heap's top then stays.
#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>

#include "dyncull/engine/heap_tuning.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace dyncull {
namespace {

TEST(HeapTuning, FreedTopOfHeapIsKept) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    GTEST_SKIP() << "a sanitizer's allocator replaces glibc's and ignores mallopt";
#elif !defined(__GLIBC__)
    EXPECT_FALSE(keepFreedHeapMemory());
#else
    ASSERT_TRUE(keepFreedHeapMemory());
    // 64 MiB in blocks below the mmap threshold (fixed at 128 KiB by the setting): more than
    // the holes an earlier test may have left, so the heap's top grows to hold them. Freed,
    // they merge back into the top, which glibc's default would trim (it trims a top above
    // 128 KiB, or above twice the largest mapped block freed so far); the setting keeps it.
    constexpr std::size_t kBlock = 96 * 1024, kBlocks = 64 * 1024 * 1024 / kBlock;
    const std::size_t before = mallinfo2().arena;
    std::vector<void*> blocks;
    blocks.reserve(kBlocks);
    for (std::size_t i = 0; i < kBlocks; ++i) blocks.push_back(std::malloc(kBlock));
    const std::size_t peak = mallinfo2().arena;
    for (std::size_t i = kBlocks; i-- > 0;) std::free(blocks[i]);
    EXPECT_GT(peak, before) << "the blocks did not grow the heap";
    EXPECT_EQ(mallinfo2().arena, peak) << "the freed top was trimmed";
#endif
}

}  // namespace
}  // namespace dyncull
