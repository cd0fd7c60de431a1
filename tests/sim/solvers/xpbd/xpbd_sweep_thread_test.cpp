// The element sweep's plan and scheduler (sim/solvers/xpbd/xpbd_sweep.hpp) on a synthetic
// mesh: vertices on a line, phases whose items are runs of neighbouring vertices (items of one
// phase disjoint, as a colour's elements are), each item updating its vertices with an order-
// dependent function. Any thread count must give the values of the phases run one after the
// other, also when workers never claim their shares. (In the TSan build: "thread" in the name.)
#include <gtest/gtest.h>

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

// Each item waits for the shares of the previous phase it touches, and no share starts a phase
// before all have finished the one before the previous: the values of the serial phases, at
// 1 to 8 threads, many times over (a missing wait shows as a different value at some run).
TEST(XpbdSweepPlan, AnyThreadCountGivesTheSerialValues) {
  const int phases = 12;
  const std::vector<uint64_t> ref = serial(phases);
  for (int threads : {1, 2, 3, 4, 5, 8}) {
    const auto x = swept(
        phases, threads, 200, [](int) { return true; }, nullptr);
    EXPECT_EQ(x, ref) << threads << " threads";
  }
}

// The plan's runs: a share waits only for the shares of the previous phase it touches (on a
// line, its neighbours), and its items that touch none come first.
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
