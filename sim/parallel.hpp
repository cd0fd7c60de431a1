// Parallel helpers for the solvers: greedy vertex colouring (once per topology) and a tiny
// persistent thread pool (the caller + N-1 workers) that runs a range split in equal chunks
// without allocating per call.
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

namespace drape::sim {

// Greedy colouring of a graph given in CSR form (offsets size n+1). Vertices with the same
// colour share no edge. Returns the number of colours; `colour_offsets`/`colour_items` list
// the vertices of each colour (CSR). Vertices with skip[i] true are left out (may be empty).
int greedy_colouring(const std::vector<int>& offsets, const std::vector<int>& nbrs,
                     std::vector<int>& colour_of, std::vector<int>& colour_offsets,
                     std::vector<int>& colour_items);

class ThreadPool {
 public:
  // threads = total workers including the caller (>= 1).
  explicit ThreadPool(int threads = 2);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;
  int size() const { return threads_; }

  // Runs fn(begin, end, worker) over [0, n) split in size() contiguous chunks; returns when
  // all are done. fn must be callable as void(int, int, int). No allocation.
  template <class Fn>
  void parallel_for(int n, Fn&& fn) {
    if (threads_ == 1 || n < min_parallel_) {
      fn(0, n, 0);
      return;
    }
    run(n, &invoke<Fn>, &fn);
  }
  // Below this many items the caller runs the range alone (sync costs more than it saves).
  void set_min_parallel(int n) { min_parallel_ = n; }

 private:
  using Thunk = void (*)(void*, int, int, int);
  template <class Fn>
  static void invoke(void* f, int b, int e, int w) {
    (*static_cast<Fn*>(f))(b, e, w);
  }
  void run(int n, Thunk thunk, void* ctx);
  void worker_main(int w);

  int threads_;
  int min_parallel_ = 64;
  std::vector<std::thread> workers_;
  std::atomic<uint64_t> generation_{0};
  std::atomic<int> pending_{0};
  std::atomic<bool> stop_{false};
  Thunk thunk_ = nullptr;
  void* ctx_ = nullptr;
  int n_ = 0;
};

}  // namespace drape::sim
