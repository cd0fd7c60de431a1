// retain_freed_memory() (see header).
#include "sim/core/memory.hpp"

#include <mutex>

#if defined(__GLIBC__)
#include <malloc.h>
#endif
#if defined(__unix__)
#include <sys/resource.h>
#endif

namespace drape::sim {

bool retain_freed_memory() {
  static std::once_flag once;
  static bool held = false;
  std::call_once(once, [] {
#if defined(__GLIBC__)
    // 32 MiB: the largest threshold glibc accepts on 64 bits (an allocation above it is mapped
    // and unmapped as before); trimming never (the top of the heap is kept); one heap for every
    // thread made from now on (a thread's own heap is unmapped once all of it is free, and a cook
    // ahead runs on a new thread: it would not find what the solver it replaces freed).
    held = mallopt(M_MMAP_THRESHOLD, 32 << 20) == 1 && mallopt(M_TRIM_THRESHOLD, -1) == 1 &&
           mallopt(M_ARENA_MAX, 1) == 1;
#endif
  });
  return held;
}

long process_page_faults() {
#if defined(__unix__)
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) == 0) return u.ru_minflt;
#endif
  return 0;
}

}  // namespace drape::sim
