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
    // 16 MiB in blocks below the mmap threshold (fixed at 128 KiB by the setting): most
    // come from the heap's top, and freed last-first they merge back into it, which stays
    // (glibc's default trims a top above 128 KiB, or above twice the largest mapped block
    // freed so far, at the free that grows it).
    constexpr std::size_t kBlock = 96 * 1024, kBlocks = 16 * 1024 * 1024 / kBlock;
    std::vector<void*> blocks;
    for (std::size_t i = 0; i < kBlocks; ++i) blocks.push_back(std::malloc(kBlock));
    for (std::size_t i = kBlocks; i-- > 0;) std::free(blocks[i]);
    EXPECT_GE(mallinfo2().keepcost, 1u * 1024 * 1024);
#endif
}

}  // namespace
}  // namespace dyncull
