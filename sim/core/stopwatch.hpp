// Milliseconds of wall time since a steady_clock time point (the timings solvers and tools
// report in their stats).
#pragma once

#include <chrono>

namespace drape::sim {

inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace drape::sim
