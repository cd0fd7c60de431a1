// The static finish: cycles of Gauss-Seidel sweeps on the static energy and a coarse
// correction converge to the static minimum, lower the energy every cycle and leave fixed
// vertices alone.
#include "sim/equilibrium_finisher.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "sim/solver_newton.hpp"
#include "solver_checks.hpp"

using namespace drape::sim;
using namespace drape::sim::test;

namespace {

// A square sheet hanging from its whole top edge, started 3 % overstretched along the warp
// and sheared sideways by a smooth field: the finish must bring it back.
Cloth hanging_sheet(int res) {
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
    x.z() += 0.2 * depth * depth;  // a curl toward +z growing down the sheet
  }
  c.state.x_prev = c.state.x;
  c.relump_masses();
  return c;
}

std::vector<int> free_group(const Cloth& c) {
  std::vector<int> g(c.num_vertices());
  for (int i = 0; i < c.num_vertices(); ++i) g[i] = c.is_free(i) ? 0 : -1;
  return g;
}

}  // namespace

TEST(EquilibriumFinisher, CyclesConvergeToTheStaticMinimumAndLowerTheEnergy) {
  Cloth c = hanging_sheet(25);
  Cloth ref = c;
  StaticOptions so;
  so.tolerance = 1e-8;
  so.contacts = false;
  ASSERT_LT(relax_static(ref, SceneObjects{}, so).residual, 1e-7);
  double rms0, mx0;
  position_error(c.state.x, ref.state.x, rms0, mx0);
  SceneObjects none;
  none.floor = false;
  const std::vector<int> g = free_group(c);
  const std::vector<Vec3> start = c.state.x;
  EquilibriumFinisher fin;
  fin.anchor(c, g);
  double rms = rms0, mx = mx0;
  for (int k = 0; k < 30; ++k) {
    const FinisherStats st = fin.cycle(c, none, g, EnergyOptions{}, nullptr);
    EXPECT_LE(st.energy_after, st.energy_before + 1e-12) << "cycle " << k;
    position_error(c.state.x, ref.state.x, rms, mx);
    if (k % 5 == 4 || k == 0)
      std::printf("cycle %2d: E %.10f -> %.10f J, moved %.3e m, %.3e m rms from the minimum\n", k,
                  st.energy_before, st.energy_after, st.last_move, rms);
  }
  std::printf("30 cycles: %.3e -> %.3e m rms (%.3e -> %.3e m max) from the static minimum\n", rms0,
              rms, mx0, mx);
  EXPECT_LT(rms, 1e-3 * rms0);
  for (int i = 0; i < c.num_vertices(); ++i) {
    if (!c.is_free(i)) {
      EXPECT_EQ(c.state.x[i], start[i]) << "pinned vertex " << i;
    } else {
      EXPECT_EQ(c.state.v[i], Vec3::Zero()) << "vertex " << i;
    }
  }
}

TEST(EquilibriumFinisher, RunStopsOnItsMoveToleranceAndLeavesOtherGroupsAlone) {
  Cloth c = hanging_sheet(13);
  // Only the left half is finished.
  std::vector<int> g = free_group(c);
  for (int i = 0; i < c.num_vertices(); ++i)
    if (c.topo.material[i].x() > 0.15 + 1e-9) g[i] = -1;
  const std::vector<Vec3> start = c.state.x;
  SceneObjects none;
  none.floor = false;
  FinisherOptions o;
  o.cycles = 400;
  o.move_tolerance = 1e-7;
  EquilibriumFinisher fin(o);
  const FinisherStats st = fin.run(c, none, g, EnergyOptions{}, nullptr);
  std::printf("%d cycles, E %.10f -> %.10f J, last cycle moved %.3e m\n", st.cycles,
              st.energy_before, st.energy_after, st.last_move);
  EXPECT_LT(st.cycles, o.cycles);
  EXPECT_LT(st.last_move, o.move_tolerance);
  EXPECT_LT(st.energy_after, st.energy_before);
  int moved = 0;
  for (int i = 0; i < c.num_vertices(); ++i) {
    if (g[i] < 0) {
      EXPECT_EQ(c.state.x[i], start[i]) << "vertex " << i;
    } else {
      moved += (c.state.x[i] - start[i]).norm() > 1e-5;
    }
  }
  EXPECT_GT(moved, 20);
}
