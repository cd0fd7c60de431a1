// The fixed-rate simulation thread: owns the World, applies queued commands at the start of each
// tick, steps the solver with a fixed substep count, and publishes immutable snapshots through
// lock-free triple buffers (a reader never blocks the simulation and the simulation never blocks a
// reader). A lock-step mode advances exactly N ticks on request, for deterministic tests/replay.
#pragma once

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "sim/runtime/world.hpp"

namespace drape::sim {

// Single-producer single-consumer triple buffer: the writer fills write_buffer() and publish()es
// it; the reader calls update() and reads read_buffer(). Neither side ever waits.
template <class T>
class TripleBuffer {
 public:
  T& write_buffer() { return slots_[back_]; }
  void publish() {
    back_ = static_cast<uint8_t>(middle_.exchange(back_ | kFresh, std::memory_order_acq_rel) & 3);
  }
  // Takes the newest published buffer if there is one; returns true when it changed.
  bool update() {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) return false;
    front_ = static_cast<uint8_t>(middle_.exchange(front_, std::memory_order_acq_rel) & 3);
    return true;
  }
  const T& read_buffer() const { return slots_[front_]; }

 private:
  static constexpr uint8_t kFresh = 4;
  std::array<T, 3> slots_{};
  std::atomic<uint8_t> middle_{1};
  uint8_t back_ = 0;   // writer-owned
  uint8_t front_ = 2;  // reader-owned
};

struct SimThreadOptions {
  double tick_rate_hz = 90;  // ticks per second of simulated (and, in real time, wall) time
  int substeps = 1;          // solver steps per tick, each of 1 / (tick_rate_hz * substeps)
  bool lock_step = false;    // ticks only when advance() asks for them
  int timing_window = 1024;  // step times kept for the percentiles
  uint64_t first_tick = 0;   // ticks counted as done at the start (a resumed session's)
};

class SimThread;

// A reader of snapshots: use each reader from one thread only (make one per consumer).
// latest() never blocks: it returns the newest snapshot published so far.
class SnapshotReader {
 public:
  SnapshotReader() = default;
  SnapshotReader(SnapshotReader&& o) noexcept { *this = std::move(o); }
  SnapshotReader& operator=(SnapshotReader&& o) noexcept;
  SnapshotReader(const SnapshotReader&) = delete;
  SnapshotReader& operator=(const SnapshotReader&) = delete;
  ~SnapshotReader() { release(); }

  bool valid() const { return slot_ != nullptr; }
  // The newest snapshot; the reference stays valid (and unchanged) until the next latest() call.
  const SceneSnapshot& latest();
  // A copy of the newest snapshot that the caller may keep and share.
  std::shared_ptr<const SceneSnapshot> latest_shared() {
    return std::make_shared<const SceneSnapshot>(latest());
  }
  void release();

 private:
  friend class SimThread;
  struct Slot {
    TripleBuffer<SceneSnapshot> buffer;
    std::atomic<bool> in_use{false};
  };
  explicit SnapshotReader(Slot* s) : slot_(s) {}
  Slot* slot_ = nullptr;
};

class SimThread {
 public:
  using Command = std::function<void(World&)>;
  static constexpr int kMaxReaders = 8;

  explicit SimThread(World world, SimThreadOptions opt = {});
  ~SimThread();
  SimThread(const SimThread&) = delete;
  SimThread& operator=(const SimThread&) = delete;

  // Starts the thread (real time: ticks at tick_rate_hz; lock step: waits for advance()).
  void start();
  // Stops and joins the thread (the current tick completes). Safe to call twice.
  void stop();
  bool running() const { return running_.load(); }

  // Queues a command; it runs on the simulation thread at the start of the next tick, in order.
  // Exceptions it throws are caught and reported in world.messages.
  void post(Command cmd);

  // Lock step: runs exactly n ticks and returns when they are done. On a started lock-step
  // thread the ticks run there; when the thread is not running they run on the caller's thread.
  void advance(int n);

  // A new snapshot reader (nullptr-like invalid reader when all kMaxReaders are taken).
  SnapshotReader make_reader();

  // Step-time percentiles and missed ticks; callable from any thread at any time.
  SimTiming timing() const;
  uint64_t ticks() const { return ticks_done_.load(); }
  double tick_dt() const { return 1.0 / opt_.tick_rate_hz; }
  const SimThreadOptions& options() const { return opt_; }

  // Direct access to the world: only while the thread is stopped, or in lock-step mode between
  // advance() calls (advance() returning orders the sim's writes before the caller's reads).
  World& world() { return world_; }

 private:
  void loop();
  void tick();
  void publish();
  void update_timing(double step_ms);

  World world_;
  SimThreadOptions opt_;
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_{false};

  std::mutex cmd_mu_;
  std::vector<Command> pending_;  // guarded by cmd_mu_
  std::vector<Command> running_cmds_;

  // Lock-step handshake.
  std::mutex step_mu_;
  std::condition_variable step_cv_, done_cv_;
  uint64_t requested_ = 0;  // lock step: ticks asked for so far; guarded by step_mu_
  std::atomic<uint64_t> ticks_done_{0};

  std::array<std::unique_ptr<SnapshotReader::Slot>, kMaxReaders> slots_;
  SceneSnapshot staging_;

  // Timing: written by the sim (try_lock, never waits), read by anyone.
  std::vector<double> step_ms_ring_, scratch_;
  size_t ring_pos_ = 0, ring_count_ = 0;
  uint64_t missed_ = 0;
  mutable std::mutex timing_mu_;
  SimTiming timing_;  // guarded by timing_mu_
  SimTiming local_timing_;
};

}  // namespace drape::sim
