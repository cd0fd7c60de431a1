#include "sim/parallel.hpp"

#include <algorithm>

namespace drape::sim {

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
  colour_offsets.assign(colours + 1, 0);
  for (int i = 0; i < n; ++i) ++colour_offsets[colour_of[i] + 1];
  for (int c = 0; c < colours; ++c) colour_offsets[c + 1] += colour_offsets[c];
  colour_items.assign(std::max(n, 0), 0);
  std::vector<int> fill(colour_offsets.begin(), colour_offsets.end() - 1);
  for (int i = 0; i < n; ++i) colour_items[fill[colour_of[i]]++] = i;
  return colours;
}

ThreadPool::ThreadPool(int threads) : threads_(std::max(1, threads)) {
  for (int w = 1; w < threads_; ++w) workers_.emplace_back([this, w] { worker_main(w); });
}

ThreadPool::~ThreadPool() {
  stop_.store(true);
  generation_.fetch_add(1);
  generation_.notify_all();
  for (auto& t : workers_) t.join();
}

void ThreadPool::run(int n, Thunk thunk, void* ctx) {
  thunk_ = thunk;
  ctx_ = ctx;
  n_ = n;
  pending_.store(threads_ - 1, std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_release);
  generation_.notify_all();
  const int chunk = (n + threads_ - 1) / threads_;
  thunk(ctx, 0, std::min(n, chunk), 0);
  // Wait for the workers: spin briefly, then block.
  for (int spin = 0; pending_.load(std::memory_order_acquire) != 0; ++spin) {
    if (spin > 2000) {
      int p = pending_.load(std::memory_order_acquire);
      if (p != 0) pending_.wait(p, std::memory_order_acquire);
    }
  }
}

void ThreadPool::worker_main(int w) {
  uint64_t seen = 0;
  for (;;) {
    uint64_t g = generation_.load(std::memory_order_acquire);
    for (int spin = 0; g == seen; ++spin) {
      if (spin > 2000) generation_.wait(seen, std::memory_order_acquire);
      g = generation_.load(std::memory_order_acquire);
    }
    seen = g;
    if (stop_.load()) return;
    const int chunk = (n_ + threads_ - 1) / threads_;
    const int b = std::min(n_, w * chunk), e = std::min(n_, (w + 1) * chunk);
    if (b < e) thunk_(ctx_, b, e, w);
    if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) pending_.notify_all();
  }
}

}  // namespace drape::sim
