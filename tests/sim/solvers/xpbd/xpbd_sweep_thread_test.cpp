// The element sweep's plan and scheduler (sim/solvers/xpbd/xpbd_sweep.hpp) on a synthetic
// mesh: vertices on a line, phases whose items are runs of neighbouring vertices (items of one
// phase disjoint, as a colour's elements are), each item updating its vertices with an order-
// dependent function. Any thread count must give the values of the phases run one after the
// other, also when workers never claim their shares. (In the TSan build: "thread" in the name.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "sim/core/thread_pool.hpp"
#include "sim/solvers/xpbd/xpbd_sweep.hpp"

using namespace drape::sim;
using xpbd::SweepPlan;

namespace {

constexpr int kVertices = 600;

// Item i of phase p covers vertices [start(p, i), start(p, i) + width(p)): the phases' widths
// and offsets differ, so items straddle the shares of the phase before.
int width(int p) {
  return 2 + p % 4;
}
int offset(int p) {
  return (3 * p) % 5;
}
int items_of(int p) {
  return (kVertices - offset(p)) / width(p);
}
int start(int p, int i) {
  return offset(p) + i * width(p);
}

// One update of vertex v by item i of phase p: not commutative with another phase's.
void update(std::vector<uint64_t>& x, int p, int i, int v) {
  x[v] = x[v] * 6364136223846793005ull + static_cast<uint64_t>(p * 1000003 + i * 7 + 1);
}

void make_plan(SweepPlan& plan, int phases, int slots) {
  plan.clear();
  for (int p = 0; p < phases; ++p) plan.add_phase(0, 0, items_of(p));
  plan.plan(slots, kVertices, [](int p, int i, auto&& fn) {
    for (int v = start(p, i); v < start(p, i) + width(p); ++v) fn(v);
  });
}

std::vector<uint64_t> serial(int phases) {
  std::vector<uint64_t> x(kVertices, 1);
  for (int p = 0; p < phases; ++p)
    for (int i = 0; i < items_of(p); ++i)
      for (int v = start(p, i); v < start(p, i) + width(p); ++v) update(x, p, i, v);
  return x;
}

// Runs the plan `reps` times on `threads` threads; claims(worker) as SweepPlan::run takes it.
template <class Claims>
std::vector<uint64_t> swept(int phases, int threads, int reps, Claims claims, bool* took_over) {
  ThreadPool pool(threads);
  SweepPlan plan;
  make_plan(plan, phases, threads);
  std::vector<uint64_t> x;
  for (int r = 0; r < reps; ++r) {
    x.assign(kVertices, 1);
    // Each phase's index is its position in plan.phases() (all of kind 0).
    const SweepPlan::Phase* first = plan.phases().data();
    const bool took = plan.run(
        pool,
        [&](const SweepPlan::Phase& P, int b, int e, int) {
          const int p = static_cast<int>(&P - first);
          for (int i = b; i < e; ++i)
            for (int v = start(p, i); v < start(p, i) + width(p); ++v) update(x, p, i, v);
        },
        claims);
    if (took_over) *took_over = *took_over || took;
    if (x != serial(phases)) return x;
  }
  return x;
}

}  // namespace

// Each item waits for the slots that last touched its vertices, until they have finished that
// phase: the values of the serial phases, at 1 to 8 threads, many times over (a missing wait
// shows as a different value at some run).
TEST(XpbdSweepPlan, AnyThreadCountGivesTheSerialValues) {
  const int phases = 12;
  const std::vector<uint64_t> ref = serial(phases);
  for (int threads : {1, 2, 3, 4, 5, 8}) {
    const auto x = swept(
        phases, threads, 200, [](int) { return true; }, nullptr);
    EXPECT_EQ(x, ref) << threads << " threads";
  }
}

