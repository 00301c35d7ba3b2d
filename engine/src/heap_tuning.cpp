// glibc's heap trimming against llvmpipe's per-draw allocations (heap_tuning.hpp).
#include "dyncull/engine/heap_tuning.hpp"

#include <cstdlib>  // defines __GLIBC__ where the C library is glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace dyncull {

bool keepFreedHeapMemory() {
#if defined(__GLIBC__)
    // Above any top-of-heap a frame frees, so no frame's frees are trimmed. Setting it also
    // fixes glibc's mmap threshold at its default (128 KiB), so blocks that big still come
    // from and go back to the system directly, and the kept heap does not grow with them.
    constexpr int kTrimThreshold = 1 << 30;
    return mallopt(M_TRIM_THRESHOLD, kTrimThreshold) == 1;
#else
    return false;
#endif
}

void returnFreedHeapMemory() {
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

}  // namespace dyncull
