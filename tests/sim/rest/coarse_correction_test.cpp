// The coarse-grid correction: on the fine lattice it is a Newton step (it reaches the static
// minimum), on a coarse one it lowers the energy to the minimum over its space, it leaves
// fixed vertices and other groups alone, and contact vertices slide on their planes.
#include "sim/rest/coarse_correction.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "sim/solvers/solver_newton.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"
#include "sim/testbeds/testbed.hpp"
#include "tests/sim/solvers/solver_checks.hpp"

using namespace drape::sim;
using namespace drape::sim::test;

namespace {

// hanging_from_an_edge (solver_checks.hpp): it contracts to its static minimum, stretched along
// the warp by gravity only (no Poisson coupling: the membrane is in tension everywhere, so the
// PSD projection of its Hessian changes nothing and Newton converges quadratically).
std::vector<Vec3> static_minimum(const Cloth& c) {
  Cloth ref = c;
  StaticOptions so;
  so.tolerance = 1e-8;  // (the solve's round-off floor is 1e-9 .. 3e-8 of a vertex weight)
  so.contacts = false;
  const StaticResult r = relax_static(ref, SceneObjects{}, so);
  EXPECT_LT(r.residual, 1e-7);
  return ref.state.x;
}

}  // namespace

TEST(CoarseCorrection, OnTheFineLatticeItIsNewtonAndReachesTheStaticMinimum) {
  Cloth c = hanging_from_an_edge(8);
  const std::vector<Vec3> ref = static_minimum(c);
  ClothEnergy e;
  e.build(c, EnergyOptions{});
  CoarseOptions o;
  o.factor = 1;  // a node on every vertex: P is the identity on the free vertices
  CoarseCorrection cc(o);
  const std::vector<int> g = free_group(c);
  double first = 0, last = 0;
  for (int k = 0; k < 12; ++k) {
    const CoarseStats st = cc.apply(c, e, g, c.state.x);
    if (k == 0) {
      first = st.residual;
      EXPECT_EQ(st.nodes, 8 * 7);  // the free vertices
    }
    last = st.residual;
    std::printf("step %d: residual %.3e N, alpha %.3g, moved %.3e m\n", k, st.residual, st.alpha,
                st.max_move);
  }
  double rms, mx;
  position_error(c.state.x, ref, rms, mx);
  std::printf(
      "fine lattice after 12 steps: %.3e m from the static minimum (max); residual %.2e -> "
      "%.2e N\n",
      mx, first, last);
  EXPECT_LT(mx, 1e-9);
  EXPECT_LT(last, 1e-8 * first);
}

TEST(CoarseCorrection, CoarseStepsLowerTheEnergyAndConvergeOnTheirSpace) {
  Cloth c = hanging_from_an_edge(25);  // 24 edges: the lattice (every 4 edges) fits exactly
  const std::vector<Vec3> ref = static_minimum(c);
  double rms0, mx0;
  position_error(c.state.x, ref, rms0, mx0);
  ClothEnergy e;
  e.build(c, EnergyOptions{});
  CoarseCorrection cc;  // factor 4
  const std::vector<int> g = free_group(c);
  double first = 0, last = 0, e_prev = e.energy(c.state.x, c.state.mass);
  for (int k = 0; k < 10; ++k) {
    const CoarseStats st = cc.apply(c, e, g, c.state.x);
    std::printf("step %d: applied %d, residual %.3e N, alpha %.3g, moved %.3e m, E %.12f\n", k,
                st.applied ? 1 : 0, st.residual, st.alpha, st.max_move, st.energy_after);
    // (Once at round-off, ~1e-10 of the start, no step lowers E any more: none is taken.)
    if (k < 3) {
      EXPECT_TRUE(st.applied) << "step " << k;
    }
    if (k == 0) {
      first = st.residual;
      EXPECT_EQ(st.nodes, 7 * 7);  // lattice lines every 0.05 m; the pinned top row has none
    }
    if (st.applied) {
      EXPECT_LT(st.energy_after, e_prev + 1e-15) << "step " << k;
      e_prev = st.energy_after;
    }
    last = st.residual;
  }
  double rms, mx;
  position_error(c.state.x, ref, rms, mx);
  std::printf(
      "coarse (every 4 edges) after 10 steps: %.3e m rms from the static minimum (start "
      "%.3e m); coarse residual %.2e -> %.2e N\n",
      rms, rms0, first, last);
  EXPECT_LT(last, 1e-8 * first);
  EXPECT_LT(rms, 0.2 * rms0);
}

