// Fixed-rate simulation thread: command queue in, triple-buffered snapshots out, own timing.
#include "sim/runtime/sim_thread.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>

namespace drape::sim {

using Clock = std::chrono::steady_clock;

SnapshotReader& SnapshotReader::operator=(SnapshotReader&& o) noexcept {
  if (this != &o) {
    release();
    slot_ = o.slot_;
    o.slot_ = nullptr;
  }
  return *this;
}

const SceneSnapshot& SnapshotReader::latest() {
  static const SceneSnapshot kEmpty;
  if (!slot_) return kEmpty;
  slot_->buffer.update();
  return slot_->buffer.read_buffer();
}

void SnapshotReader::release() {
  if (slot_) slot_->in_use.store(false, std::memory_order_release);
  slot_ = nullptr;
}

SimThread::SimThread(World world, SimThreadOptions opt) : world_(std::move(world)), opt_(opt) {
  if (!(opt_.tick_rate_hz > 0)) opt_.tick_rate_hz = 90;
  opt_.substeps = std::max(1, opt_.substeps);
  opt_.timing_window = std::max(8, opt_.timing_window);
  for (auto& s : slots_) s = std::make_unique<SnapshotReader::Slot>();
  step_ms_ring_.assign(opt_.timing_window, 0.0);
  scratch_.reserve(opt_.timing_window);
  local_timing_.tick_rate_hz = opt_.tick_rate_hz;
  local_timing_.substeps = opt_.substeps;
  timing_ = local_timing_;
  ticks_done_.store(opt_.first_tick);
  requested_ = opt_.first_tick;
}

SimThread::~SimThread() {
  stop();
}

void SimThread::start() {
  if (running_.load()) return;
  stop_.store(false);
  running_.store(true);
  thread_ = std::thread([this] { loop(); });
}

void SimThread::stop() {
  if (!running_.load()) return;
  {
    std::lock_guard<std::mutex> lk(step_mu_);
    stop_.store(true);
  }
  step_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  running_.store(false);
  done_cv_.notify_all();
}

void SimThread::post(Command cmd) {
  std::lock_guard<std::mutex> lk(cmd_mu_);
  pending_.push_back(std::move(cmd));
}

void SimThread::advance(int n) {
  if (n <= 0) return;
  if (!running_.load()) {
    for (int i = 0; i < n; ++i) tick();
    return;
  }
  if (!opt_.lock_step) return;  // real time: the clock drives the ticks
  std::unique_lock<std::mutex> lk(step_mu_);
  requested_ = std::max(requested_, ticks_done_.load()) + static_cast<uint64_t>(n);
  const uint64_t target = requested_;
  step_cv_.notify_all();
  done_cv_.wait(lk, [&] { return ticks_done_.load() >= target || stop_.load(); });
}

SnapshotReader SimThread::make_reader() {
  for (auto& s : slots_) {
    bool expected = false;
    if (s->in_use.compare_exchange_strong(expected, true, std::memory_order_acq_rel)) {
      if (!running_.load()) {
        // Nobody else writes while stopped: give the new reader the current state at once.
        fill_snapshot(world_, s->buffer.write_buffer());
        s->buffer.write_buffer().tick = ticks_done_.load();
        s->buffer.publish();
      }
      return SnapshotReader(s.get());
    }
  }
  return SnapshotReader();
}

SimTiming SimThread::timing() const {
  std::lock_guard<std::mutex> lk(timing_mu_);
  return timing_;
}

void SimThread::loop() {
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / opt_.tick_rate_hz));
  auto next = Clock::now();
  while (!stop_.load()) {
    if (opt_.lock_step) {
      std::unique_lock<std::mutex> lk(step_mu_);
      step_cv_.wait(lk, [&] { return ticks_done_.load() < requested_ || stop_.load(); });
      if (stop_.load()) break;
      lk.unlock();
      tick();
      lk.lock();  // orders the tick's writes before the waiting caller's reads
      lk.unlock();
      done_cv_.notify_all();
      continue;
    }
    const auto now = Clock::now();
    if (now < next) {
      std::unique_lock<std::mutex> lk(step_mu_);
      step_cv_.wait_until(lk, next, [&] { return stop_.load(); });
      if (stop_.load()) break;
    } else if (now - next > period) {
      // Deadlines passed before this tick could start: count them, do not try to catch up.
      missed_ += static_cast<uint64_t>((now - next) / period);
      next = now;
    }
    tick();
    next += period;
  }
}

