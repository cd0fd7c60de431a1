// Tests of sim/solvers/verlet_solver.cpp: the explicit mass-spring baseline.
#include "sim/solvers/verlet_solver.hpp"

#include <gtest/gtest.h>

using namespace drape::sim;

TEST(Verlet, FreeFallMatchesVerletRecurrence) {
  // Without springs acting (a panel at rest falls rigidly) and alpha = 1, eq. 3-4 from rest
  // gives y_N = y_0 - g h^2 N (N + 1) / 2: the continuous -g t^2 / 2 plus the O(h) start-up term.
  Cloth c = make_panel(PanelSpec{0.1, 0.1, 0.05}, FabricParams{});
  place_spread(c, Vec3(0, 2, 0), Vec3::UnitX(), Vec3::UnitZ());
  VerletParams p;
  p.substeps = 10;
  p.alpha = 1.0;
  VerletSolver s(p);
  SceneObjects scene;
  scene.floor = false;
  const double dt = 0.01;
  for (int k = 0; k < 20; ++k) s.step(c, scene, dt);
  const int N = 200;
  const double h = dt / 10;
  const double expect = 2 - kGravity * h * h * N * (N + 1) / 2;
  std::printf("free fall: y %.12f expected %.12f (continuous %.12f)\n", c.state.x[0].y(), expect,
              2 - 0.5 * kGravity * 0.04);
  for (const Vec3& x : c.state.x) EXPECT_NEAR(x.y(), expect, 1e-9);
  EXPECT_NEAR(c.state.time, 0.2, 1e-12);
}

TEST(Verlet, HangingStripSupportEqualsWeight) {
  // A strip pinned at its top edge comes to rest; the spring forces on the pins then carry the
  // whole weight of the free particles (the chain check of shared/data/README.md).
  FabricParams f;
  PanelSpec spec;
  spec.width = 0.04;
  spec.height = 0.2;
  spec.spacing = 0.02;
  Cloth c = make_panel(spec, f);
  place_spread(c, Vec3(0, 1, 0), Vec3::UnitX(), -Vec3::UnitY());  // v runs downwards
  const int nx = c.topo.grid_nx;
  for (int i = 0; i < nx; ++i) c.state.flags[i] |= kFlagPinned;
  c.relump_masses();
  VerletParams p;
  p.air_drag = 60;  // strong damping to settle fast
  VerletSolver s(p);
  SceneObjects scene;
  scene.floor = false;
  StepStats st;
  for (int k = 0; k < 200; ++k) st = s.step(c, scene, 1.0 / 90);
  EXPECT_FALSE(st.diverged);
  std::printf("substeps per 1/90 s frame (auto): %d, Gershgorin dt bound %.3e s\n", st.substeps,
              s.stable_dt_bound(c));
  double free_weight = 0;
  for (int i = 0; i < c.num_vertices(); ++i)
    if (c.is_free(i)) free_weight += c.state.mass[i] * kGravity;
  double support = 0;
  const Springs& sp = s.springs();
  for (int k = 0; k < sp.size(); ++k) {
    const bool pa = !c.is_free(sp.a[k]), pb = !c.is_free(sp.b[k]);
    if (pa == pb) continue;
    const Vec3 d = c.state.x[sp.b[k]] - c.state.x[sp.a[k]];
    const Vec3 fa = sp.k[k] * (d.norm() - sp.rest[k]) * d.normalized();  // spring force on a
    support -= pa ? fa.y() : -fa.y();  // the pin pushes back on the cloth
  }
  std::printf("support %.9f N, weight %.9f N, rel. error %.2e\n", support, free_weight,
              std::abs(support - free_weight) / free_weight);
  EXPECT_NEAR(support, free_weight, 1e-3 * free_weight);
}

