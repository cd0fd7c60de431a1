// XPBD's element sweep on any number of threads (XpbdSolver::sweep): a substep's phases (the
// prediction with the packing, each triangle colour, each bending colour, the unpacking with
// contacts and velocities) are each split in as many shares as there are sweep slots, share t of
// every phase going to slot t. The items of a phase (vertex blocks, packs of one colour) lie in
// mesh order, so a slot's shares cover the same strip of the mesh from one phase to the next and
// touch only the strips of a few other slots. A slot runs the items of its share whose vertices
// another slot touched last (in an earlier phase) only once that slot has finished that phase,
// the others at once; slots wait for nothing else, so a slot runs ahead of the slots it does
// not touch. There is no barrier between the phases, and every item sees what it would see
// after one: the results are those of the phases run one after the other on one thread, bit for
// bit.
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
  // Items [b, e) of one slot's share of a phase, run once every slot o of `wait` (bit o) has
  // finished its first need(run)[k] phases (k: o's rank among wait's bits) — the phase in which
  // it last touched a vertex of these items.
  struct Run {
    int b, e;
    uint64_t wait;
    int need;  // the run's first entry in needs_
  };

  void clear() {
    phases_.clear();
    runs_.clear();
    needs_.clear();
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
  // Per slot of a run's wait (in bit order): the phases it must have finished.
  const int* need(const Run& r) const { return needs_.data() + r.need; }

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

  // Benchmarks: the sweep's length on slots() threads, from its runs timed on one.
  // run_timed() runs the phases on the calling thread, each phase's shares one after the other
  // (the same results as run(), bit for bit), and adds each run's duration in ns to ns[run].
  // schedule(ns, handover_ns) replays those durations as slots() threads would run them: a
  // slot's runs in order, each once the slots it waits for have finished the phases it needs (a
  // wait costs handover_ns more: the flag's cache line crossing cores). Threads are never
  // descheduled and run as fast as one alone (no shared caches or memory bandwidth): the loss it
  // shows is the plan's own. With phase_gate, a slot also starts a phase only once every slot
  // has finished the one before the previous (what a plan whose waits name only the phase
  // before needs; kept to measure against).
  template <class Items>
  void run_timed(Items&& items, std::vector<double>& ns) const;
  struct Schedule {
    double work_ns = 0;    // the runs' durations summed
    double span_ns = 0;    // from the start to the last slot's end
    double border_ns = 0;  // slots idle before a run (for the slots it waits for, the gate)
    double tail_ns = 0;    // slots idle after their last phase, until the last slot ends
  };
  Schedule schedule(const std::vector<double>& ns, double handover_ns,
                    bool phase_gate = false) const;
  int num_runs() const { return static_cast<int>(runs_.size()); }

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
  void add_runs(const Phase& P, int t, const std::vector<uint64_t>& mask,
                const std::vector<int>& need);

  std::vector<Phase> phases_;
  std::vector<Run> runs_;
  std::vector<int> needs_;
  std::vector<int> run_off_{0};  // per (phase, slot): its first run
  int slots_ = 0;
  std::unique_ptr<Slot[]> state_;
  std::atomic<bool> took_over_{false};
};

// Slot t's runs of phase P (mask: per item of P, the slots it waits for; need: per item and
// slot, the phases that slot must have finished): the items that wait for nobody first, then the
// others, each a stretch of items with the same wait, which waits for the most any of them needs.
inline void SweepPlan::add_runs(const Phase& P, int t, const std::vector<uint64_t>& mask,
                                const std::vector<int>& need) {
  const int cnt = P.e - P.b, lo = share_begin(cnt, t, slots_), hi = share_begin(cnt, t + 1, slots_);
  for (const bool waiting : {false, true})
    for (int i = lo; i < hi; ++i) {
      if ((mask[i] != 0) != waiting) continue;
      const int* ni = need.data() + static_cast<size_t>(i) * slots_;
      if (static_cast<int>(runs_.size()) > run_off_.back() && runs_.back().e == P.b + i &&
          runs_.back().wait == mask[i]) {
        ++runs_.back().e;
        int* nr = needs_.data() + runs_.back().need;
        for (uint64_t m = mask[i]; m; m &= m - 1) {
          *nr = std::max(*nr, ni[__builtin_ctzll(m)]);
          ++nr;
        }
      } else {
        runs_.push_back(Run{P.b + i, P.b + i + 1, mask[i], static_cast<int>(needs_.size())});
        for (uint64_t m = mask[i]; m; m &= m - 1) needs_.push_back(ni[__builtin_ctzll(m)]);
      }
    }
}