// The plan's runs: a share waits only for the slots that touched its vertices last (on a line,
// its neighbours), and its items that wait for nobody come first.
TEST(XpbdSweepPlan, RunsWaitOnlyForTheSharesTheyTouch) {
  const int slots = 4;
  SweepPlan plan;
  make_plan(plan, 6, slots);
  for (int p = 0; p < 6; ++p)
    for (int t = 0; t < slots; ++t) {
      bool waited = false;
      for (const SweepPlan::Run* r = plan.runs_begin(p, t); r != plan.runs_end(p, t); ++r) {
        if (p == 0) {
          EXPECT_EQ(r->wait, 0u);
        }
        uint64_t allowed = 0;
        if (t > 0) allowed |= uint64_t{1} << (t - 1);
        if (t + 1 < slots) allowed |= uint64_t{1} << (t + 1);
        EXPECT_EQ(r->wait & ~allowed, 0u) << "phase " << p << " share " << t;
        if (r->wait) waited = true;
        if (waited) {
          EXPECT_NE(r->wait, 0u) << "an item that waits for nobody after one that waits";
        }
      }
    }
}

// Workers that never claim their shares (as when they are not scheduled): the others, or the
// caller alone, take them over, with the same values.
TEST(XpbdSweepPlan, SharesNobodyClaimedAreTakenOver) {
  const int phases = 10;
  const std::vector<uint64_t> ref = serial(phases);
  bool took = false;
  EXPECT_EQ(swept(
                phases, 4, 100, [](int w) { return w != 2; }, &took),
            ref);
  EXPECT_TRUE(took);
  took = false;
  EXPECT_EQ(swept(
                phases, 3, 100, [](int w) { return w == 0; }, &took),
            ref);
  EXPECT_TRUE(took);
}

// Every run waits, for each vertex of its items that another slot touched last, for that slot to
// have finished the phase of that touch (found by walking the phases), and for no later phase
// than the one before its own (so that no slot can wait for one that waits for it). Phases that
// skip vertices make the last touch lie several phases back.
TEST(XpbdSweepPlan, RunsWaitForTheLastTouchOfEachVertex) {
  const int phases = 9, slots = 5;
  SweepPlan plan;
  // Phase p's items skip every (p % 3 + 2)-th vertex block of width(p).
  auto skipped = [](int p, int i) { return i % (p % 3 + 2) == 1; };
  plan.clear();
  for (int p = 0; p < phases; ++p) plan.add_phase(0, 0, items_of(p));
  auto vertices = [&](int p, int i, auto&& fn) {
    if (skipped(p, i)) return;
    for (int v = start(p, i); v < start(p, i) + width(p); ++v) fn(v);
  };
  plan.plan(slots, kVertices, vertices);
  std::vector<int> last_phase(kVertices, -1), last_slot(kVertices, -1);
  int runs = 0, far_back = 0;
  for (int p = 0; p < phases; ++p) {
    std::vector<std::pair<int, int>> touched;  // (vertex, slot) of this phase
    for (int t = 0; t < slots; ++t)
      for (const SweepPlan::Run* r = plan.runs_begin(p, t); r != plan.runs_end(p, t); ++r) {
        ++runs;
        const int* need = plan.need(*r);
        for (uint64_t m = r->wait, k = 0; m; m &= m - 1, ++k) {
          EXPECT_NE(__builtin_ctzll(m), t);
          EXPECT_GE(need[k], 1);
          EXPECT_LE(need[k], p) << "phase " << p << " slot " << t;
        }
        for (int i = r->b; i < r->e; ++i)
          vertices(p, i, [&](int v) {
            touched.emplace_back(v, t);
            const int o = last_slot[v];
            if (o < 0 || o == t) return;
            ASSERT_TRUE(r->wait >> o & 1) << "phase " << p << " vertex " << v;
            const int k = __builtin_popcountll(r->wait & ((uint64_t{1} << o) - 1));
            EXPECT_GE(need[k], last_phase[v] + 1) << "phase " << p << " vertex " << v;
            if (last_phase[v] < p - 1) ++far_back;
          });
      }
    for (const auto& [v, t] : touched) {
      last_phase[v] = p;
      last_slot[v] = t;
    }
  }
  EXPECT_GT(runs, phases * slots);
  EXPECT_GT(far_back, 0) << "no last touch lay more than one phase back: the test tests less";
  // And the values of the serial phases on 5 threads.
  std::vector<uint64_t> ref(kVertices, 1), x(kVertices, 1);
  for (int p = 0; p < phases; ++p)
    for (int i = 0; i < items_of(p); ++i) vertices(p, i, [&](int v) { update(ref, p, i, v); });
  ThreadPool pool(slots);
  const SweepPlan::Phase* first = plan.phases().data();
  for (int rep = 0; rep < 100 && (rep == 0 || x == ref); ++rep) {
    x.assign(kVertices, 1);
    plan.run(
        pool,
        [&](const SweepPlan::Phase& P, int b, int e, int) {
          const int p = static_cast<int>(&P - first);
          for (int i = b; i < e; ++i) vertices(p, i, [&](int v) { update(x, p, i, v); });
        },
        [](int) { return true; });
  }
  EXPECT_EQ(x, ref);
}

