// Newton (implicit Euler + sparse LDLT) and the static solver: chain support force, Peirce
// cantilever against the exact elastica at two resolutions, static sheet is an equilibrium.
#include "sim/solver_newton.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "sim/scenes.hpp"

using namespace drape::sim;

TEST(Newton, ChainSupportForceEqualsTotalWeight) {
  StudyScene sc = make_chain(20, 1.0, 1e5);
  NewtonOptions o;
  o.energy.model = EnergyOptions::Model::kSprings;
  NewtonSolver s(o);
  StaticOptions so;
  so.energy.model = EnergyOptions::Model::kSprings;
  so.tolerance = 1e-10;
  StaticResult r = relax_static(sc.cloth, sc.objects, so);
  const auto& x = sc.cloth.state.x;
  const double tension = 1e5 * ((x[0] - x[1]).norm() - 0.1);
  const double support = tension + 1.0 * kGravity;
  std::printf("static chain: support %.6f N, weight %.6f N, %d iterations\n", support,
              20 * kGravity, r.iterations);
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(support, 20 * kGravity, 1e-6 * 20 * kGravity);
  // Dynamic Newton run to rest gives the same force.
  StudyScene d = make_chain(20, 1.0, 1e5);
  for (int k = 0; k < 300; ++k) s.step(d.cloth, d.objects, 1.0 / 90);
  const auto& y = d.cloth.state.x;
  const double sup2 = 1e5 * ((y[0] - y[1]).norm() - 0.1) + kGravity;
  std::printf("dynamic chain after 3.3 s: support %.4f N (error %.3f %%)\n", sup2,
              100 * (sup2 / (20 * kGravity) - 1));
  EXPECT_NEAR(sup2 / (20 * kGravity), 1.0, 0.01);
}

namespace {
// Solves the Peirce strip statically and inverts the exact elastica for the rigidity per width.
// weft: the strip runs along the weft (material u and v swapped: same vertices and placement).
double cantilever_rigidity(double spacing, double overhang, double width, const FabricParams& f,
                           const EnergyOptions& eo, double& tip_drop, bool weft) {
  StudyScene sc = make_cantilever(overhang, spacing, width, f);
  if (weft)
    for (auto& m : sc.cloth.topo.material) m = Vec2(m.y(), m.x());
  StaticOptions so;
  so.tolerance = 1e-7;
  so.max_iterations = 300;
  so.energy = eo;
  StaticResult r = relax_static(sc.cloth, sc.objects, so);
  std::printf("cantilever static solve: %d iterations, residual %.2e\n", r.iterations, r.residual);
  EXPECT_LT(r.residual, 1e-5);
  const int nx = sc.cloth.topo.grid_nx, ny = sc.cloth.topo.grid_ny;
  double drop = 0;
  for (int i = 0; i < nx; ++i) drop += 1.0 - sc.cloth.state.x[(ny - 1) * nx + i].y();
  drop /= nx;
  tip_drop = drop;
  const double w = spacing * (nx - 1);
  const double len = spacing * (ny - 3);  // overhang beyond the last clamped row
  const double q = sc.cloth.fabric.areal_density * kGravity * w;
  return elastica_rigidity_for_drop(len, q, drop) / w;
}

// Rigidity error (recovered / true - 1) at 8 and 12 cells along the Peirce overhang l = 2c.
void cantilever_errors(double width_cells, const FabricParams& f, const EnergyOptions& eo,
                       double err[2], const char* label, bool weft = false) {
  const double B = weft ? f.bending_weft : f.bending_warp;
  const double c = std::cbrt(B / (f.areal_density * kGravity));
  int k = 0;
  for (double spacing : {2.0 * c / 8, 2.0 * c / 12}) {
    double drop = 0;
    const double width = width_cells > 0 ? width_cells * spacing : 0.01;
    const double Br = cantilever_rigidity(spacing, 2 * c, width, f, eo, drop, weft);
    err[k++] = Br / B - 1;
    std::printf(
        "%s: spacing %.2f mm: tip drop %.2f mm (chord %.1f deg), B recovered %.4e vs %.4e N m "
        "(rigidity error %+.2f %%; target +-5 %%)\n",
        label, spacing * 1e3, drop * 1e3, std::atan2(drop, 2 * c) * 180 / M_PI, Br, B,
        100 * err[k - 1]);
  }
}

EnergyOptions dihedral() {
  EnergyOptions o;
  o.bending_model = EnergyOptions::Bending::kDihedral;
  return o;
}
}  // namespace

// Issue-3 target: rigidity within +-5 % of the exact elastica at two resolutions (8 and 12
// cells along the overhang), along the warp and along the weft. Met by the default bending
// model (kTensor, blended curvature estimator, rigid-boundary rule at the clamp): measured
// -3.5 % / -1.6 % (warp) (docs/solvers.md "Cantilever").
TEST(Newton, CantileverRigidityAgainstElasticaAtTwoResolutions) {
  const FabricParams f;
  double warp[2], weft[2];
  cantilever_errors(0, f, EnergyOptions{}, warp, "muslin 1 cm strip, warp");
  cantilever_errors(0, f, EnergyOptions{}, weft, "muslin 1 cm strip, weft", true);
  for (double e : warp) EXPECT_NEAR(e, 0.0, 0.05);
  for (double e : weft) EXPECT_NEAR(e, 0.0, 0.05);
  // Converging: the finer strip is not worse.
  EXPECT_LE(std::abs(warp[1]), std::abs(warp[0]) + 0.005);
  EXPECT_LE(std::abs(weft[1]), std::abs(weft[0]) + 0.005);
}

