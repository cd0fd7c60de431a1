// XPBD's element sweep on two threads (XpbdSolver::SweepPhase): the phases of a substep (the
// prediction with the packing, the triangle colours, the bending colours, the unpacking with
// contacts and velocities) run without barriers, each thread waiting only where its items touch
// what the other has still to do. The drape must come out as on one thread, bit for bit, also
// when the caller has to take the worker's half over. (In the TSan build: "thread" in the name.)
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "sim/solvers/xpbd/solver_xpbd.hpp"
#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

namespace {

struct DrapeRun {
  std::vector<Vec3> x, v;
  long sweeps = 0, takeovers = 0, detections = 0;
  int frozen = 0;
};

// The form drape (falls onto the form: contacts, friction, settling, sleeping).
DrapeRun form_drape(int res, int frames, int threads, bool worker = true) {
  Testbed sc = make_scene("form", res);
  XpbdOptions o;
  o.substeps = 10;
  o.air_drag = sc.air_drag;
  o.threads = threads;
  o.min_parallel_triangles = 0;  // small test cloths run on two threads too
  o.freeze = true;
  o.sweep_worker = worker;
  XpbdSolver s(o);
  for (int f = 0; f < frames; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
  return DrapeRun{sc.cloth.state.x,    sc.cloth.state.v,       s.sweeps(),
                  s.sweep_takeovers(), s.contact_detections(), s.frozen_count()};
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

// A worker that never takes its half (as when it is not scheduled): the caller runs both
// halves, alternating between them where each needs the other, with the same result.
TEST(XpbdSweep, TheCallerTakesOverAHalfNobodyClaimed) {
  const DrapeRun one = form_drape(24, 60, 1), alone = form_drape(24, 60, 2, false);
  EXPECT_EQ(alone.sweeps, 60 * 10);
  EXPECT_EQ(alone.takeovers, alone.sweeps);
  EXPECT_EQ(max_diff(one.x, alone.x), 0.0);
  EXPECT_EQ(max_diff(one.v, alone.v), 0.0);
}

// A cloth at rest on the form falls asleep the same way on two threads (the motion sums that
// decide it are taken per vertex block, in block order, whatever the thread count).
TEST(XpbdSweep, TheDrapeFallsAsleepAsOnOneThread) {
  const DrapeRun one = form_drape(16, 900, 1), two = form_drape(16, 900, 2);
  std::printf("16^2 form drape after 10 s: %d / %d vertices asleep (one / two threads)\n",
              one.frozen, two.frozen);
  EXPECT_GT(one.frozen, 0);
  EXPECT_EQ(one.frozen, two.frozen);
  EXPECT_EQ(max_diff(one.x, two.x), 0.0);
}
