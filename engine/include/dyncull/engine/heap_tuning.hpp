// A process-wide setting for programs that draw through a software GL (Mesa llvmpipe) on
// glibc. The engine never applies it itself: the heap belongs to the program that embeds it.
#pragma once

namespace dyncull {

/// Tells glibc's malloc to keep freed memory at the top of its heap instead of returning it
/// to the system (M_TRIM_THRESHOLD of 1 GiB). llvmpipe allocates and frees large blocks for
/// every draw it bins; with glibc's default trimming each frame gives those pages back and
/// faults them in again (on the bunny swarm of docs/BENCHMARKS.md, 16x the page faults and
/// 1.4x the frame time, with or without culling). The cost is that the heap stays at its
/// peak size. Call once, at start-up, before the first allocation that matters; harmless
/// where it does not apply (another C library: it does nothing and returns false). Returns
/// whether the setting was applied.
bool keepFreedHeapMemory();

/// Gives the heap's free pages back to the system (glibc's malloc_trim), wherever in the
/// heap they lie. For a program that keeps freed memory (keepFreedHeapMemory) and also
/// streams geometry: a leaf cache frees and allocates leaves of every size each frame, and
/// the free pages it leaves between live leaves would otherwise stay resident, so the
/// process outgrows its memory budget. Call between frames; it costs a pass over the heap.
/// Does nothing on another C library.
void returnFreedHeapMemory();

}  // namespace dyncull