TEST(CoarseCorrection, FixedVerticesStayAndGroupsMayNotShareAnElement) {
  Cloth c = hanging_from_an_edge(13);
  ClothEnergy e;
  e.build(c, EnergyOptions{});
  // Only the left half may move.
  std::vector<int> g = free_group(c);
  for (int i = 0; i < c.num_vertices(); ++i)
    if (c.topo.material[i].x() > 0.15 + 1e-9) g[i] = -1;
  const std::vector<Vec3> before = c.state.x;
  CoarseCorrection cc;
  const CoarseStats st = cc.apply(c, e, g, c.state.x);
  EXPECT_TRUE(st.applied);
  int moved = 0;
  for (int i = 0; i < c.num_vertices(); ++i) {
    if (g[i] < 0)
      EXPECT_EQ(c.state.x[i], before[i]) << "vertex " << i;
    else
      moved += (c.state.x[i] - before[i]).norm() > 1e-6;
  }
  EXPECT_GT(moved, 20);
  // Two groups joined by the triangles along the middle column: rejected, x untouched.
  for (int i = 0; i < c.num_vertices(); ++i)
    if (c.is_free(i)) g[i] = c.topo.material[i].x() > 0.15 + 1e-9 ? 1 : 0;
  const std::vector<Vec3> kept = c.state.x;
  EXPECT_THROW(cc.apply(c, e, g, c.state.x), std::invalid_argument);
  EXPECT_EQ(c.state.x, kept);
  // A rejected call leaves nothing half built: the same groups are rejected again.
  EXPECT_THROW(cc.apply(c, e, g, c.state.x), std::invalid_argument);
  EXPECT_EQ(c.state.x, kept);
}

TEST(CoarseCorrection, ContactVerticesSlideOnTheirPlanes) {
  // A cloth draped on the form by XPBD for a second; then one correction with the contacts
  // detected there.
  Testbed sc = make_scene("form", 24);
  XpbdSolver s;
  for (int k = 0; k < 90; ++k) s.step(sc.cloth, sc.objects, 1.0 / 90);
  ClothEnergy e;
  e.build(sc.cloth, EnergyOptions{});
  e.set_form(&sc.objects);
  e.detect_contacts(sc.cloth, sc.objects);
  CoarseOptions o;
  const std::vector<Vec3> before = sc.cloth.state.x;
  std::vector<int> g = free_group(sc.cloth);
  CoarseCorrection cc(o);
  const CoarseStats st = cc.apply(sc.cloth, e, g, sc.cloth.state.x);
  ASSERT_TRUE(st.applied);
  int sliding = 0;
  double worst = 0, moved = 0;
  for (const Contact& ct : e.contacts()) {
    const int i = ct.vertex;
    if (!sc.cloth.is_free(i) || ct.n.dot(before[i] - ct.p) >= o.contact_reach) continue;
    ++sliding;
    const Vec3 d = sc.cloth.state.x[i] - before[i];
    worst = std::max(worst, std::abs(ct.n.dot(d)));
    moved = std::max(moved, d.norm());
  }
  std::printf("%d contact vertices: largest move %.3e m, largest normal part %.3e m\n", sliding,
              moved, worst);
  EXPECT_GT(sliding, 10);
  EXPECT_GT(moved, 1e-7);
  EXPECT_LT(worst, 1e-12);
}

// A cloth without a nominal grid spacing (imported, remeshed): the lattice takes its mean
// material edge, and the step still lowers the energy.
TEST(CoarseCorrection, ClothWithoutANominalSpacingUsesItsMeanEdge) {
  Cloth c = hanging_from_an_edge(13);
  c.topo.spacing = 0;
  ClothEnergy e;
  e.build(c, EnergyOptions{});
  CoarseCorrection cc;
  const double e0 = e.energy(c.state.x, c.state.mass);
  const CoarseStats st = cc.apply(c, e, free_group(c), c.state.x);
  // Mean edge of the criss-cross grid (0.025 m sides, 0.035 m diagonals) ~0.028 m: nodes every
  // ~0.11 m over 0.3 m, 4-5 per axis.
  std::printf("%d nodes, E %.9f -> %.9f J\n", st.nodes, e0, st.energy_after);
  EXPECT_GE(st.nodes, 16);
  EXPECT_LE(st.nodes, 25);
  EXPECT_TRUE(st.applied);
  EXPECT_LT(st.energy_after, e0);
}

