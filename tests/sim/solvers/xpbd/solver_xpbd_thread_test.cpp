// XPBD's element sweep on N threads (xpbd_sweep.hpp): the phases of a substep (the prediction
// with the packing, the triangle colours, the bending colours, the unpacking with contacts and
// velocities) run without barriers, each phase split in one share per thread, each thread
// waiting only where its items touch what another has still to do. The drape must come out as
// on one thread, bit for bit, at any thread count, also when a worker never takes its share and
// the others take it over. (In the TSan build: "thread" in the name.)
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "sim/ops/cut.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"
#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

namespace {

struct DrapeRun {
  std::vector<Vec3> x, v;
  long sweeps = 0, takeovers = 0, detections = 0;
  int frozen = 0, finished = 0;
};

// The form drape (falls onto the form: contacts, friction, settling, sleeping).
DrapeRun form_drape(int res, int frames, int threads, bool worker = true, int absent = -1) {
  Testbed sc = make_scene("form", res);
  XpbdOptions o;
  o.substeps = 10;
  o.air_drag = sc.air_drag;
  o.threads = threads;
  o.min_parallel_triangles = 0;  // small test cloths run on two threads too
  o.freeze = true;
  o.sweep_worker = worker;
  o.sweep_absent_worker = absent;
  // The static finish of sleeping pieces one cycle per step on the solver's threads: on a thread
  // of its own, the frame its result lands on depends on the scheduler, not on the sweep.
  o.finish_thread = false;
  XpbdSolver s(o);
  for (int f = 0; f < frames; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
  return DrapeRun{sc.cloth.state.x,       sc.cloth.state.v, s.sweeps(),      s.sweep_takeovers(),
                  s.contact_detections(), s.frozen_count(), s.finish_count()};
}

double max_diff(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double m = 0;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, (a[i] - b[i]).cwiseAbs().maxCoeff());
  return m;
}

}  // namespace

TEST(XpbdSweep, TwoThreadsGiveTheDrapeOfOneBitForBit) {
  const DrapeRun one = form_drape(24, 120, 1), two = form_drape(24, 120, 2);
  std::printf(
      "24^2 form drape, 120 frames: %ld sweeps on two threads (%ld taken over), %ld "
      "contact detections\n",
      two.sweeps, two.takeovers, two.detections);
  EXPECT_EQ(one.sweeps, 0);
  EXPECT_EQ(two.sweeps, 120 * 10);
  EXPECT_EQ(one.detections, two.detections);
  EXPECT_EQ(max_diff(one.x, two.x), 0.0);
  EXPECT_EQ(max_diff(one.v, two.v), 0.0);
}

// The sweep on 3, 4 and 8 threads: each thread a share (a strip of the mesh), the same drape as
// on one thread bit for bit, every sweep on the threads. (Beyond the machine's cores the threads
// take turns: correctness only.)
TEST(XpbdSweep, AnyThreadCountGivesTheDrapeOfOneBitForBit) {
  const DrapeRun one = form_drape(24, 120, 1);
  for (int threads : {3, 4, 8}) {
    const DrapeRun many = form_drape(24, 120, threads);
    std::printf(
        "24^2 form drape, 120 frames, %d threads: %ld sweeps (%ld with a share taken over)\n",
        threads, many.sweeps, many.takeovers);
    EXPECT_EQ(many.sweeps, 120 * 10) << threads << " threads";
    EXPECT_EQ(one.detections, many.detections) << threads << " threads";
    EXPECT_EQ(max_diff(one.x, many.x), 0.0) << threads << " threads";
    EXPECT_EQ(max_diff(one.v, many.v), 0.0) << threads << " threads";
  }
}

// A larger cloth (more vertex blocks and packs per share, strips touching only their
// neighbours) on 5 threads: still the drape of one thread.
TEST(XpbdSweep, FiveThreadsOnALargerClothGiveTheDrapeOfOne) {
  const DrapeRun one = form_drape(48, 40, 1), five = form_drape(48, 40, 5);
  EXPECT_EQ(five.sweeps, 40 * 10);
  EXPECT_EQ(max_diff(one.x, five.x), 0.0);
  EXPECT_EQ(max_diff(one.v, five.v), 0.0);
}

