// The process's heap for the solvers' cooks: freed memory kept for the next allocation rather
// than returned to the kernel.
//
// A cook (the first step on a topology, and the re-cook after a cut, slit or sew) builds arrays
// of tens of MB at 128^2 that the cook before it freed. glibc serves an allocation over its mmap
// threshold (128 KiB, growing with what was freed) with fresh pages and returns freed ones at
// once, so each cook touches its arrays' pages for the first time: a page fault per 4 KiB,
// ~2 us each on a virtual machine (13 of a cut's 33 ms cook at 128^2: 6 100 faults). With the
// threshold at its largest (32 MiB), no trimming and one heap for all threads, the arrays come
// from the heap, and a cook reuses what the previous one freed (15 faults), also on a thread of
// its own (a cook ahead's worker: 0-780 faults once the process has cooked a cut before).
#pragma once

namespace drape::sim {

// Keeps freed memory in the process's heap, one heap for the threads made from now on (glibc:
// mallopt M_MMAP_THRESHOLD, M_TRIM_THRESHOLD, M_ARENA_MAX); the process's resident memory then
// stays at its peak. Once per process (later calls do nothing); a no-op where the C library has
// no such settings (a sanitizer's allocator). True when the settings hold.
bool retain_freed_memory();

// The page faults the process has taken so far (minor: first touches of fresh memory), every
// thread's; 0 where the system does not count them.
long process_page_faults();

}  // namespace drape::sim
