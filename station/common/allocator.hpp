// The process's heap, set for what the station does: fits, ADEV and exports allocate and free
// the same few large arrays (n bins x p terms) hundreds of times a second.
#pragma once

namespace station {

/// Keeps freed blocks up to 32 MiB in the heap for reuse instead of returning each to the kernel.
/// glibc serves a block above M_MMAP_THRESHOLD (128 KiB at start) with a fresh mmap and unmaps it
/// on free, so every n x p matrix of a 10^4-bin fit came back as zero pages to fault in again: a
/// third of the fit's time (docs/BENCHMARKS.md). mallopt(3): fixing M_MMAP_THRESHOLD at 32 MiB
/// and M_TRIM_THRESHOLD at 64 MiB keeps such blocks; larger ones (a week of 1 Hz samples) are
/// still mapped and returned. The cost: up to 64 MiB of freed heap the process keeps.
/// Call once, first thing in main().
void keep_freed_memory_for_reuse();

}  // namespace station
