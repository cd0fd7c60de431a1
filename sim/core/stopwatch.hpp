// Milliseconds of wall time since a steady_clock time point (the timings solvers and tools
// report in their stats), and of the calling thread's CPU time.
#pragma once

#include <time.h>

#include <chrono>

namespace drape::sim {

inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The calling thread's CPU time (ms): on a shared machine wall time also counts other threads'.
inline double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

}  // namespace drape::sim