// One worker of four never takes its share (as when it is not scheduled): a thread that needs
// that share, or that has finished its own, claims it and runs it alongside its own.
TEST(XpbdSweep, OthersTakeOverTheShareOfAnAbsentWorker) {
  const DrapeRun one = form_drape(24, 60, 1), three = form_drape(24, 60, 4, true, 2);
  EXPECT_EQ(three.sweeps, 60 * 10);
  EXPECT_EQ(three.takeovers, three.sweeps);
  EXPECT_EQ(max_diff(one.x, three.x), 0.0);
  EXPECT_EQ(max_diff(one.v, three.v), 0.0);
}

// No worker takes its share (as when none is scheduled): the caller runs every share,
// alternating between them where each needs another, with the same result.
TEST(XpbdSweep, TheCallerTakesOverEveryShareNobodyClaimed) {
  const DrapeRun one = form_drape(24, 60, 1);
  for (int threads : {2, 3}) {
    const DrapeRun alone = form_drape(24, 60, threads, false);
    EXPECT_EQ(alone.sweeps, 60 * 10) << threads << " threads";
    EXPECT_EQ(alone.takeovers, alone.sweeps) << threads << " threads";
    EXPECT_EQ(max_diff(one.x, alone.x), 0.0) << threads << " threads";
    EXPECT_EQ(max_diff(one.v, alone.v), 0.0) << threads << " threads";
  }
}

// A cloth at rest on the form falls asleep the same way on four threads (the motion sums that
// decide it are taken per vertex block, in block order, whatever the thread count).
TEST(XpbdSweep, TheDrapeFallsAsleepAsOnOneThread) {
  const DrapeRun one = form_drape(16, 900, 1), two = form_drape(16, 900, 4);
  std::printf("16^2 form drape after 10 s: %d / %d vertices asleep (one / four threads)\n",
              one.frozen, two.frozen);
  EXPECT_GT(one.frozen, 0);
  EXPECT_EQ(one.frozen, two.frozen);
  EXPECT_GT(one.finished, 0);
  EXPECT_EQ(one.finished, two.finished);
  EXPECT_EQ(max_diff(one.x, two.x), 0.0);
}

// A cut in the middle of the drape: the solver re-cooks the new topology (its cook counted and
// timed, last_cook()) and the sweep on four threads goes on giving the drape of one thread.
TEST(XpbdSweep, AfterACutTheSweepStillGivesTheDrapeOfOneThread) {
  DrapeRun runs[2];
  XpbdSolver::CookStats cook;
  for (int k = 0; k < 2; ++k) {
    Testbed sc = make_scene("form", 24);
    XpbdOptions o;
    o.air_drag = sc.air_drag;
    o.threads = k == 0 ? 1 : 4;
    o.min_parallel_triangles = 0;
    XpbdSolver s(o);
    for (int f = 0; f < 30; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
    ASSERT_EQ(s.last_cook().cooks, 1);
    ASSERT_TRUE(cut_across_material(sc.cloth, 0.51).ok);
    for (int f = 0; f < 30; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
    cook = s.last_cook();
    EXPECT_EQ(cook.cooks, 2);
    runs[k] = DrapeRun{sc.cloth.state.x, sc.cloth.state.v, s.sweeps(), s.sweep_takeovers()};
  }
  std::printf("24^2 re-cook after the cut: %.2f ms (energy %.2f, bending %.2f, sweep plan %.2f)\n",
              cook.total_ms, cook.energy_ms, cook.bending_ms, cook.sweep_ms);
  EXPECT_GT(cook.total_ms, 0.0);
  EXPECT_GE(cook.total_ms, cook.energy_ms + cook.bending_ms + cook.sweep_ms);
  EXPECT_EQ(runs[1].sweeps, 60 * 10);
  ASSERT_EQ(runs[0].x.size(), runs[1].x.size());
  EXPECT_EQ(max_diff(runs[0].x, runs[1].x), 0.0);
  EXPECT_EQ(max_diff(runs[0].v, runs[1].v), 0.0);
}
