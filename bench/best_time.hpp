// The best of `reps` wall times of a call, in milliseconds (benchmarks of short calls: the
// least disturbed run is the one that measures the call).
#pragma once

#include <algorithm>
#include <chrono>

namespace drape::bench {

template <class F>
double best_ms(int reps, F&& f) {
  double best = 1e300;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(
        best,
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

}  // namespace drape::bench
