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
