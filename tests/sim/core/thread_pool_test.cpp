// sim/core/thread_pool.hpp: the thread pool runs every index exactly once, keeps each thread on its
// own end of the range, sleeps while it waits long for a worker, holds work made with a closed
// gate at its pause points, and element colouring gives colours whose elements share no vertex.
// The file name contains "thread": it also runs in the TSan build.
#include "sim/core/thread_pool.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "sim/core/stopwatch.hpp"

namespace drape::sim {
namespace {

TEST(ThreadPool, RunsEveryIndexExactlyOnce) {
  for (int threads : {1, 2, 3}) {
    ThreadPool pool(threads);
    pool.set_min_parallel(0);
    for (int n : {0, 1, 5, 255, 256, 10007}) {
      for (int rep = 0; rep < 20; ++rep) {
        std::vector<std::atomic<int>> hits(n);
        for (auto& h : hits) h.store(0);
        pool.parallel_for(n, [&](int b, int e, int w) {
          EXPECT_GE(w, 0);
          EXPECT_LT(w, threads);
          for (int i = b; i < e; ++i) hits[i].fetch_add(1);
        });
        for (int i = 0; i < n; ++i) ASSERT_EQ(hits[i].load(), 1) << threads << " " << n << " " << i;
      }
    }
  }
}

// Each half of the range is cut in chunks that halve toward the middle (1/2, 1/4, 1/8, 1/8 of
// the half with two threads), so that the threads, working from the two ends, meet on small
// ones: whoever finishes first waits for at most a sixteenth of the loop, not an eighth.
TEST(ThreadPool, ChunksHalveTowardTheMiddleOfTheRange) {
  ThreadPool pool(2);
  pool.set_min_parallel(0);
  std::vector<std::pair<int, int>> got;
  std::mutex m;
  pool.parallel_for(4096, [&](int b, int e, int) {
    std::lock_guard<std::mutex> lock(m);
    got.push_back({b, e});
  });
  std::sort(got.begin(), got.end());
  const std::vector<std::pair<int, int>> want{{0, 1024},    {1024, 1536}, {1536, 1792},
                                              {1792, 2048}, {2048, 2304}, {2304, 2560},
                                              {2560, 3072}, {3072, 4096}};
  EXPECT_EQ(got, want);
}

// On any thread count the chunks tile the range, none is more than a thread's share of its half,
// and threads claiming them as the pool does (even threads from the front, odd ones from the
// back, each the next chunk when it is free) finish a loop of equal items within 10 % of
// n / threads (halving from half of each half, as with two threads, would make the caller's
// first chunk a quarter of the loop on any count).
TEST(ThreadPool, ChunksLetEveryThreadShareOnManyThreads) {
  const int64_t n = 100000;
  for (int threads : {2, 3, 4, 6, 8, 12, 16}) {
    const int m = ThreadPool::chunks_for(threads);
    std::vector<int64_t> at(m + 1);
    for (int k = 0; k <= m; ++k) at[k] = ThreadPool::chunk_start(n, m, threads, k);
    ASSERT_EQ(at[0], 0);
    ASSERT_EQ(at[m], n);
    for (int k = 0; k < m; ++k) {
      ASSERT_LE(at[k], at[k + 1]) << threads << " threads, chunk " << k;
      EXPECT_LE(at[k + 1] - at[k], n / 2 / threads + 1) << threads << " threads, chunk " << k;
    }
    // Greedy claiming, one item one unit of time.
    std::vector<int64_t> free_at(threads, 0);
    int front = 0, back = m;
    while (front < back) {
      const int w =
          static_cast<int>(std::min_element(free_at.begin(), free_at.end()) - free_at.begin());
      const int k = w % 2 ? --back : front++;
      free_at[w] += at[k + 1] - at[k];
    }
    const int64_t span = *std::max_element(free_at.begin(), free_at.end());
    EXPECT_LE(span, 1.1 * n / threads) << threads << " threads";
  }
  // Two threads: the halving of ChunksHalveTowardTheMiddleOfTheRange.
  EXPECT_EQ(ThreadPool::chunk_start(4096, 8, 2, 1), 1024);
  EXPECT_EQ(ThreadPool::chunk_start(4096, 8, 2, 3), 1792);
}

// parallel_slots: every slot once, each on one thread.
TEST(ThreadPool, RunsEverySlotExactlyOnce) {
  for (int threads : {1, 2, 3}) {
    ThreadPool pool(threads);
    for (int rep = 0; rep < 200; ++rep) {
      std::vector<std::atomic<int>> hits(threads);
      for (auto& h : hits) h.store(0);
      pool.parallel_slots([&](int slot, int w) {
        EXPECT_GE(w, 0);
        EXPECT_LT(w, threads);
        hits[slot].fetch_add(1);
      });
      for (int k = 0; k < threads; ++k) ASSERT_EQ(hits[k].load(), 1) << threads << " " << k;
    }
  }
}

// With two threads the caller claims chunks from the front and the worker from the back, so
// whatever the timing, every index the caller ran comes before every index the worker ran: each
// thread keeps to one part of the range (of the mesh) from call to call.
TEST(ThreadPool, TwoThreadsKeepToTheirOwnEndOfTheRange) {
  ThreadPool pool(2);
  pool.set_min_parallel(0);
  int both = 0;
  for (int rep = 0; rep < 500; ++rep) {
    std::atomic<int> max0{-1}, min1{1 << 30};
    pool.parallel_for(4096, [&](int b, int e, int w) {
      volatile double sink = 0;  // some work, so that the worker gets a chance to join
      for (int i = b; i < e; ++i) sink = sink + i * 1e-3;
      if (w == 0) {
        int m = max0.load();
        while (e - 1 > m && !max0.compare_exchange_weak(m, e - 1)) {
        }
      } else {
        int m = min1.load();
        while (b < m && !min1.compare_exchange_weak(m, b)) {
        }
      }
    });
    if (max0.load() >= 0 && min1.load() < (1 << 30)) {
      ++both;
      ASSERT_LT(max0.load(), min1.load()) << "call " << rep;
    }
  }
  std::printf("calls in which both threads ran chunks: %d of 500\n", both);
}

// An idle worker spins briefly (so that it is awake for the next of a solver's many short
// loops) and then sleeps: between steps it does not burn a core.
TEST(ThreadPool, AnIdleWorkerSleepsAfterSpinning) {
  ThreadPool pool(2);
  pool.set_min_parallel(0);
  std::atomic<long> sum{0};
  for (int rep = 0; rep < 3; ++rep) {
    const long before = pool.idle_sleeps();
    pool.parallel_for(64, [&](int b, int e, int) { sum += e - b; });
    // The spin lasts 200 us; allow a loaded machine 5 s to schedule the worker.
    for (int ms = 0; ms < 5000 && pool.idle_sleeps() == before; ++ms)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    EXPECT_GT(pool.idle_sleeps(), before) << "rep " << rep;
  }
  EXPECT_EQ(sum.load(), 3 * 64);
}

// A caller whose worker runs a long chunk sleeps until it ends (a futex the chunk's end wakes)
// instead of spinning or yielding its core all along: a yield hands the core to any runnable
// thread, an idle-priority cook ahead's too, until the next scheduler tick.
TEST(ThreadPool, ACallerWaitingForALongChunkSleeps) {
  using Clock = std::chrono::steady_clock;
  ThreadPool pool(2);
  std::atomic<bool> worker_in{false};
  std::atomic<int> slots{0};
  double cpu0 = 0;
  Clock::time_point t0{};
  pool.parallel_slots([&](int slot, int w) {
    ++slots;
    if (w == 1) {
      worker_in = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(40));
      return;
    }
    if (slot != 0) return;  // (the worker came late: the caller ran its slot)
    // The caller's slot ends once the worker has taken its own (5 s for a loaded machine).
    const auto until = Clock::now() + std::chrono::seconds(5);
    while (!worker_in && Clock::now() < until) std::this_thread::yield();
    cpu0 = thread_cpu_ms();
    t0 = Clock::now();
  });
  ASSERT_TRUE(worker_in.load()) << "the worker never took its slot";
  const double cpu = thread_cpu_ms() - cpu0;
  const double wall = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  std::printf("the caller waited %.1f ms for the worker's chunk on %.2f ms of CPU\n", wall, cpu);
  EXPECT_EQ(slots.load(), 2);
  EXPECT_GT(wall, 20.0);
  EXPECT_LT(cpu, 0.25 * wall) << "the caller spun through the worker's chunk";
}

// Work kept off the ticks (TickGate): while the gate is closed neither a pool made with it nor a
// pause point of a thread given it gets past the next chunk or point; opened, all of it runs.
TEST(ThreadPool, AClosedGateHoldsTheWorkAtItsPausePoints) {
  TickGate gate;
  gate.close();
  std::atomic<int> chunks{0}, points{0};
  std::atomic<bool> finished{false};
  std::thread held([&] {
    set_thread_gate(&gate);
    ThreadPool pool(2, &gate);
    pool.set_min_parallel(0);
    pool.parallel_for(64, [&](int, int, int) { ++chunks; });
    for (int k = 0; k < 3; ++k) {
      pause_point();
      ++points;
    }
    finished = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(chunks.load(), 0) << "a chunk ran past the closed gate";
  EXPECT_EQ(points.load(), 0);
  gate.open();
  held.join();
  EXPECT_TRUE(finished.load());
  EXPECT_EQ(points.load(), 3);
  EXPECT_EQ(chunks.load(), 8) << "64 items in 4 chunks per thread";
}

TEST(Colouring, ElementsOfOneColourShareNoVertex) {
  // Triangles of a 20 x 20 grid (two per cell).
  const int g = 20, n = (g + 1) * (g + 1);
  std::vector<int> off{0}, verts;
  for (int j = 0; j < g; ++j)
    for (int i = 0; i < g; ++i) {
      const int a = j * (g + 1) + i, b = a + 1, c = a + g + 1, d = c + 1;
      for (int t : {a, b, d}) verts.push_back(t);
      off.push_back(static_cast<int>(verts.size()));
      for (int t : {a, d, c}) verts.push_back(t);
      off.push_back(static_cast<int>(verts.size()));
    }
  std::vector<int> order, col;
  const int colours = colour_elements(n, off, verts, order, col);
  ASSERT_EQ(static_cast<int>(col.size()), colours + 1);
  EXPECT_LE(colours, 13);  // a vertex is in at most 6 triangles: greedy needs at most 13
  std::vector<int> seen(order.size(), 0);
  for (int c = 0; c < colours; ++c) {
    std::set<int> used;
    for (int k = col[c]; k < col[c + 1]; ++k) {
      const int e = order[k];
      ++seen[e];
      for (int q = off[e]; q < off[e + 1]; ++q)
        EXPECT_TRUE(used.insert(verts[q]).second) << "colour " << c << " vertex " << verts[q];
    }
  }
  EXPECT_EQ(static_cast<int>(order.size()), 2 * g * g);
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int s) { return s == 1; }));
}

}  // namespace
}  // namespace drape::sim
