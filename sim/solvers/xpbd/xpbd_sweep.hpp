// XPBD's element sweep on any number of threads (XpbdSolver::sweep): a substep's phases (the
// prediction with the packing, each triangle colour, each bending colour, the unpacking with
// contacts and velocities) are each split in as many shares as there are sweep slots, share t of
// every phase going to slot t. The items of a phase (vertex blocks, packs of one colour) lie in
// mesh order, so a slot's shares cover the same strip of the mesh from one phase to the next and
// touch only the strips of a few other slots. A slot runs the items of its share that share no
// vertex with another slot's share of the previous phase at once, and the others only once the
// slots they touch have finished that phase; no slot starts a phase before every slot has
// finished the one before the previous. There is no barrier between the phases, and every item
// sees what it would see after one: the results are those of the phases run one after the other
// on one thread, bit for bit.
//
// Each slot is claimed by one thread. A thread that has waited kClaimGrace for a slot nobody has
// claimed (a worker that is not scheduled) claims it and runs it alongside its own, each as far
// as it gets without waiting; a thread that has finished its slots claims any slot still
// unclaimed.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include "sim/core/thread_pool.hpp"

namespace drape::sim::xpbd {

class SweepPlan {
 public:
  static constexpr int kMaxSlots = 64;  // (a run's wait list is a 64-bit mask)
  // How long a thread waits for a slot nobody has claimed before it takes the slot over: a
  // worker spinning between sweeps claims its own within it, one that is not scheduled does not
  // (the waiting thread then runs both; on a loaded two-core machine that is most sweeps). Not
  // tuned on a many-core machine.
  static constexpr std::chrono::microseconds kClaimGrace{5};
  struct Phase {
    int kind;  // the caller's kind of items
    int b, e;  // the items
  };
  // Items [b, e) of one slot's share of a phase, run once every slot of `wait` (bit o: slot o)
  // has finished the previous phase.
  struct Run {
    int b, e;
    uint64_t wait;
  };

  void clear() {
    phases_.clear();
    runs_.clear();
    run_off_.assign(1, 0);
    slots_ = 0;
  }
  bool empty() const { return phases_.empty(); }
  int slots() const { return slots_; }
  const std::vector<Phase>& phases() const { return phases_; }
  void add_phase(int kind, int b, int e) { phases_.push_back(Phase{kind, b, e}); }
  // Slot t's share of a phase's cnt items: [share_begin(cnt, t, slots), share_begin(cnt, t + 1,
  // slots)) (part_begin, the same split as the packs' padding shares).
  static int share_begin(int cnt, int t, int slots) { return part_begin(cnt, t, slots); }
  // The runs of slot t in phase p: those that wait for nobody first, then the others, each in
  // item order.
  const Run* runs_begin(int p, int t) const { return runs_.data() + run_off_[p * slots_ + t]; }
  const Run* runs_end(int p, int t) const { return runs_.data() + run_off_[p * slots_ + t + 1]; }

  // Splits the phases (added before) for `slots` slots. vertices(p, i, fn) calls fn(v) for each
  // vertex v < n of item i of phase p (vertices of the padding's scratch left out: each share
  // has its own). The items of one phase must share no vertex.
  template <class Vertices>
  void plan(int slots, int n, Vertices&& vertices);

  // Runs the sweep on the pool (pool.size() == slots(); one slot per thread), or on the caller
  // alone when the pool has one thread: items(phase, b, e, slot) for every run. claims(worker)
  // says whether a pool thread may claim its slot (tests: false plays a worker that is never
  // scheduled). Returns whether some thread took over a slot nobody had claimed.
  template <class Items, class Claims>
  bool run(ThreadPool& pool, Items&& items, Claims&& claims);

 private:
  struct alignas(64) Slot {
    std::atomic<int> done{0};    // phases finished
    std::atomic<int> owner{-1};  // the thread running it (-1: nobody yet)
    int phase = 0;               // the phase it is in
    int next = -1;               // its next run (-1: the phase not started)
  };
  template <class Items>
  int advance(int t, Items& items);
  template <class Items>
  void drive(int first, int worker, Items& items);
  bool claim(int t, int worker) {
    int nobody = -1;
    return state_[t].owner.load(std::memory_order_relaxed) == -1 &&
           state_[t].owner.compare_exchange_strong(nobody, worker, std::memory_order_acq_rel);
  }
  void add_runs(const Phase& P, int t, const std::vector<uint64_t>& mask);

