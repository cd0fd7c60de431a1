// Parallel helpers for the solvers: greedy vertex colouring (once per topology) and a tiny
// persistent thread pool (the caller + N-1 workers) that runs a range split in equal chunks
// without allocating per call.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <thread>
#include <type_traits>
#include <vector>

namespace drape::sim {

// Greedy colouring of a graph given in CSR form (offsets size n+1). Vertices with the same
// colour share no edge. Returns the number of colours; `colour_offsets`/`colour_items` list
// the vertices of each colour (CSR). Vertices with skip[i] true are left out (may be empty).
int greedy_colouring(const std::vector<int>& offsets, const std::vector<int>& nbrs,
                     std::vector<int>& colour_of, std::vector<int>& colour_offsets,
                     std::vector<int>& colour_items);

// Greedy colouring of elements (triangles, hinges, springs...) given their vertex lists in CSR
// form (elem_offsets size m+1 over elem_verts): elements of one colour share no vertex, so a
// colour can be projected in parallel. Returns the number of colours; `order` lists the
// elements colour by colour and `colour_offsets` (size colours+1) delimits them.
int colour_elements(int num_vertices, const std::vector<int>& elem_offsets,
                    const std::vector<int>& elem_verts, std::vector<int>& order,
                    std::vector<int>& colour_offsets);

// The first item of part k when n items are split in `parts` equal contiguous parts: part k is
// [part_begin(n, k, parts), part_begin(n, k + 1, parts)).
inline int part_begin(int n, int k, int parts) {
  return static_cast<int>(int64_t{n} * k / parts);
}

// Work kept off the ticks (a cook ahead, CookAheadSolver): the thread that ticks closes the gate
// for its step and opens it after; the kept-off threads wait while it is closed at their pause
// points: before each chunk of a pool made with the gate, and at pause_point() between the
// parts of long serial work. A thread at SCHED_IDLE alone still takes slices of a busy core
// under the kernel's fair scheduler (measured: 2-4 ms inside a 5 ms tick on two cores).
class TickGate {
 public:
  void close() { closed_.store(true, std::memory_order_release); }
  void open() {
    closed_.store(false, std::memory_order_release);
    closed_.notify_all();
  }
  bool closed() const { return closed_.load(std::memory_order_acquire); }
  // Waits while the gate is closed.
  void pass() const {
    while (closed_.load(std::memory_order_acquire)) closed_.wait(true, std::memory_order_acquire);
  }

 private:
  std::atomic<bool> closed_{false};
};

// The gate the calling thread's pause points wait at (null: none, the default).
inline thread_local const TickGate* thread_gate = nullptr;
inline void set_thread_gate(const TickGate* gate) {
  thread_gate = gate;
}
// A pause point: waits while the calling thread's gate is closed (no gate: returns at once; a
// thread-local load, cheap enough for a loop's every item).
inline void pause_point() {
  if (thread_gate && thread_gate->closed()) thread_gate->pass();
}

class ThreadPool {
 public:
  // threads = total workers including the caller (>= 1). With a gate, each thread of a call
  // (the caller too) passes it before each chunk it takes, and the workers' pause points wait
  // at it.
  explicit ThreadPool(int threads = 2, const TickGate* gate = nullptr);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;
  int size() const { return threads_; }

  // Runs fn(begin, end, worker) over [0, n) split in up to chunks_for() contiguous chunks
  // (shrinking toward the middle of the range: thread_pool.cpp, chunk_start) claimed
  // by whichever thread is free (the caller included; fn may be called several times per
  // thread, `worker` is the calling thread's index); returns when all are done. fn must be
  // callable as void(int, int, int). No allocation.
  template <class Fn>
  void parallel_for(int n, Fn&& fn) {
    if (threads_ == 1 || n < min_parallel_) {
      fn(0, n, 0);
      return;
    }
    run(n, &invoke<std::remove_reference_t<Fn>>, &fn, std::min(n, chunks_for(threads_)));
  }
  // parallel_for's chunks on `threads` threads: 4 per thread up to two threads, 12 beyond (the
  // chunks shrink by 1/threads of what is left: with more threads more chunks keep the last
  // ones small, e^-6 of the half), and the first item of chunk k of m over [0, n).
  static int chunks_for(int threads) { return threads <= 2 ? 4 * threads : 12 * threads; }
  static int chunk_start(int64_t n, int m, int threads, int k);
  // Runs fn(slot, worker) once for each slot in [0, size()), every slot claimed by one thread
  // (the caller takes slot 0 first; a worker that arrives late may find its slot taken by the
  // caller, which then runs it after its own). fn may wait for another slot only if it can take
  // that slot's work over when nobody has claimed it (XpbdSolver's sweep does). No allocation.
  template <class Fn>
  void parallel_slots(Fn&& fn) {
    auto body = [&fn](int b, int e, int w) {
      for (int k = b; k < e; ++k) fn(k, w);
    };
    if (threads_ == 1) {
      body(0, 1, 0);
      return;
    }
    run(threads_, &invoke<decltype(body)>, &body, threads_);
  }
  // Runs fn(begin, end, part) once for each of size() equal parts of [0, n) (part_begin), one
  // part per slot (parallel_slots): a part's results can be joined in part order, the same on
  // any thread.
  template <class Fn>
  void parallel_parts(int n, Fn&& fn) {
    parallel_slots(
        [&](int k, int) { fn(part_begin(n, k, threads_), part_begin(n, k + 1, threads_), k); });
  }
  // Times a worker went to sleep after spinning idle (thread_pool.cpp, kSpinBeforeSleep).
  long idle_sleeps() const { return idle_sleeps_.load(std::memory_order_relaxed); }
  // Below this many items the caller runs the range alone (sync costs more than it saves).
  void set_min_parallel(int n) { min_parallel_ = n; }

 private:
  using Thunk = void (*)(void*, int, int, int);
  template <class Fn>
  static void invoke(void* f, int b, int e, int w) {
    (*static_cast<Fn*>(f))(b, e, w);
  }
  void run(int n, Thunk thunk, void* ctx, int chunks);
  int chunk_start(int k) const;
  void work(uint64_t generation, int w);
  void worker_main(int w);

  int threads_;
  const TickGate* gate_ = nullptr;
  int min_parallel_ = 64;
  std::vector<std::thread> workers_;
  std::atomic<uint64_t> generation_{0};
  std::atomic<uint64_t> next_{0};      // generation << 32 | back << 16 | front (see run())
  std::atomic<int> done_{0};           // chunks finished in this generation
  std::atomic<int> caller_asleep_{0};  // run() sleeps on done_ (a chunk's end wakes it)
  std::atomic<int> chunks_{0};         // chunks of this generation
  std::atomic<bool> stop_{false};
  std::atomic<long> idle_sleeps_{0};
  Thunk thunk_ = nullptr;
  void* ctx_ = nullptr;
  int n_ = 0;
};

}  // namespace drape::sim
