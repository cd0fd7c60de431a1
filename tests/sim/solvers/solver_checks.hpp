// Set-ups and checks shared by the dynamic solver tests (solver_xpbd_test, solver_vbd_test):
// each check prints the measured figure, then asserts with the bound its caller passes.
#pragma once

#include <gtest/gtest.h>

#include <cstdio>

#include "sim/solvers/solver_newton.hpp"
#include "sim/testbeds/testbed.hpp"

namespace drape::sim::test {

// `frames` steps of 1/90 s.
template <class S>
void run_frames(S& solver, Testbed& sc, int frames) {
  for (int k = 0; k < frames; ++k) solver.step(sc.cloth, sc.objects, 1.0 / 90);
}

// The res x res hanging sheet relaxed to its static minimum by Newton (tolerance 1e-9): the
// reference the dynamic solvers converge to.
inline Testbed newton_hanging_sheet(int res) {
  Testbed ref = make_hanging_sheet(res);
  StaticOptions so;
  so.tolerance = 1e-9;
  relax_static(ref.cloth, ref.objects, so);
  return ref;
}

// The 20-link chain (1 kg, k = 1e5 N/m) after `frames` frames with `solver`: the top spring's
// force plus the top vertex's weight must carry the whole chain (relative error <= tol).
template <class S>
void expect_chain_carries_its_weight(S& solver, int frames, const char* name, double tol) {
  Testbed sc = make_chain(20, 1.0, 1e5);
  run_frames(solver, sc, frames);
  const auto& x = sc.cloth.state.x;
  const double support = 1e5 * ((x[0] - x[1]).norm() - 0.1) + kGravity;
  std::printf("%s chain: support %.4f N vs weight %.4f N (%.3f %%)\n", name, support, 20 * kGravity,
              100 * (support / (20 * kGravity) - 1));
  EXPECT_NEAR(support / (20 * kGravity), 1.0, tol);
}

// The res x res hanging sheet after `frames` frames with `solver` from its flat start: RMS and
// max vertex distance (m) from the Newton static minimum, printed in mm after `what`.
template <class S>
void sheet_error_vs_newton(S& solver, int res, int frames, const char* what, double& rms,
                           double& mx) {
  const Testbed ref = newton_hanging_sheet(res);
  Testbed sc = make_hanging_sheet(res);
  run_frames(solver, sc, frames);
  position_error(sc.cloth.state.x, ref.cloth.state.x, rms, mx);
  std::printf("%s: rms %.3f mm, max %.3f mm\n", what, rms * 1e3, mx * 1e3);
}

// Freezing: more than half of the resting hanging sheet is frozen; dragging its pinned corner
// for 45 frames wakes more than half again. Returns how far the bottom-left vertex moved (m).
template <class S>
double expect_frozen_then_woken_by_a_drag(Testbed& sc, S& solver) {
  EXPECT_GT(solver.frozen_count(), sc.cloth.num_vertices() / 2);
  const double moved = drag_sheet_corner(sc, solver, 45);
  std::printf("bottom-left moved %.2f mm after the corner moved, frozen %d\n", moved * 1e3,
              solver.frozen_count());
  EXPECT_LT(solver.frozen_count(), sc.cloth.num_vertices() / 2);
  return moved;
}

// A square sheet (0.3 m, res x res vertices) hanging from its whole top edge in the x-y plane,
// started 3 % overstretched along the warp and, with `curl` > 0, bent toward +z by curl * depth^2
// (m) down the sheet: a start away from its static minimum.
inline Cloth hanging_from_an_edge(int res, double curl = 0) {
  PanelSpec p;
  p.width = p.height = 0.3;
  p.nx = p.ny = res;
  Cloth c = make_panel(p, FabricParams{});
  place_spread(c, Vec3(0, 1.0, 0), Vec3::UnitX(), Vec3::UnitY());
  for (int i = 0; i < res; ++i) c.state.flags[(res - 1) * res + i] |= kFlagPinned;
  const double top = c.state.x.back().y();
  for (Vec3& x : c.state.x) {
    const double depth = top - x.y();
    x.y() = top - 1.03 * depth;
    x.z() += curl * depth * depth;
  }
  c.state.x_prev = c.state.x;
  c.relump_masses();
  return c;
}

// Group 0 for every free vertex, -1 for the fixed ones (CoarseCorrection, EquilibriumFinisher).
inline std::vector<int> free_group(const Cloth& c) {
  std::vector<int> g(c.num_vertices());
  for (int i = 0; i < c.num_vertices(); ++i) g[i] = c.is_free(i) ? 0 : -1;
  return g;
}

}  // namespace drape::sim::test