// The replay of timed runs (benchmarks): run_timed() gives the serial values; on one slot the
// span is the work; on several, the slots' busy and idle time add up to slots x span, the span
// lies between work / slots and the work, and a slow share delays the runs that wait for it by
// its own length plus the hand-over (with the phase gate, every slot two phases on).
TEST(XpbdSweepPlan, ScheduleReplaysTheRunsAsTheSlotsWouldRunThem) {
  const int phases = 8;
  std::vector<uint64_t> x(kVertices, 1);
  const SweepPlan::Phase* first = nullptr;
  auto items = [&](const SweepPlan::Phase& P, int b, int e, int) {
    const int p = static_cast<int>(&P - first);
    for (int i = b; i < e; ++i)
      for (int v = start(p, i); v < start(p, i) + width(p); ++v) update(x, p, i, v);
  };
  for (int slots : {1, 2, 4, 7}) {
    SweepPlan plan;
    make_plan(plan, phases, slots);
    first = plan.phases().data();
    x.assign(kVertices, 1);
    std::vector<double> ns;
    plan.run_timed(items, ns);
    EXPECT_EQ(x, serial(phases)) << slots << " slots";
    ASSERT_EQ(static_cast<int>(ns.size()), plan.num_runs());
    // Durations: 10 ns per item, so that the replay is exact.
    for (int r = 0; r < plan.num_runs(); ++r)
      ns[r] = 10.0 * (plan.runs_begin(0, 0)[r].e - plan.runs_begin(0, 0)[r].b);
    const SweepPlan::Schedule s = plan.schedule(ns, 0);
    double work = 0;
    for (double d : ns) work += d;
    EXPECT_DOUBLE_EQ(s.work_ns, work);
    if (slots == 1) {
      EXPECT_DOUBLE_EQ(s.span_ns, work);
      EXPECT_DOUBLE_EQ(s.border_ns + s.tail_ns, 0.0);
    }
    EXPECT_NEAR(slots * s.span_ns, s.work_ns + s.border_ns + s.tail_ns, 1e-6) << slots;
    EXPECT_GE(s.span_ns, work / slots - 1e-9);
    EXPECT_LE(s.span_ns, work + 1e-9);
    // A hand-over per wait, or the phase gate, only lengthens the span.
    EXPECT_GE(plan.schedule(ns, 50).span_ns, s.span_ns);
    EXPECT_GE(plan.schedule(ns, 0, true).span_ns, s.span_ns);
    if (slots < 2) continue;
    // Slot 1's share of phase 0 a million ns longer: every run that waits for slot 1 in phase 1
    // starts after it, 1e6 + the hand-over (100) after the start at the earliest.
    std::vector<double> slow = ns;
    for (const SweepPlan::Run* r = plan.runs_begin(0, 1); r != plan.runs_end(0, 1); ++r)
      slow[r - plan.runs_begin(0, 0)] += 1e6 / (plan.runs_end(0, 1) - plan.runs_begin(0, 1));
    const SweepPlan::Schedule d = plan.schedule(slow, 100);
    EXPECT_GE(d.span_ns, 1e6 + 100) << slots;
    EXPECT_GT(d.border_ns, 1e6 - work) << "the slots touching slot 1 waited for it";
    // With the gate every other slot waits for it by phase 2.
    const SweepPlan::Schedule g = plan.schedule(slow, 0, true);
    EXPECT_GE(g.border_ns, (slots - 1) * (1e6 - work)) << slots;
  }
}