// Nodes with rotations: a rigid rotation of a curved sheet lies in the coarse space (a partition
// of unity of locally rigid motions reproduces a global one exactly), while translations alone
// can only follow it by a bilinear field, which stretches a curved patch.
TEST(CoarseCorrection, NodeRotationsReproduceARigidMotionOfACurvedSheet) {
  PanelSpec p;
  p.width = p.height = 0.3;
  p.nx = p.ny = 17;
  Cloth c = make_panel(p, FabricParams{});
  // Rolled onto a cylinder of radius 0.08 m about the y axis (the sheet's width: 215 degrees).
  const double R = 0.08;
  for (int i = 0; i < c.num_vertices(); ++i) {
    const Vec2 m = c.topo.material[i];
    c.state.x[i] = Vec3(R * std::sin(m.x() / R), m.y(), R * std::cos(m.x() / R));
  }
  c.state.x_prev = c.state.x;
  ClothEnergy e;
  e.build(c, EnergyOptions{});
  const std::vector<int> g = free_group(c);
  // A small rotation about a tilted axis through an off-centre point, and a translation.
  const Vec3 w = Vec3(0.3, 1.0, -0.5).normalized() * 1e-3, o(0.05, 0.1, -0.02),
             t(2e-4, -1e-4, 3e-4);
  std::vector<Vec3> f(c.num_vertices());
  double f2 = 0;
  for (int i = 0; i < c.num_vertices(); ++i) {
    f[i] = t + w.cross(c.state.x[i] - o);
    f2 += f[i].squaredNorm();
  }
  double rest[2] = {0, 0};
  for (int rot = 0; rot < 2; ++rot) {
    CoarseOptions o2;
    o2.rotations = rot == 1;
    CoarseCorrection cc(o2);
    cc.apply(c, e, g, c.state.x);  // builds the lattice and the prolongation at x
    std::vector<Vec3> fitted;
    ASSERT_TRUE(cc.fit(f, fitted));
    double r2 = 0;
    for (int i = 0; i < c.num_vertices(); ++i) r2 += (f[i] - fitted[i]).squaredNorm();
    rest[rot] = std::sqrt(r2 / f2);
    std::printf("nodes %s: the fit misses %.3e of the rigid motion\n",
                rot ? "with rotations   " : "translations only", rest[rot]);
  }
  EXPECT_LT(rest[1], 1e-6);
  EXPECT_GT(rest[0], 1e-3);
}

// With rotations the coarse matrix is formed from a fine block pattern cooked from the energy's
// elements: a call with another energy of the same cloth (here without the bending matrix, so
// with a different pattern) rebuilds it instead of indexing the old one, and both steps agree.
TEST(CoarseCorrection, AnotherEnergyOfTheSameClothRebuildsTheFinePattern) {
  Cloth c = hanging_from_an_edge(13);
  ClothEnergy with_matrix, rows_only;
  with_matrix.build(c, EnergyOptions{});
  EnergyOptions eo;
  eo.bending_matrix = false;
  rows_only.build(c, eo);
  CoarseOptions o;
  o.rotations = true;
  CoarseCorrection cc(o);
  const std::vector<int> g = free_group(c);
  std::vector<Vec3> xa = c.state.x, xb = c.state.x;
  const CoarseStats a = cc.apply(c, with_matrix, g, xa);
  const CoarseStats b = cc.apply(c, rows_only, g, xb);
  EXPECT_TRUE(a.applied);
  EXPECT_TRUE(b.applied);
  EXPECT_TRUE(b.rebuilt);
  // The same energy summed two ways: the same step to round-off.
  double d = 0;
  for (int i = 0; i < c.num_vertices(); ++i) d = std::max(d, (xa[i] - xb[i]).norm());
  std::printf("steps with the bending matrix and with its rows: %.3e m apart (moved %.3e m)\n", d,
              a.max_move);
  EXPECT_LT(d, 1e-12);
}
