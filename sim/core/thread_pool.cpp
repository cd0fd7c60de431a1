#include "sim/core/thread_pool.hpp"

#if defined(__linux__)
#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include <algorithm>
#include <chrono>
#include <cmath>

namespace drape::sim {

namespace {
// Sleeps while `a` holds `old` (or until a wake), and wakes every such sleeper: a futex alone,
// without the spins and yields std::atomic::wait makes first (a yield hands the core to any
// runnable thread, an idle-priority one too, until the next scheduler tick).
void sleep_while(const std::atomic<int>& a, int old) {
#if defined(__linux__)
  static_assert(sizeof(std::atomic<int>) == sizeof(int));
  syscall(SYS_futex, reinterpret_cast<const int*>(&a), FUTEX_WAIT_PRIVATE, old, nullptr, nullptr,
          0);
#else
  a.wait(old, std::memory_order_acquire);
#endif
}
void wake_all(std::atomic<int>& a) {
#if defined(__linux__)
  syscall(SYS_futex, reinterpret_cast<int*>(&a), FUTEX_WAKE_PRIVATE, INT32_MAX, nullptr, nullptr,
          0);
#else
  a.notify_all();
#endif
}

// Lists the items colour by colour (CSR: offsets per colour, items in index order).
void bucket_by_colour(const std::vector<int>& colour, int colours, std::vector<int>& offsets,
                      std::vector<int>& items) {
  const int n = static_cast<int>(colour.size());
  offsets.assign(colours + 1, 0);
  for (int i = 0; i < n; ++i) ++offsets[colour[i] + 1];
  for (int c = 0; c < colours; ++c) offsets[c + 1] += offsets[c];
  items.assign(n, 0);
  std::vector<int> fill(offsets.begin(), offsets.end() - 1);
  for (int i = 0; i < n; ++i) items[fill[colour[i]]++] = i;
}
}  // namespace

int greedy_colouring(const std::vector<int>& offsets, const std::vector<int>& nbrs,
                     std::vector<int>& colour_of, std::vector<int>& colour_offsets,
                     std::vector<int>& colour_items) {
  const int n = static_cast<int>(offsets.size()) - 1;
  colour_of.assign(std::max(n, 0), -1);
  std::vector<int> mark;
  int colours = 0;
  // Largest degree first gives fewer colours on irregular meshes.
  std::vector<int> order(std::max(n, 0));
  for (int i = 0; i < n; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return offsets[a + 1] - offsets[a] > offsets[b + 1] - offsets[b];
  });
  for (int i : order) {
    mark.assign(colours + 1, 0);
    for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
      const int c = colour_of[nbrs[k]];
      if (c >= 0) mark[c] = 1;
    }
    int c = 0;
    while (mark[c]) ++c;
    colour_of[i] = c;
    colours = std::max(colours, c + 1);
  }
  bucket_by_colour(colour_of, colours, colour_offsets, colour_items);
  return colours;
}

int colour_elements(int num_vertices, const std::vector<int>& elem_offsets,
                    const std::vector<int>& elem_verts, std::vector<int>& order,
                    std::vector<int>& colour_offsets) {
  const int m = static_cast<int>(elem_offsets.size()) - 1;
  // Per vertex, the colours already used by its elements (64 per word, grown on demand).
  std::vector<uint64_t> used(static_cast<size_t>(std::max(num_vertices, 0)), 0);
  std::vector<std::vector<uint64_t>> more;  // words beyond the first, rarely needed
  std::vector<int> colour(std::max(m, 0), 0);
  int colours = 0;
  for (int e = 0; e < m; ++e) {
    int c = 0;
    for (int word = 0;; ++word) {
      uint64_t taken = 0;
      for (int k = elem_offsets[e]; k < elem_offsets[e + 1]; ++k) {
        const int v = elem_verts[k];
        if (word == 0)
          taken |= used[v];
        else if (static_cast<int>(more.size()) >= word && !more[word - 1].empty())
          taken |= more[word - 1][v];
      }
      if (taken != ~uint64_t{0}) {
        c = 64 * word + __builtin_ctzll(~taken);
        break;
      }
    }
    const int word = c / 64;
    if (word > 0) {
      if (static_cast<int>(more.size()) < word) more.resize(word);
      if (more[word - 1].empty()) more[word - 1].assign(used.size(), 0);
    }
    for (int k = elem_offsets[e]; k < elem_offsets[e + 1]; ++k) {
      const int v = elem_verts[k];
      (word == 0 ? used[v] : more[word - 1][v]) |= uint64_t{1} << (c % 64);
    }
    colour[e] = c;
    colours = std::max(colours, c + 1);
  }
  bucket_by_colour(colour, colours, colour_offsets, order);
  return colours;
}

