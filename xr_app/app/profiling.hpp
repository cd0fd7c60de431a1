// Profiling of the frame loop and the sim's ticks: wall and CPU clocks, the stage laps of a
// frame, CPU seconds per group of threads (/proc/self/task) and the sim tick's cost and jitter.
#pragma once

#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "xr_app/app/xr_app.hpp"

namespace drape::app {

using Clock = std::chrono::steady_clock;
double ms_between(Clock::time_point a, Clock::time_point b);
double thread_cpu_ms();   // the calling thread's CPU time
double process_cpu_ms();  // all threads: the app, lavapipe's, the sim's

// CPU seconds (user + system) of each live thread of this process: tid -> (name, seconds).
using ThreadTimes = std::map<int, std::pair<std::string, double>>;
ThreadTimes thread_cpu_seconds();

// The stage laps of one frame: wall ms since the previous lap, added to the profile at the end.
class FrameLaps {
 public:
  explicit FrameLaps(Clock::time_point start) : t_(start) {}
  void lap(const char* stage);             // the time since the previous lap
  void add(const char* stage, double ms);  // a figure measured elsewhere (the renderer's)
  void record(std::map<std::string, std::vector<double>>& profile) const;

 private:
  Clock::time_point t_;
  std::vector<std::pair<const char*, double>> laps_;
};

// CPU seconds per group of threads from the first frame to the end of the run: the frame loop,
// the sim thread, the solver's workers (threads made with the sim), lavapipe's rasterisers and
// the rest (lavapipe's queue thread, the loader, ...).
class ThreadGroups {
 public:
  void mark_before_sim();   // the threads alive before the sim and its solver are made
  void mark_first_frame();  // start-up excluded; only the first call counts
  void set_sim_thread(int tid) { sim_tid_.store(tid, std::memory_order_relaxed); }
  std::map<std::string, double> seconds() const;  // while the threads still live

 private:
  std::atomic<int> sim_tid_{0};
  std::set<int> pre_sim_;
  ThreadTimes at_first_frame_;
};

// The sim tick's cost, written on the thread running the ticks: the solver step (wall, CPU),
// fill_snapshot (wall) and, for a free-running sim, the tick start times (its clock's jitter).
class TickProfile {
 public:
  void tick_started();   // before the step hooks
  void step_started();   // the solver step begins
  void step_finished();  // the solver step ends
  void after_step_finished();
  void snapshot_filled();
  // sim_tick_jitter_ms and the "sim.*" profile rows.
  void write(XrAppResult& r);

 private:
  static constexpr size_t kMaxSamples = 100000;
  std::mutex mu_;
  std::vector<Clock::time_point> tick_starts_;
  std::vector<double> step_wall_, step_cpu_, snapshot_wall_;  // guarded by mu_
  Clock::time_point step_t0_{}, step_end_{};
  double step_cpu0_ = 0;
  bool step_done_ = false;
};

}  // namespace drape::app
