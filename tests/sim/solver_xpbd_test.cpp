// XPBD on the same energy: chain support force, sheet close to the Newton reference.
#include "sim/solver_xpbd.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "sim/scenes.hpp"
#include "sim/solver_newton.hpp"

using namespace drape::sim;

TEST(Xpbd, ChainSupportForceEqualsTotalWeight) {
  StudyScene sc = make_chain(20, 1.0, 1e5);
  XpbdOptions o;
  o.energy.model = EnergyOptions::Model::kSprings;
  o.substeps = 20;
  o.iterations = 20;
  o.damping = 2.0;
  XpbdSolver s(o);
  for (int k = 0; k < 400; ++k) s.step(sc.cloth, sc.objects, 1.0 / 90);
  const auto& x = sc.cloth.state.x;
  const double support = 1e5 * ((x[0] - x[1]).norm() - 0.1) + kGravity;
  std::printf("XPBD chain: support %.4f N vs %.4f N (%.3f %%)\n", support, 20 * kGravity,
              100 * (support / (20 * kGravity) - 1));
  EXPECT_NEAR(support / (20 * kGravity), 1.0, 0.02);
}

TEST(Xpbd, HangingSheetNearNewtonReference) {
  StudyScene ref = make_hanging_sheet(10);
  StaticOptions so;
  so.tolerance = 1e-9;
  relax_static(ref.cloth, ref.objects, so);
  StudyScene sc = make_hanging_sheet(10);
  XpbdOptions o;
  o.substeps = 20;
  o.iterations = 2;
  o.damping = 2.0;
  XpbdSolver s(o);
  for (int k = 0; k < 360; ++k) s.step(sc.cloth, sc.objects, 1.0 / 90);
  double rms, mx;
  position_error(sc.cloth.state.x, ref.cloth.state.x, rms, mx);
  std::printf("XPBD sheet after 4 s vs static Newton: rms %.3f mm, max %.3f mm\n", rms * 1e3,
              mx * 1e3);
  EXPECT_LT(rms, 5e-3);  // stated: 5 mm RMS (XPBD leaves stiffness under-resolved)
}

// Colours are projected in parallel: elements of one colour share no vertex, so the result
// does not depend on the thread count (bit for bit).
TEST(Xpbd, ParallelColoursGiveTheSameResultAsOneThread) {
  std::vector<Vec3> out[2];
  for (int t = 0; t < 2; ++t) {
    StudyScene sc = make_hanging_sheet(24);
    XpbdOptions o;
    o.threads = t + 1;
    XpbdSolver s(o);
    for (int k = 0; k < 30; ++k) s.step(sc.cloth, sc.objects, 1.0 / 90);
    out[t] = sc.cloth.state.x;
    std::printf("%d thread(s): %d colours\n", t + 1, s.num_colours());
    EXPECT_GT(s.num_colours(), 3);
  }
  double rms, mx;
  position_error(out[0], out[1], rms, mx);
  EXPECT_EQ(mx, 0.0);
}

TEST(Xpbd, FreezingSkipsRestingVerticesWakesAndKeepsTheRestState) {
  StudyScene free_run = make_hanging_sheet(10);
  StudyScene sc = make_hanging_sheet(10);
  XpbdOptions o;
  o.damping = 3.0;
  XpbdSolver plain(o);
  o.freeze = true;
  XpbdSolver s(o);
  for (int k = 0; k < 600; ++k) {
    plain.step(free_run.cloth, free_run.objects, 1.0 / 90);
    s.step(sc.cloth, sc.objects, 1.0 / 90);
  }
  double rms, mx;
  position_error(sc.cloth.state.x, free_run.cloth.state.x, rms, mx);
  std::printf("frozen after rest: %d of %d; rest state vs no freezing: rms %.3f mm, max %.3f mm\n",
              s.frozen_count(), sc.cloth.num_vertices(), rms * 1e3, mx * 1e3);
  EXPECT_GT(s.frozen_count(), sc.cloth.num_vertices() / 2);
  EXPECT_LT(mx, 1e-3);
  // Move a pinned corner: neighbours wake and the cloth follows.
  const double moved = drag_sheet_corner(sc, s, 45);
  std::printf("bottom-left moved %.2f mm after the corner moved, frozen %d\n", moved * 1e3,
              s.frozen_count());
  EXPECT_LT(s.frozen_count(), sc.cloth.num_vertices() / 2);
  EXPECT_GT(moved, 5e-3);
}

// Warm-started multipliers shrink XPBD's under-converged sag of a hanging sheet (measured:
// 12.1 -> 6.5 mm at 24^2 with 0.5); the option stays off by default (>= 0.7 diverges).
TEST(Xpbd, WarmStartHalvesTheSagBiasOfAHangingSheet) {
  StudyScene ref = make_hanging_sheet(16);
  StaticOptions so;
  so.tolerance = 1e-9;
  relax_static(ref.cloth, ref.objects, so);
  double err[2];
  for (int k = 0; k < 2; ++k) {
    StudyScene sc = make_hanging_sheet(16);
    XpbdOptions o;
    o.damping = 2.0;
    o.warm_start = 0.5 * k;
    XpbdSolver s(o);
    for (int f = 0; f < 360; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
    double mx;
    position_error(sc.cloth.state.x, ref.cloth.state.x, err[k], mx);
  }
  std::printf("16^2 sheet, 10 substeps, after 4 s: rms %.3f mm (classic), %.3f mm (warm 0.5)\n",
              err[0] * 1e3, err[1] * 1e3);
  EXPECT_LT(err[1], 0.7 * err[0]);
}