ThreadPool::ThreadPool(int threads, const TickGate* gate)
    : threads_(std::max(1, threads)), gate_(gate) {
  for (int w = 1; w < threads_; ++w)
    workers_.emplace_back([this, w] {
      set_thread_gate(gate_);
      worker_main(w);
    });
}

ThreadPool::~ThreadPool() {
  stop_.store(true);
  generation_.fetch_add(1);
  generation_.notify_all();
  for (auto& t : workers_) t.join();
}

// Chunks are claimed from one counter that also carries the generation (high 32 bits): the
// caller claims chunks too, so when a worker is not scheduled (few cores shared with the
// renderer's threads) the caller simply runs every chunk itself and waits only for chunks a
// worker has actually claimed and is running. A late worker cannot claim a chunk of a newer
// generation with a stale task: its compare-exchange fails on the generation bits. The low 32
// bits hold the next chunk from the front (bits 0-15) and the end of the unclaimed ones (bits
// 16-31): the caller and even-numbered workers take chunks from the front, odd-numbered ones
// from the back, so with two threads each keeps to the same part of the range (the same part
// of the mesh) from one call to the next instead of trading cache lines.
void ThreadPool::run(int n, Thunk thunk, void* ctx, int chunks) {
  thunk_ = thunk;
  ctx_ = ctx;
  n_ = n;
  chunks_.store(chunks, std::memory_order_relaxed);
  done_.store(0, std::memory_order_relaxed);
  const uint64_t gen = generation_.load(std::memory_order_relaxed) + 1;
  next_.store(gen << 32 | static_cast<uint64_t>(chunks) << 16, std::memory_order_release);
  generation_.store(gen, std::memory_order_release);
  generation_.notify_all();
  work(gen, 0);
  // The wait for the chunks workers run: a spin, then (a worker off its core for kSpinBeforeSleep)
  // a sleep until they end (work() wakes it at each chunk's end). Not a yield: a yield hands the
  // core to any runnable thread, an idle-priority cook ahead's too, until the next scheduler tick
  // (4 ms at 250 Hz; measured inside the ticks of a cut's window on two cores), while a sleeper's
  // wake takes the core back from such a thread at once. (Kept off the ticks: the wait of a pool
  // with a gate sleeps at the closed gate too.)
  constexpr auto kSpinBeforeSleep = std::chrono::microseconds(50);
  std::chrono::steady_clock::time_point t0{};
  for (int spin = 0;; ++spin) {
    const int d = done_.load(std::memory_order_acquire);
    if (d == chunks) break;
    if (gate_ && gate_->closed()) {
      gate_->pass();
      continue;
    }
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
    if ((spin & 63) != 63) continue;
    const auto now = std::chrono::steady_clock::now();
    if (spin == 63) {
      t0 = now;
    } else if (now - t0 > kSpinBeforeSleep) {
      // Announced before the last look at done_, read by work() after its increment (both
      // sequentially consistent): either the sleep sees the last chunk's count or work() sees
      // the sleeper.
      caller_asleep_.store(1);
      if (done_.load() == d) sleep_while(done_, d);
      caller_asleep_.store(0);
    }
  }
}

