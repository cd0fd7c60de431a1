// Profiling of the frame loop and the sim's ticks (see profiling.hpp).
#include "xr_app/app/profiling.hpp"

#include <time.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace drape::app {

namespace {
double cpu_ms(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}
}  // namespace

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}
double thread_cpu_ms() {
  return cpu_ms(CLOCK_THREAD_CPUTIME_ID);
}
double process_cpu_ms() {
  return cpu_ms(CLOCK_PROCESS_CPUTIME_ID);
}

ThreadTimes thread_cpu_seconds() {
  ThreadTimes out;
  const double tick = static_cast<double>(sysconf(_SC_CLK_TCK));
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    std::ifstream f(e.path() / "stat");
    std::string line;
    if (!std::getline(f, line)) continue;
    const size_t open = line.find('('), close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    std::string tok;
    double ut = 0, st = 0;
    for (int field = 3; rest >> tok && field <= 15; ++field) {  // utime 14, stime 15
      if (field == 14) ut = std::atof(tok.c_str());
      if (field == 15) st = std::atof(tok.c_str());
    }
    out[std::atoi(e.path().filename().c_str())] = {line.substr(open + 1, close - open - 1),
                                                   (ut + st) / tick};
  }
  return out;
}

void FrameLaps::lap(const char* stage) {
  const auto now = Clock::now();
  laps_.emplace_back(stage, ms_between(t_, now));
  t_ = now;
}

void FrameLaps::add(const char* stage, double ms) {
  laps_.emplace_back(stage, ms);
}

void FrameLaps::record(std::map<std::string, std::vector<double>>& profile) const {
  for (const auto& [stage, ms] : laps_) profile[stage].push_back(ms);
}

void ThreadGroups::mark_before_sim() {
  for (const auto& [tid, t] : thread_cpu_seconds()) pre_sim_.insert(tid);
}

void ThreadGroups::mark_first_frame() {
  if (at_first_frame_.empty()) at_first_frame_ = thread_cpu_seconds();
}

std::map<std::string, double> ThreadGroups::seconds() const {
  std::map<std::string, double> out;
  for (const auto& [tid, t] : thread_cpu_seconds()) {
    const auto base = at_first_frame_.find(tid);
    const double sec = t.second - (base != at_first_frame_.end() ? base->second.second : 0.0);
    std::string group = "other (lavapipe queue, loader)";
    if (tid == getpid())
      group = "app frame loop (main)";
    else if (tid == sim_tid_.load())
      group = "sim thread";
    else if (t.first.rfind("llvmpipe", 0) == 0)
      group = "lavapipe rasterisers (" + t.first.substr(0, 8) + "-*)";
    else if (!pre_sim_.count(tid))
      group = "solver workers";
    out[group] += sec;
  }
  return out;
}

void TickProfile::tick_started() {
  std::lock_guard<std::mutex> lk(mu_);
  if (tick_starts_.size() < kMaxSamples) tick_starts_.push_back(Clock::now());
}

void TickProfile::step_started() {
  step_cpu0_ = thread_cpu_ms();
  step_t0_ = Clock::now();
}

void TickProfile::step_finished() {
  const auto t1 = Clock::now();
  const double cpu = thread_cpu_ms() - step_cpu0_;
  std::lock_guard<std::mutex> lk(mu_);
  if (step_wall_.size() < kMaxSamples) {
    step_wall_.push_back(ms_between(step_t0_, t1));
    step_cpu_.push_back(cpu);
  }
}

void TickProfile::after_step_finished() {
  step_end_ = Clock::now();
  step_done_ = true;
}

void TickProfile::snapshot_filled() {
  if (!step_done_) return;  // the snapshot made before the first tick
  step_done_ = false;
  std::lock_guard<std::mutex> lk(mu_);
  if (snapshot_wall_.size() < kMaxSamples)
    snapshot_wall_.push_back(ms_between(step_end_, Clock::now()));
}

void TickProfile::write(XrAppResult& r) {
  std::lock_guard<std::mutex> lk(mu_);
  if (tick_starts_.size() > 10) {
    std::vector<double> d;
    for (size_t i = 1; i < tick_starts_.size(); ++i)
      d.push_back(ms_between(tick_starts_[i - 1], tick_starts_[i]));
    double mean = 0, var = 0;
    for (double x : d) mean += x;
    mean /= static_cast<double>(d.size());
    for (double x : d) var += (x - mean) * (x - mean);
    r.sim_tick_jitter_ms = std::sqrt(var / static_cast<double>(d.size()));
    r.profile_ms["sim.tick_interval"] = d;
  }
  r.profile_ms["sim.step_wall"] = step_wall_;
  r.profile_ms["sim.step_cpu"] = step_cpu_;
  r.profile_ms["sim.snapshot_wall"] = snapshot_wall_;
}

}  // namespace drape::app