void SimThread::tick() {
  const auto t0 = Clock::now();
  {
    std::lock_guard<std::mutex> lk(cmd_mu_);
    running_cmds_.swap(pending_);
  }
  world_.tick = ticks_done_.load();
  if (world_.at_tick_start) {
    try {
      world_.at_tick_start(world_);
    } catch (const std::exception& e) {
      world_.report(std::string("tick start failed: ") + e.what());
    }
  }
  for (auto& cmd : running_cmds_) {
    try {
      cmd(world_);
    } catch (const std::exception& e) {
      world_.report(std::string("command failed: ") + e.what());
    } catch (...) {
      world_.report("command failed: unknown exception");
    }
  }
  running_cmds_.clear();

  const double h = 1.0 / (opt_.tick_rate_hz * opt_.substeps);
  for (int s = 0; s < opt_.substeps; ++s) {
    try {
      if (world_.before_step) world_.before_step(world_, h);
      if (!world_.paused && world_.solver) {
        world_.last_step = world_.solver->step(world_.cloth, world_.scene, h);
        if (world_.last_step.diverged) {
          world_.report("solver " + world_.solver->name() +
                        " diverged at t = " + std::to_string(world_.cloth.state.time) +
                        (world_.last_step.retries ? " (rolled back)" : ""));
        }
      }
      if (world_.after_step) world_.after_step(world_, h);
    } catch (const std::exception& e) {
      world_.report(std::string("simulation step failed: ") + e.what());
    } catch (...) {
      world_.report("simulation step failed: unknown exception");
    }
  }
  const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  const uint64_t tick_no = ticks_done_.load() + 1;
  update_timing(ms);
  local_timing_.ticks = tick_no;
  publish();
  ticks_done_.store(tick_no);
}

void SimThread::update_timing(double step_ms) {
  step_ms_ring_[ring_pos_] = step_ms;
  ring_pos_ = (ring_pos_ + 1) % step_ms_ring_.size();
  ring_count_ = std::min(ring_count_ + 1, step_ms_ring_.size());
  scratch_.assign(step_ms_ring_.begin(), step_ms_ring_.begin() + ring_count_);
  std::sort(scratch_.begin(), scratch_.end());
  auto pct = [&](double p) {
    const size_t i = static_cast<size_t>(std::ceil(p * ring_count_)) - 1;
    return scratch_[std::min(i, ring_count_ - 1)];
  };
  local_timing_.step_ms_p50 = pct(0.50);
  local_timing_.step_ms_p95 = pct(0.95);
  local_timing_.step_ms_p99 = pct(0.99);
  local_timing_.step_ms_max = scratch_.back();
  local_timing_.missed_ticks = missed_;
  local_timing_.ticks = ticks_done_.load() + 1;
  if (timing_mu_.try_lock()) {  // never wait for a reader: skip this update if one is copying
    timing_ = local_timing_;
    timing_mu_.unlock();
  }
}

void SimThread::publish() {
  try {
    fill_snapshot(world_, staging_);
  } catch (const std::exception& e) {
    world_.report(std::string("snapshot decoration failed: ") + e.what());
  } catch (...) {
    world_.report("snapshot decoration failed: unknown exception");
  }
  staging_.tick = ticks_done_.load() + 1;
  staging_.timing = local_timing_;
  for (auto& s : slots_) {
    if (!s->in_use.load(std::memory_order_acquire)) continue;
    s->buffer.write_buffer() = staging_;
    s->buffer.publish();
  }
}

}  // namespace drape::sim
