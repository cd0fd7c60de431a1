// The static finish: cycles of Gauss-Seidel sweeps on the static energy and a coarse
// correction converge to the static minimum, lower the energy every cycle and leave fixed
// vertices alone.
#include "sim/rest/equilibrium_finisher.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "sim/solvers/solver_newton.hpp"
#include "tests/sim/solvers/solver_checks.hpp"

using namespace drape::sim;
using namespace drape::sim::test;

// The sheets: hanging_from_an_edge (solver_checks.hpp), 3 % overstretched, here also curled
// toward +z (0.2 depth^2 m): the finish must bring them back.

TEST(EquilibriumFinisher, CyclesConvergeToTheStaticMinimumAndLowerTheEnergy) {
  Cloth c = hanging_from_an_edge(25, 0.2);
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
  Cloth c = hanging_from_an_edge(13, 0.2);
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