// Chunk k's start: each half of the range is split in chunks that shrink toward the middle, each
// 1/threads of what is left of the half (with two threads 1/2, 1/4, ... of the half, the last
// two equal), so that the threads, taking chunks from opposite ends, meet on small ones and no
// first chunk is more than a thread's share (with 1/2 of what is left at any thread count, the
// caller's first chunk would be a quarter of the range: no loop faster than 4x). With as many
// chunks as items (parallel_slots: one slot per thread) each chunk is one item.
int ThreadPool::chunk_start(int64_t n, int m, int threads, int k) {
  if (m < 4 || m % 2 || m == n) return static_cast<int>(n * k / m);  // (one item per chunk)
  const int c = m / 2;
  const int64_t h1 = n / 2, h2 = n - h1;
  // What is left of a half of h items after j chunks: h ((threads - 1) / threads)^j (two
  // threads: h >> j, exactly).
  auto left = [threads](int64_t h, int j) {
    if (threads <= 2) return h >> j;
    const double r = 1.0 - 1.0 / threads;
    return static_cast<int64_t>(static_cast<double>(h) * std::pow(r, j));
  };
  if (k <= c) return static_cast<int>(k == c ? h1 : h1 - left(h1, k));
  return static_cast<int>(n - h2 + left(h2, m - k));
}

int ThreadPool::chunk_start(int k) const {
  return chunk_start(n_, chunks_.load(std::memory_order_relaxed), threads_, k);
}

void ThreadPool::work(uint64_t gen, int w) {
  const bool from_back = w % 2 == 1;
  for (;;) {
    if (gate_) gate_->pass();
    uint64_t cur = next_.load(std::memory_order_acquire);
    int k;
    uint64_t claimed;
    do {
      if ((cur >> 32) != gen) return;
      const int front = static_cast<int>(cur & 0xffffu);
      const int back = static_cast<int>((cur >> 16) & 0xffffu);
      if (front >= back) return;
      k = from_back ? back - 1 : front;
      claimed = from_back ? cur - (uint64_t{1} << 16) : cur + 1;
    } while (!next_.compare_exchange_weak(cur, claimed, std::memory_order_acq_rel));
    // Claimed chunk k of this generation: the caller waits for it, so the task is valid.
    const int b = chunk_start(k), e = chunk_start(k + 1);
    if (b < e) thunk_(ctx_, b, e, w);
    // Each chunk's end wakes the caller if it sleeps (run()).
    done_.fetch_add(1);
    if (caller_asleep_.load()) wake_all(done_);
  }
}

// A worker with nothing to do spins for kSpinBeforeSleep before it sleeps on the generation
// (a futex). A solver's substep runs ~40 parallel loops with short serial parts between them
// (contacts, settling); a worker asleep in such a gap wakes tens of microseconds late, while the
// caller runs the chunks alone. Measured, form 128^2 XPBD 10x1 on two threads (120 frames):
// spinning 2000 iterations (a few microseconds) the worker slept 81 times per frame and the
// caller waited 1.36 ms per frame at the ends of the loops; with ~200 us it slept 4 times per
// frame, and the frame took 0.92-0.95x the wall time (64^2: 0.89x). The price: a worker burns up to
// kSpinBeforeSleep of CPU after the last loop of a step before it sleeps (~2 % of a core at 90
// steps per second).
void ThreadPool::worker_main(int w) {
  constexpr auto kSpinBeforeSleep = std::chrono::microseconds(200);
  uint64_t seen = 0;
  for (;;) {
    uint64_t g = generation_.load(std::memory_order_acquire);
    if (g == seen) {
      const auto t0 = std::chrono::steady_clock::now();
      for (int spin = 0; g == seen; ++spin) {
        if (gate_ && gate_->closed()) gate_->pass();  // (no spinning while the ticks run)
        if ((spin & 255) == 255 && std::chrono::steady_clock::now() - t0 > kSpinBeforeSleep) {
          idle_sleeps_.fetch_add(1, std::memory_order_relaxed);
          generation_.wait(seen, std::memory_order_acquire);
        }
        g = generation_.load(std::memory_order_acquire);
      }
    }
    seen = g;
    if (stop_.load()) return;
    work(g, w);
  }
}

}  // namespace drape::sim