// Why the estimator matters: the local per-triangle estimate S_t = L_t^-1 theta_t is exact for
// constant curvature but lets alternating diagonal folds bend the strip for twist energy
// only (its element average is not the surface's Hessian): the strip is ~23 % soft. The
// dihedral hinges have the same soft mode (diagonal hinges in series, -15..-18 %).
TEST(Newton, CantileverSoftModeOfTheLocalEstimatorAndOfTheHinges) {
  const FabricParams f;
  EnergyOptions local;
  local.curvature_estimator = EnergyOptions::Curvature::kLocal;
  double el[2], ed[2];
  cantilever_errors(0, f, local, el, "kTensor, local estimator (soft mode)");
  cantilever_errors(0, f, dihedral(), ed, "kDihedral hinges (soft mode)");
  for (int k = 0; k < 2; ++k) {
    EXPECT_LT(el[k], -0.15);
    EXPECT_LT(ed[k], -0.10);
  }
}

// The clamp: without the rigid-boundary rule (the clamped side does not curve) the strip is
// first-order too soft (-30 % / -20 %, shrinking with h).
TEST(Newton, CantileverNeedsTheRigidBoundaryRule) {
  const FabricParams f;
  EnergyOptions no_clamp;
  no_clamp.rigid_boundary_hinges = false;
  double err[2];
  cantilever_errors(0, f, no_clamp, err, "kTensor without the clamp rule");
  EXPECT_LT(err[0], -0.15);
  EXPECT_LT(err[0], err[1]);  // first order: the error shrinks with h
}

// The dihedral hinges with stiff diagonals (a one-cell strip whose diagonal hinges only see
// bending_weft = 1e-3 N m): the hinge and clamp discretisation alone, within +-5 %
// (-3.0 % / -1.6 %, the same as kTensor's default).
TEST(Newton, CantileverHingeAndClampWithinFivePercentWhenDiagonalsAreStiff) {
  FabricParams f;
  f.bending_weft = 1e-3;
  double err[2];
  cantilever_errors(1, f, dihedral(), err, "dihedral, 1-cell strip, stiff diagonals");
  for (double e : err) EXPECT_NEAR(e, 0.0, 0.05);
}

// The dihedral hinges' soft mode: B_eff = 1 / (1/B_warp + 1/(4 B_diag)), B_diag = (B_warp +
// B_weft)/2 for a one-cell muslin strip (-23.5 %).
TEST(Newton, CantileverDiagonalHingesInSeriesExplainTheGap) {
  const FabricParams f;
  const double Bd = 0.5 * (f.bending_warp + f.bending_weft);
  const double predicted = 1.0 / (1.0 / f.bending_warp + 1.0 / (4 * Bd)) / f.bending_warp - 1;
  double err[2];
  cantilever_errors(1, f, dihedral(), err, "dihedral, 1-cell muslin strip");
  std::printf("series-compliance prediction %+.2f %%\n", 100 * predicted);
  for (double e : err) EXPECT_NEAR(e, predicted, 0.02);
}

TEST(Newton, StaticSheetIsAnEquilibrium) {
  StudyScene sc = make_hanging_sheet(10);
  StaticOptions so;
  so.tolerance = 1e-8;
  StaticResult r = relax_static(sc.cloth, sc.objects, so);
  std::printf("static sheet: %d iterations, residual %.2e, %.1f ms\n", r.iterations, r.residual,
              r.ms);
  EXPECT_TRUE(r.converged);
  ClothEnergy e;
  e.build(sc.cloth, EnergyOptions{});
  std::vector<Vec3> g;
  e.gradient(sc.cloth.state.x, sc.cloth.state.mass, g);
  double worst = 0;
  for (int i = 0; i < sc.cloth.num_vertices(); ++i)
    if (sc.cloth.is_free(i))
      worst = std::max(worst, g[i].norm() / (sc.cloth.state.mass[i] * kGravity));
  EXPECT_LT(worst, 1e-6);
  // The sheet sags below its pins.
  EXPECT_LT(sc.cloth.state.x[0].y(), 0.7);
}

TEST(Newton, UnknownSceneFallsBackAndBadStateIsNotHidden) {
  // A cloth whose positions contain NaN: the Newton step must not report convergence.
  StudyScene sc = make_hanging_sheet(6);
  sc.cloth.state.x[3] = Vec3(NAN, 0, 0);
  NewtonSolver s;
  StepStats st = s.step(sc.cloth, sc.objects, 1.0 / 90);
  EXPECT_FALSE(std::isfinite(st.residual) && st.residual < 1e-6);
}