  std::vector<Phase> phases_;
  std::vector<Run> runs_;
  std::vector<int> run_off_{0};  // per (phase, slot): its first run
  int slots_ = 0;
  std::unique_ptr<Slot[]> state_;
  std::atomic<bool> took_over_{false};
};

// Slot t's runs of phase P (mask: per item of P, the slots it waits for): the items that wait for
// nobody first, then the others, each a stretch of items with the same wait.
inline void SweepPlan::add_runs(const Phase& P, int t, const std::vector<uint64_t>& mask) {
  const int cnt = P.e - P.b, lo = share_begin(cnt, t, slots_), hi = share_begin(cnt, t + 1, slots_);
  for (const bool waiting : {false, true})
    for (int i = lo; i < hi; ++i) {
      if ((mask[i] != 0) != waiting) continue;
      if (!runs_.empty() && static_cast<int>(runs_.size()) > run_off_.back() &&
          runs_.back().e == P.b + i && runs_.back().wait == mask[i])
        ++runs_.back().e;
      else
        runs_.push_back(Run{P.b + i, P.b + i + 1, mask[i]});
    }
}

template <class Vertices>
void SweepPlan::plan(int slots, int n, Vertices&& vertices) {
  slots_ = std::clamp(slots, 1, kMaxSlots);
  const int S = slots_;
  state_ = std::make_unique<Slot[]>(S);
  runs_.clear();
  run_off_.assign(1, 0);
  // The phase that last touched each vertex and the slot whose share did.
  std::vector<int> stamp(std::max(n, 0), -1);
  std::vector<uint8_t> owner(std::max(n, 0), 0);
  std::vector<uint64_t> mask;
  for (int p = 0; p < static_cast<int>(phases_.size()); ++p) {
    const Phase& P = phases_[p];
    const int cnt = P.e - P.b;
    mask.assign(cnt, 0);
    for (int t = 0; t < S; ++t)
      for (int i = P.b + share_begin(cnt, t, S); i < P.b + share_begin(cnt, t + 1, S); ++i) {
        uint64_t& m = mask[i - P.b];
        vertices(p, i, [&](int v) {
          if (p > 0 && stamp[v] == p - 1 && owner[v] != t) m |= uint64_t{1} << owner[v];
        });
      }
    for (int t = 0; t < S; ++t)
      for (int i = P.b + share_begin(cnt, t, S); i < P.b + share_begin(cnt, t + 1, S); ++i)
        vertices(p, i, [&](int v) {
          stamp[v] = p;
          owner[v] = static_cast<uint8_t>(t);
        });
    for (int t = 0; t < S; ++t) {
      add_runs(P, t, mask);
      run_off_.push_back(static_cast<int>(runs_.size()));
    }
  }
}

// Slot t as far as it goes without waiting: returns the slot it waits for, or -1 once it has
// run every phase.
template <class Items>
int SweepPlan::advance(int t, Items& items) {
  const int S = slots_, np = static_cast<int>(phases_.size());
  Slot& s = state_[t];
  while (s.phase < np) {
    const int p = s.phase;
    if (s.next < 0) {  // the phase's start: every slot has finished phase p - 2
      for (int o = 0; o < S && p >= 2; ++o)
        if (o != t && state_[o].done.load(std::memory_order_acquire) < p - 1) return o;
      s.next = run_off_[p * S + t];
    }
    for (const int end = run_off_[p * S + t + 1]; s.next < end; ++s.next) {
      const Run& R = runs_[s.next];
      for (uint64_t m = R.wait; m; m &= m - 1) {
        const int o = __builtin_ctzll(m);
        if (state_[o].done.load(std::memory_order_acquire) < p) return o;
      }
      items(phases_[p], R.b, R.e, t);
    }
    s.next = -1;
    s.done.store(++s.phase, std::memory_order_release);
  }
  return -1;
}

// One thread: its slot `first` and those it takes over, each advanced in turn.
template <class Items>
void SweepPlan::drive(int first, int worker, Items& items) {
  int own[kMaxSlots];
  int count = 1;
  own[0] = first;
  auto take = [&](int t) {
    if (!claim(t, worker)) return false;
    own[count++] = t;
    took_over_.store(true, std::memory_order_relaxed);
    return true;
  };
  std::chrono::steady_clock::time_point blocked_at;
  for (int spin = 0;;) {
    bool moved = false, done = true;
    int waits[kMaxSlots];
    for (int k = 0; k < count; ++k) {
      const Slot& s = state_[own[k]];
      const int phase = s.phase, next = s.next;
      waits[k] = advance(own[k], items);
      moved = moved || s.phase != phase || s.next != next;
      done = done && waits[k] < 0;
    }
    if (done) {  // own slots finished: any slot nobody has claimed yet
      bool took = false;
      for (int t = 0; t < slots_ && !took; ++t) took = take(t);
      if (!took) return;
      continue;
    }
    if (moved) {
      spin = 0;
      continue;
    }
    // Blocked: a slot waited for that nobody has claimed after kClaimGrace is taken over (a
    // worker asleep between two sweeps wakes within it; one not scheduled does not).
    if (spin == 0) blocked_at = std::chrono::steady_clock::now();
    bool took = false;
    if ((++spin & 7) == 0 && std::chrono::steady_clock::now() - blocked_at > kClaimGrace)
      for (int k = 0; k < count && !took; ++k)
        if (waits[k] >= 0) took = take(waits[k]);
    if (took) {
      spin = 0;
      continue;
    }
    if (spin > 1024) std::this_thread::yield();
  }
}

template <class Items, class Claims>
bool SweepPlan::run(ThreadPool& pool, Items&& items, Claims&& claims) {
  const int S = slots_;
  if (pool.size() == 1 || S <= 1) {
    for (const Phase& P : phases_) items(P, P.b, P.e, 0);
    return false;
  }
  for (int t = 0; t < S; ++t) {
    state_[t].done.store(0, std::memory_order_relaxed);
    state_[t].owner.store(-1, std::memory_order_relaxed);
    state_[t].phase = 0;
    state_[t].next = -1;
  }
  took_over_.store(false, std::memory_order_relaxed);
  pool.parallel_slots([&](int slot, int worker) {
    if (slot < S && claims(worker) && claim(slot, worker)) drive(slot, worker, items);
  });
  // Slots whose pool chunk went to a thread that may not claim them (tests): the caller runs
  // them now.
  for (int t = 0; t < S; ++t)
    if (claim(t, 0)) {
      took_over_.store(true, std::memory_order_relaxed);
      drive(t, 0, items);
    }
  return took_over_.load(std::memory_order_relaxed);
}

}  // namespace drape::sim::xpbd