template <class Vertices>
void SweepPlan::plan(int slots, int n, Vertices&& vertices) {
  slots_ = std::clamp(slots, 1, kMaxSlots);
  const int S = slots_;
  state_ = std::make_unique<Slot[]>(S);
  runs_.clear();
  needs_.clear();
  run_off_.assign(1, 0);
  // The phase that last touched each vertex (-1: none yet) and the slot whose share did.
  std::vector<int> stamp(std::max(n, 0), -1);
  std::vector<uint8_t> owner(std::max(n, 0), 0);
  std::vector<uint64_t> mask;
  std::vector<int> need;
  for (int p = 0; p < static_cast<int>(phases_.size()); ++p) {
    const Phase& P = phases_[p];
    const int cnt = P.e - P.b;
    mask.assign(cnt, 0);
    need.assign(static_cast<size_t>(cnt) * S, 0);
    for (int t = 0; t < S; ++t)
      for (int i = P.b + share_begin(cnt, t, S); i < P.b + share_begin(cnt, t + 1, S); ++i) {
        uint64_t& m = mask[i - P.b];
        int* ni = need.data() + static_cast<size_t>(i - P.b) * S;
        vertices(p, i, [&](int v) {
          if (stamp[v] < 0 || owner[v] == t) return;
          m |= uint64_t{1} << owner[v];
          ni[owner[v]] = std::max(ni[owner[v]], stamp[v] + 1);
        });
      }
    for (int t = 0; t < S; ++t)
      for (int i = P.b + share_begin(cnt, t, S); i < P.b + share_begin(cnt, t + 1, S); ++i)
        vertices(p, i, [&](int v) {
          stamp[v] = p;
          owner[v] = static_cast<uint8_t>(t);
        });
    for (int t = 0; t < S; ++t) {
      add_runs(P, t, mask, need);
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
    if (s.next < 0) s.next = run_off_[p * S + t];
    for (const int end = run_off_[p * S + t + 1]; s.next < end; ++s.next) {
      const Run& R = runs_[s.next];
      const int* need = needs_.data() + R.need;
      for (uint64_t m = R.wait; m; m &= m - 1, ++need) {
        const int o = __builtin_ctzll(m);
        if (state_[o].done.load(std::memory_order_acquire) < *need) return o;
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

template <class Items>
void SweepPlan::run_timed(Items&& items, std::vector<double>& ns) const {
  ns.resize(runs_.size(), 0.0);
  for (int p = 0; p < static_cast<int>(phases_.size()); ++p)
    for (int t = 0; t < slots_; ++t)
      for (int r = run_off_[p * slots_ + t]; r < run_off_[p * slots_ + t + 1]; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        items(phases_[p], runs_[r].b, runs_[r].e, t);
        ns[r] +=
            std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
      }
}

inline SweepPlan::Schedule SweepPlan::schedule(const std::vector<double>& ns, double handover_ns,
                                               bool phase_gate) const {
  Schedule out;
  const int S = slots_, np = static_cast<int>(phases_.size());
  if (S < 1 || np == 0 || ns.size() < runs_.size()) return out;
  std::vector<double> end(static_cast<size_t>(np) * S, 0.0);  // when slot t finished phase p
  std::vector<double> now(S, 0.0);
  for (int p = 0; p < np; ++p) {
    double gate = 0;
    for (int o = 0; o < S && phase_gate && p >= 2; ++o)
      gate = std::max(gate, end[static_cast<size_t>(p - 2) * S + o]);
    for (int t = 0; t < S; ++t) {
      double at = now[t];
      if (gate > at) out.border_ns += gate - at, at = gate;
      for (int r = run_off_[p * S + t]; r < run_off_[p * S + t + 1]; ++r) {
        double ready = at;
        const int* need = needs_.data() + runs_[r].need;
        for (uint64_t m = runs_[r].wait; m; m &= m - 1, ++need)
          ready = std::max(
              ready, end[static_cast<size_t>(*need - 1) * S + __builtin_ctzll(m)] + handover_ns);
        if (ready > at) out.border_ns += ready - at, at = ready;
        at += ns[r];
        out.work_ns += ns[r];
      }
      now[t] = at;
      end[static_cast<size_t>(p) * S + t] = at;
    }
  }
  for (int t = 0; t < S; ++t) out.span_ns = std::max(out.span_ns, now[t]);
  for (int t = 0; t < S; ++t) out.tail_ns += out.span_ns - now[t];
  return out;
}

}  // namespace drape::sim::xpbd