TEST(Verlet, AutoSubstepsStableAndTooFewDiverge) {
  FabricParams f;
  Cloth base = make_panel(PanelSpec{0.1, 0.1, 0.01}, f);
  place_spread(base, Vec3(0, 1, 0), Vec3::UnitX(), -Vec3::UnitY());
  for (int i = 0; i < base.topo.grid_nx; ++i) base.state.flags[i] |= kFlagPinned;
  base.relump_masses();
  SceneObjects scene;
  // Auto: stable.
  Cloth c = base;
  VerletSolver ok{VerletParams{}};
  StepStats st;
  for (int k = 0; k < 20 && !st.diverged; ++k) st = ok.step(c, scene, 1.0 / 90);
  EXPECT_FALSE(st.diverged);
  std::printf("1 cm muslin: %d substeps per frame, h = %.3e s\n", st.substeps,
              1.0 / 90 / st.substeps);
  // 5 substeps per 1/90 s: far beyond the stability limit; the watchdog restores the start state.
  Cloth d = base;
  VerletParams p;
  p.substeps = 5;
  VerletSolver bad(p);
  StepStats sb;
  for (int k = 0; k < 20 && !sb.diverged; ++k) sb = bad.step(d, scene, 1.0 / 90);
  EXPECT_TRUE(sb.diverged);
  EXPECT_EQ(sb.retries, 1);
  EXPECT_EQ(d.validate(), "");  // finite again after the rollback
}

TEST(Verlet, DropOnFloorStaysAboveOffset) {
  FabricParams f;
  Cloth c = make_panel(PanelSpec{0.1, 0.1, 0.02}, f);
  place_spread(c, Vec3(0, 0.05, 0), Vec3::UnitX(), Vec3::UnitZ());
  SceneObjects scene;
  scene.offset = 0.003;
  VerletSolver s{VerletParams{}};
  double pen = 0;
  for (int k = 0; k < 30; ++k) pen = std::max(pen, s.step(c, scene, 1.0 / 90).max_penetration);
  double ymin = 1;
  for (const Vec3& x : c.state.x) ymin = std::min(ymin, x.y());
  std::printf("floor drop: min y %.6f m (offset %.3f), max penetration before response %.2e m\n",
              ymin, scene.offset, pen);
  EXPECT_GT(pen, 0.0);                   // it did land
  EXPECT_GT(ymin, 0.0);                  // never inside the floor
  EXPECT_GT(ymin, scene.offset - 5e-4);  // at most a step's travel into the offset shell
}

// Regression (drop test): a cloth resting on the floor must not keep a velocity into
// it. The response used to move x(t) and x(t-h) together, which kept the inward velocity, so
// gravity accelerated resting vertices into the floor by g h more each substep. With the
// projection default, resting on the floor the vertical velocity stays ~0 (at most g h from the
// last substep's gravity) and every vertex ends exactly at the offset.
TEST(Verlet, RestingContactKeepsNoVelocityIntoTheObject) {
  Cloth c = make_panel(PanelSpec{0.1, 0.1, 0.02}, FabricParams{});
  place_spread(c, Vec3(0, 0.004, 0), Vec3::UnitX(), Vec3::UnitZ());
  SceneObjects scene;
  scene.offset = 0.003;
  VerletSolver s{VerletParams{}};
  int substeps = 0;
  for (int k = 0; k < 90; ++k) substeps = s.step(c, scene, 1.0 / 90).substeps;
  const double h = 1.0 / 90 / substeps;
  double vmin = 0, ymin = 1, ymax = -1;
  for (int i = 0; i < c.num_vertices(); ++i) {
    vmin = std::min(vmin, c.state.v[i].y());
    ymin = std::min(ymin, c.state.x[i].y());
    ymax = std::max(ymax, c.state.x[i].y());
  }
  std::printf(
      "resting on the floor after 1 s: y in [%.6f, %.6f] m (offset %.3f), most negative "
      "v_y %.3e m/s (g h = %.3e)\n",
      ymin, ymax, scene.offset, vmin, kGravity * h);
  EXPECT_NEAR(ymin, scene.offset, 1e-9);
  EXPECT_NEAR(ymax, scene.offset, 1e-9);
  EXPECT_GE(vmin, -1.01 * kGravity * h);  // old response: -g (1 - e^-1) / (1/s), metres/s
}
