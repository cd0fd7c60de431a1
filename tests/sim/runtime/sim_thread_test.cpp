// Tests of sim/runtime/sim_thread.cpp: lock-step determinism, command timing, non-blocking
// snapshots, timing statistics, exceptions reported instead of escaping.
#include "sim/runtime/sim_thread.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <thread>

#include "sim/solvers/verlet_solver.hpp"

using namespace drape::sim;

static World make_world() {
  World w;
  w.cloth = make_panel(PanelSpec{0.1, 0.1, 0.02}, FabricParams{});
  place_spread(w.cloth, Vec3(-0.05, 0.3, -0.05), Vec3::UnitX(), Vec3::UnitZ());
  w.cloth.state.flags[0] |= kFlagPinned;
  w.cloth.relump_masses();
  w.scene.spheres.push_back({Vec3(0, 0.2, 0), 0.05});
  w.solver = std::make_unique<VerletSolver>();
  return w;
}

TEST(SimThread, LockStepDeterministic) {
  uint64_t hashes[2];
  for (int run = 0; run < 2; ++run) {
    SimThreadOptions o;
    o.lock_step = true;
    SimThread t(make_world(), o);
    t.start();
    t.advance(10);
    t.post([](World& w) { w.cloth.state.flags[1] |= kFlagPinned; });
    t.advance(10);
    EXPECT_EQ(t.ticks(), 20u);
    hashes[run] = state_hash(t.world().cloth);
    t.stop();
  }
  std::printf("hashes %016llx %016llx\n", (unsigned long long)hashes[0],
              (unsigned long long)hashes[1]);
  EXPECT_EQ(hashes[0], hashes[1]);
  // Inline (no thread) gives the same state as the threaded lock step.
  SimThreadOptions o;
  o.lock_step = true;
  SimThread inl(make_world(), o);
  inl.advance(10);
  inl.post([](World& w) { w.cloth.state.flags[1] |= kFlagPinned; });
  inl.advance(10);
  EXPECT_EQ(state_hash(inl.world().cloth), hashes[0]);
}

TEST(SimThread, CommandsRunAtStartOfNextTick) {
  SimThreadOptions o;
  o.lock_step = true;
  SimThread t(make_world(), o);
  SnapshotReader reader = t.make_reader();
  t.start();
  t.advance(3);
  std::vector<double> seen_time;
  t.post([&](World& w) { seen_time.push_back(w.cloth.state.time); });
  t.post([&](World& w) { seen_time.push_back(-w.cloth.state.time); });  // FIFO
  EXPECT_TRUE(seen_time.empty());
  t.advance(1);
  ASSERT_EQ(seen_time.size(), 2u);
  EXPECT_NEAR(seen_time[0], 3.0 / 90, 1e-9);  // before the 4th tick's step
  EXPECT_NEAR(seen_time[1], -3.0 / 90, 1e-9);
  const SceneSnapshot& s = reader.latest();
  EXPECT_EQ(s.tick, 4u);
  EXPECT_NEAR(s.sim_time, 4.0 / 90, 1e-9);
  EXPECT_EQ(s.positions.size(), static_cast<size_t>(t.world().cloth.num_vertices()));
  EXPECT_EQ(s.pins.size(), 1u);
  EXPECT_EQ(s.solver, "verlet-baseline");
  t.stop();
}

// Deterministic (no wall-clock thresholds): the sim thread is held inside a before_step hook on
// its 3rd tick; while it is blocked a reader still gets the newest snapshot (tick 2) at once, as
// often as it likes, and the timing stats are readable. The only durations used are sleeps, which
// are lower bounds whatever the load: 1 ms in each of the first two ticks, >= 50 ms blocked.
TEST(SimThread, ReaderNeverBlocksAndTimingReported) {
  World w = make_world();
  const size_t nv = static_cast<size_t>(w.cloth.num_vertices());
  std::promise<void> blocked, release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<int> calls{0};
  std::atomic<bool> command_ran{false};
  w.before_step = [&blocked, released, &calls](World&, double) {
    const int k = ++calls;
    if (k <= 2) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (k == 3) {
      blocked.set_value();
      released.wait();
    }
  };
  SimThread t(std::move(w));  // real time, 90 Hz
  SnapshotReader reader = t.make_reader();
  // Releases the sim thread on every exit path (a failed ASSERT must not leave it blocked while
  // the SimThread destructor joins it).
  struct Releaser {
    std::promise<void>& p;
    bool done = false;
    void operator()() {
      if (!done) p.set_value();
      done = true;
    }
    ~Releaser() { (*this)(); }
  } releaser{release};
  t.start();
  blocked.get_future().wait();  // the sim thread is now stuck in tick 3

  t.post([&command_ran](World&) { command_ran = true; });
  int reads = 0;
  for (int r = 0; r < 1000; ++r) {
    const SceneSnapshot& s = reader.latest();
    ASSERT_EQ(s.tick, 2u);
    ASSERT_NEAR(s.sim_time, 2.0 / 90, 1e-12);
    ASSERT_EQ(s.positions.size(), nv);
    ASSERT_EQ(s.timing.ticks, 2u);
    ASSERT_GE(s.timing.step_ms_p50, 1.0);  // both ticks slept 1 ms
    const SimTiming tm = t.timing();       // never waits for the (blocked) sim either
    ASSERT_EQ(tm.ticks, 2u);
    ASSERT_GE(tm.step_ms_p50, 1.0);
    ++reads;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(reader.latest().tick, 2u);  // still blocked, still readable
  EXPECT_FALSE(command_ran.load());     // commands wait for the next tick
  releaser();

  uint64_t last_tick = 0;
  while (last_tick < 5) {  // the thread runs on: terminates without a time limit
    const uint64_t tick = reader.latest().tick;
    EXPECT_GE(tick, last_tick);  // snapshots never go back in time
    last_tick = tick;
    std::this_thread::yield();
  }
  t.stop();
  EXPECT_TRUE(command_ran.load());
  const SimTiming tm = t.timing();
  std::printf(
      "%d reads while the sim was blocked; ticks %llu, p50 %.2f ms, p99 %.2f ms, max %.2f "
      "ms, missed %llu\n",
      reads, (unsigned long long)tm.ticks, tm.step_ms_p50, tm.step_ms_p99, tm.step_ms_max,
      (unsigned long long)tm.missed_ticks);
  EXPECT_EQ(tm.ticks, t.ticks());
  EXPECT_GE(tm.ticks, 5u);
  EXPECT_GE(tm.step_ms_max, 50.0);  // the blocked tick
  EXPECT_GE(tm.step_ms_max, tm.step_ms_p99);
  EXPECT_GE(tm.step_ms_p99, tm.step_ms_p95);
  EXPECT_GE(tm.step_ms_p95, tm.step_ms_p50);
  // >= 50 ms blocked at 90 Hz: at least 3 deadlines passed before the next tick could start.
  EXPECT_GE(tm.missed_ticks, 3u);
}

TEST(SimThread, ExceptionsAreReportedNotThrown) {
  SimThreadOptions o;
  o.lock_step = true;
  World w = make_world();
  int after = 0;
  w.before_step = [](World&, double) { throw std::runtime_error("hook broke"); };
  w.after_step = [&](World&, double) { ++after; };
  SimThread t(std::move(w), o);
  t.start();
  t.post([](World&) { throw std::runtime_error("bad command"); });
  t.advance(2);
  t.stop();
  const auto& msgs = t.world().messages;
  ASSERT_GE(msgs.size(), 3u);
  EXPECT_EQ(msgs[0], "command failed: bad command");
  EXPECT_EQ(msgs[1], "simulation step failed: hook broke");
  EXPECT_EQ(after, 0);  // the step threw before it
}

TEST(SimThread, ManyReadersAndTripleBuffer) {
  TripleBuffer<int> tb;
  tb.write_buffer() = 1;
  tb.publish();
  tb.write_buffer() = 2;
  tb.publish();
  EXPECT_TRUE(tb.update());
  EXPECT_EQ(tb.read_buffer(), 2);  // the newest wins
  EXPECT_FALSE(tb.update());
  EXPECT_EQ(tb.read_buffer(), 2);
  SimThread t(make_world());
  std::vector<SnapshotReader> readers;
  for (int i = 0; i < SimThread::kMaxReaders; ++i) readers.push_back(t.make_reader());
  EXPECT_FALSE(t.make_reader().valid());
  readers.pop_back();
  EXPECT_TRUE(t.make_reader().valid());
  EXPECT_EQ(readers[0].latest().positions.size(), 36u);  // filled at once while stopped
}
