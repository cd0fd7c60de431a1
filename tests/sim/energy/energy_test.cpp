// The cloth energy: gradients and Hessians against finite differences, zero energy at rest,
// invariance under rigid motions, bending rigidity of a cylinder, PSD projection.
#include "sim/energy/energy.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "sim/core/thread_pool.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"
#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

namespace {

Cloth small_panel(int n = 5) {
  PanelSpec p;
  p.width = 0.1;
  p.height = 0.08;
  p.nx = n;
  p.ny = n;
  Cloth c = make_panel(p, FabricParams{});
  place_spread(c, Vec3(0, 1, 0), Vec3::UnitX(), Vec3::UnitZ());
  return c;
}

void perturb(Cloth& c, double amp, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amp, amp);
  for (auto& x : c.state.x) x += Vec3(u(rng), u(rng), u(rng));
}

// The cloth energy of c without gravity (the elastic terms), `o` giving the other options.
ClothEnergy elastic_energy(const Cloth& c, EnergyOptions o = {}) {
  o.gravity = false;
  ClothEnergy e;
  e.build(c, o);
  return e;
}

// Central difference (step eps) of the scalar f(x) along coordinate d of vertex i.
template <class F>
double central_difference(const std::vector<Vec3>& x, int i, int d, double eps, F f) {
  auto xp = x, xm = x;
  xp[i][d] += eps;
  xm[i][d] -= eps;
  return (f(xp) - f(xm)) / (2 * eps);
}

// An element's Hessian H (3N x 3N, vertices v) at x against central differences (step eps) of
// its gradient grad(x, g[N]): the worst |FD - H's 3x1 block| / (|H| + floor) over every vertex
// coordinate and gradient block.
template <class Mat, std::size_t N, class Grad>
double hessian_fd_error(const std::vector<Vec3>& x, const std::array<int32_t, N>& v, const Mat& H,
                        double eps, double floor, Grad grad) {
  double worst = 0;
  for (std::size_t k = 0; k < N; ++k)
    for (int d = 0; d < 3; ++d) {
      auto xp = x, xm = x;
      xp[v[k]][d] += eps;
      xm[v[k]][d] -= eps;
      Vec3 gp[N], gm[N];
      grad(xp, gp);
      grad(xm, gm);
      for (std::size_t l = 0; l < N; ++l) {
        const Vec3 fd = (gp[l] - gm[l]) / (2 * eps);
        const double err = (fd - H.template block<3, 1>(3 * l, 3 * k + d)).norm();
        worst = std::max(worst, err / (H.norm() + floor));
      }
    }
  return worst;
}

}  // namespace

TEST(Energy, RestEnergyIsZeroAndGradientVanishes) {
  Cloth c = small_panel();
  ClothEnergy e = elastic_energy(c);
  EXPECT_GT(e.num_hinges(), 0);
  const double E = e.energy(c.state.x, c.state.mass);
  std::vector<Vec3> g;
  e.gradient(c.state.x, c.state.mass, g);
  double gmax = 0;
  for (auto& v : g) gmax = std::max(gmax, v.norm());
  std::printf("rest energy %.3e J, max |grad| %.3e N\n", E, gmax);
  EXPECT_NEAR(E, 0.0, 1e-14);
  EXPECT_LT(gmax, 1e-10);
}

TEST(Energy, GradientMatchesFiniteDifferences) {
  for (auto model : {EnergyOptions::Model::kFem, EnergyOptions::Model::kSprings}) {
    Cloth c = small_panel();
    perturb(c, 0.004, 7);
    EnergyOptions o;
    o.model = model;
    ClothEnergy e;
    e.build(c, o);
    std::vector<Vec3> g;
    e.gradient(c.state.x, c.state.mass, g);
    double maxerr = 0, scale = 0;
    const double eps = 1e-7;
    for (int i = 0; i < c.num_vertices(); ++i)
      for (int d = 0; d < 3; ++d) {
        const double fd = central_difference(
            c.state.x, i, d, eps, [&](const auto& x) { return e.energy(x, c.state.mass); });
        maxerr = std::max(maxerr, std::abs(fd - g[i][d]));
        scale = std::max(scale, std::abs(g[i][d]));
      }
    std::printf("model %d: max gradient error %.3e (scale %.3e)\n", static_cast<int>(model), maxerr,
                scale);
    EXPECT_LT(maxerr, 1e-5 * scale + 1e-9);
  }
}

TEST(Energy, ElementHessiansMatchFiniteDifferences) {
  Cloth c = small_panel(4);
  perturb(c, 0.005, 3);
  ClothEnergy e;
  e.build(c, EnergyOptions{});
  const double eps = 1e-7;
  double worst = 0;
  for (int t = 0; t < e.num_triangles(); ++t) {
    Mat9 H;
    e.tri_hessian(t, c.state.x, H, false);
    worst =
        std::max(worst, hessian_fd_error(c.state.x, e.tri(t), H, eps, 1e-12,
                                         [&](const auto& x, Vec3* g) { e.tri_gradient(t, x, g); }));
    // The vertex blocks used by VBD equal the diagonal blocks of the projected Hessian.
    Mat9 Hp;
    e.tri_hessian(t, c.state.x, Hp, true);
    for (int a = 0; a < 3; ++a) {
      Vec3 g;
      Mat3 B;
      e.tri_vertex_block(t, a, c.state.x, g, B);
      EXPECT_LT((B - Hp.block<3, 3>(3 * a, 3 * a)).norm(), 1e-9 * (Hp.norm() + 1));
    }
    Eigen::SelfAdjointEigenSolver<Mat9> es(0.5 * (Hp + Hp.transpose()));
    EXPECT_GT(es.eigenvalues().minCoeff(), -1e-9 * Hp.norm()) << "projected Hessian not PSD";
  }
  std::printf("worst relative triangle Hessian error %.3e\n", worst);
  EXPECT_LT(worst, 1e-5);
  // Hinges, both models: the exact Hessian (unprojected) against the gradient's FD; the
  // projected one is PSD; the VBD vertex block is the Gauss-Newton diagonal block (PSD).
  for (auto model : {EnergyOptions::Bending::kDihedral, EnergyOptions::Bending::kLinear}) {
    EnergyOptions o;
    o.bending_model = model;
    ClothEnergy eb;
    eb.build(c, o);
    double hworst = 0;
    for (int h = 0; h < eb.num_hinges(); ++h) {
      Mat12 H;
      eb.hinge_hessian(h, c.state.x, H, false);
      hworst = std::max(
          hworst, hessian_fd_error(c.state.x, eb.hinge(h), H, eps, 1e-12,
                                   [&](const auto& x, Vec3* g) { eb.hinge_gradient(h, x, g); }));
      Mat12 Hp;
      eb.hinge_hessian(h, c.state.x, Hp, true);
      Eigen::SelfAdjointEigenSolver<Mat12> es(Hp);
      EXPECT_GT(es.eigenvalues().minCoeff(), -1e-9 * Hp.norm()) << "hinge Hessian not PSD";
      for (int a = 0; a < 4; ++a) {
        Vec3 g, gfull[4];
        Mat3 B;
        eb.hinge_vertex_block(h, a, c.state.x, g, B);
        eb.hinge_gradient(h, c.state.x, gfull);
        EXPECT_LT((g - gfull[a]).norm(), 1e-12 * (gfull[a].norm() + 1e-12));
        Eigen::SelfAdjointEigenSolver<Mat3> eb3(B);
        EXPECT_GT(eb3.eigenvalues().minCoeff(), -1e-12 * (B.norm() + 1e-12));
      }
    }
    std::printf("bending model %d: worst relative hinge Hessian error %.3e\n",
                static_cast<int>(model), hworst);
    EXPECT_LT(hworst, 1e-5);
  }
}

TEST(Energy, DihedralAngleAndGradientAtLargeFolds) {
  // One hinge folded to angles up to +-170 degrees: theta equals the fold, and the energy
  // gradient and exact Hessian match finite differences (relative to their scale).
  PanelSpec p;
  p.width = p.height = 0.01;
  p.nx = p.ny = 2;
  Cloth c = make_panel(p, FabricParams{});
  ClothEnergy e = elastic_energy(c);
  ASSERT_EQ(e.num_hinges(), 1);
  const auto& v = e.hinge(0);
  double gworst = 0, hworst = 0, tworst = 0;
  for (double deg : {-170.0, -90.0, -30.0, -1.0, 0.5, 10.0, 60.0, 120.0, 170.0}) {
    // Edge along z through the origin; triangle 1 in the x-z half-plane x > 0, triangle 2
    // rotated about the edge by the fold.
    const double a = deg * M_PI / 180;
    std::vector<Vec3> x(4);
    x[v[0]] = Vec3(0, 0, 0);
    x[v[1]] = Vec3(0, 0, 0.012);
    x[v[2]] = Vec3(0.009, 0, 0.003);
    x[v[3]] = Vec3(-0.008 * std::cos(a), 0.008 * std::sin(a), 0.007);
    double th;
    Vec3 d[4];
    ASSERT_TRUE(e.hinge_angle(0, x, th, d));
    tworst = std::max(tworst, std::abs(std::abs(th) - std::abs(a)));
    const double eps = 1e-8;
    Vec3 g[4];
    e.hinge_gradient(0, x, g);
    Mat12 H;
    e.hinge_hessian(0, x, H, false);
    for (int k = 0; k < 4; ++k)
      for (int dd = 0; dd < 3; ++dd) {
        const double fd = central_difference(x, v[k], dd, eps,
                                             [&](const auto& y) { return e.hinge_energy(0, y); });
        gworst = std::max(gworst, std::abs(fd - g[k][dd]) / (std::abs(g[k][dd]) + 1e-9));
      }
    hworst = std::max(hworst, hessian_fd_error(x, v, H, eps, 0.0, [&](const auto& y, Vec3* gy) {
                        e.hinge_gradient(0, y, gy);
                      }));
  }
  std::printf("large folds: |theta| error %.2e rad, gradient rel. error %.2e, Hessian %.2e\n",
              tworst, gworst, hworst);
  EXPECT_LT(tworst, 1e-12);
  EXPECT_LT(gworst, 1e-5);
  EXPECT_LT(hworst, 1e-5);
}

TEST(Energy, RigidMotionInvariance) {
  Cloth c = small_panel();
  perturb(c, 0.003, 11);
  ClothEnergy e = elastic_energy(c);
  const double E0 = e.energy(c.state.x, c.state.mass);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  auto x = c.state.x;
  for (auto& p : x) p = R * p + Vec3(0.3, -2, 5);
  const double E1 = e.energy(x, c.state.mass);
  std::printf("E before %.9e, after rigid motion %.9e\n", E0, E1);
  EXPECT_GT(E0, 0);
  EXPECT_NEAR(E1, E0, 1e-9 * E0);
}

TEST(Energy, CylinderBendingMatchesWarpAndWeftRigidity) {
  // Roll a panel onto a cylinder of radius R around an axis along u (curvature along the warp)
  // and along v (weft): E = 1/2 B kappa^2 A for the matching rigidity.
  for (int axis = 0; axis < 2; ++axis) {
    PanelSpec p;
    p.width = p.height = 0.1;
    p.nx = p.ny = 41;
    Cloth c = make_panel(p, FabricParams{});
    const double R = 0.2;
    for (int i = 0; i < c.num_vertices(); ++i) {
      const Vec2 m = c.topo.material[i];
      const double s = axis == 0 ? m.y() : m.x();  // arc length along the curved direction
      const double a = axis == 0 ? m.x() : m.y();
      c.state.x[i] = Vec3(a, R * std::sin(s / R), R * (1 - std::cos(s / R)));
    }
    ClothEnergy e = elastic_energy(c);
    double Eb = 0, Em = 0;
    for (int h = 0; h < e.num_hinges(); ++h) Eb += e.hinge_energy(h, c.state.x);
    for (int t = 0; t < e.num_triangles(); ++t) Em += e.tri_energy(t, c.state.x);
    const double B = axis == 0 ? c.fabric.bending_warp : c.fabric.bending_weft;
    // Hinges cover the strip between the first and last row of interior edges.
    const double expected = 0.5 * B / (R * R) * 0.1 * 0.1;
    std::printf("axis %d: bending %.4e J, expected %.4e J (%.2f %%), membrane %.2e J\n", axis, Eb,
                expected, 100 * (Eb / expected - 1), Em);
    EXPECT_NEAR(Eb / expected, 1.0, 0.05);
  }
}

TEST(Energy, ElasticaReferenceMatchesSmallDeflectionLimit) {
  // For a stiff strip the tip drop tends to q l^4 / (8 B).
  const double l = 0.05, q = 1.0, B = 1.0;
  const Vec2 tip = elastica_tip(l, B, q);
  const double lin = q * std::pow(l, 4) / (8 * B);
  std::printf("elastica drop %.6e, linear %.6e\n", tip.y(), lin);
  EXPECT_NEAR(tip.y() / lin, 1.0, 1e-3);
  // And the inversion recovers B.
  const Vec2 t2 = elastica_tip(0.04, 8e-8, 0.013, 2000);
  const double Bi = elastica_rigidity_for_drop(0.04, 0.013, t2.y());
  EXPECT_NEAR(Bi / 8e-8, 1.0, 1e-3);
}

// --- kTensor bending (the default) -------------------------------------------------------------

namespace {

// A 0.1 x 0.1 m panel, n x n grid; jitter > 0 moves every interior vertex's material
// coordinates by up to jitter * spacing (an irregular mesh).
Cloth tensor_panel(int n, double jitter, unsigned seed = 1) {
  PanelSpec p;
  p.width = p.height = 0.1;
  p.nx = p.ny = n;
  Cloth c = make_panel(p, FabricParams{});
  const double h = 0.1 / (n - 1);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter * h, jitter * h);
  for (int j = 1; j + 1 < n; ++j)
    for (int i = 1; i + 1 < n; ++i) c.topo.material[j * n + i] += Vec2(u(rng), u(rng));
  c.relump_masses();
  return c;
}

// Height field z = 1/2 p^T S p over the material coordinates (x = (u, v, z)).
void set_height_field(Cloth& c, double suu, double svv, double suv) {
  for (int i = 0; i < c.num_vertices(); ++i) {
    const Vec2 m = c.topo.material[i];
    c.state.x[i] =
        Vec3(m.x(), m.y(), 0.5 * (suu * m.x() * m.x() + svv * m.y() * m.y()) + suv * m.x() * m.y());
  }
}

}  // namespace

TEST(Energy, TensorBendingEqualsAnalyticEnergyOfConstantCurvature) {
  // E = 1/2 A (B_weft S_uu^2 + B_warp S_vv^2 + 2 B_twist S_uv^2), B_twist = sqrt(B_warp B_weft).
  // Deep interior (triangles farther than 2.5 cells from the boundary): exact on the regular
  // grid, tight on a jittered mesh; whole sheet: the free-boundary layer (one row of
  // triangles resists no curvature normal to its free edge) is printed and bounded.
  const FabricParams f;
  const double bt = std::sqrt(f.bending_warp * f.bending_weft);
  const struct {
    const char* name;
    double suu, svv, suv;
  } fields[] = {{"warp bend", 0, 4, 0},
                {"weft bend", 4, 0, 0},
                {"twist", 0, 0, 4},
                {"saddle", 3, -3, 0},
                {"mixed", 1, -2.5, 1.5}};
  for (double jitter : {0.0, 0.3})
    for (int variant = 0; variant < 4; ++variant) {
      const auto est = variant == 2   ? EnergyOptions::Curvature::kLocal
                       : variant == 3 ? EnergyOptions::Curvature::kDivergence
                                      : EnergyOptions::Curvature::kBlended;
      const int n = 21;
      Cloth c = tensor_panel(n, jitter);
      EnergyOptions o;
      o.curvature_estimator = est;
      o.curvature_smoothing = variant == 1 ? 2 : 1;
      ClothEnergy e = elastic_energy(c, o);
      ASSERT_TRUE(e.tensor_bending());
      const double h = 0.1 / (n - 1), margin = 2.5 * h;
      double worst_in = 0, worst_all = 0;
      for (const auto& fd : fields) {
        set_height_field(c, fd.suu, fd.svv, fd.suv);
        const double dens = 0.5 * (f.bending_weft * fd.suu * fd.suu +
                                   f.bending_warp * fd.svv * fd.svv + 2 * bt * fd.suv * fd.suv);
        double ein = 0, ain = 0, atot = 0;
        for (int t = 0; t < e.num_triangles(); ++t) {
          atot += e.rest_area(t);
          bool deep = true;
          for (int k = 0; k < 3; ++k) {
            const Vec2 m = c.topo.material[e.tri(t)[k]];
            deep = deep && m.x() > margin && m.y() > margin && m.x() < 0.1 - margin &&
                   m.y() < 0.1 - margin;
          }
          if (!deep) continue;
          ein += e.bending_triangle_energy(t, c.state.x);
          ain += e.rest_area(t);
        }
        const double etot = e.bending_energy(c.state.x);
        const double err_in = ein / (dens * ain) - 1, err_all = etot / (dens * atot) - 1;
        std::printf(
            "estimator %d (W passes %d), jitter %.1f, %-9s: interior %.6e J vs %.6e J (%+.2e), "
            "whole sheet %+.2f %%\n",
            static_cast<int>(est), o.curvature_smoothing, jitter, fd.name, ein, dens * ain, err_in,
            100 * err_all);
        worst_in = std::max(worst_in, std::abs(err_in));
        worst_all = std::max(worst_all, std::abs(err_all));
      }
      if (est == EnergyOptions::Curvature::kDivergence) continue;  // printed for comparison
      if (jitter == 0.0 || est == EnergyOptions::Curvature::kLocal) {
        EXPECT_LT(worst_in, 1e-9);
      } else {
        // GAP: the blended estimator is exact only where the neighbour average removes the
        // divergence form's element noise (regular grids); on this 30 %-jittered mesh the
        // interior is measured 3-7 % too stiff (kLocal is exact here but has the soft mode).
        EXPECT_LT(worst_in, variant == 1 ? 0.03 : 0.09);
      }
      EXPECT_LT(worst_all, 0.12);  // boundary layer of a 20-cell sheet
    }
}

TEST(Energy, TensorBendingRigidMotionsAndFlatStatesCostNothing) {
  Cloth c = tensor_panel(9, 0.3, 4);
  ClothEnergy e = elastic_energy(c);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(1.1, Vec3(-1, 2, 0.5).normalized()).toRotationMatrix();
  // Flat, rotated and translated: zero; and a curved state moved rigidly keeps its energy.
  std::vector<Vec3> x(c.num_vertices());
  for (int i = 0; i < c.num_vertices(); ++i) {
    const Vec2 m = c.topo.material[i];
    x[i] = R * Vec3(m.x(), m.y(), 0) + Vec3(0.4, -1, 2);
  }
  const double e_flat = e.bending_energy(x);
  set_height_field(c, 2, -1, 3);
  perturb(c, 1e-3, 9);
  const double e0 = e.bending_energy(c.state.x);
  for (int i = 0; i < c.num_vertices(); ++i) x[i] = R * c.state.x[i] + Vec3(-3, 0.2, 1);
  const double e1 = e.bending_energy(x);
  // The constraint rows (XPBD's view) carry the same energy.
  double er = 0;
  for (int r = 0; r < e.num_bending_rows(); ++r) {
    Vec3 v = Vec3::Zero();
    for (int k = e.bending_row_offsets()[r]; k < e.bending_row_offsets()[r + 1]; ++k)
      v += e.bending_row_values()[k] * c.state.x[e.bending_row_columns()[k]];
    er += 0.5 * e.bending_row_stiffness(r) * v.squaredNorm();
  }
  EXPECT_NEAR(er, e0, 1e-9 * e0);
  std::printf("flat rotated sheet %.3e J; curved %.9e J, moved %.9e J, by rows %.9e J\n", e_flat,
              e0, e1, er);
  EXPECT_LT(std::abs(e_flat), 1e-9 * e0);  // round-off of P x at |x| ~ 2 m
  EXPECT_GT(e0, 0);
  EXPECT_NEAR(e1, e0, 1e-8 * e0);
}

TEST(Energy, TensorBendingGradientHessianAndVertexBlocks) {
  // E_b = 1/2 x^T (P (x) I3) x: gradient against finite differences of the energy, P symmetric
  // and PSD, P annihilates affine maps, the VBD vertex block is (P x)_i and P_ii I.
  Cloth c = tensor_panel(6, 0.3, 2);
  set_height_field(c, 3, 1, -2);
  perturb(c, 2e-3, 5);
  EnergyOptions o;
  o.gravity = false;  // also for the membrane-only energy below (a copy of o)
  o.model = EnergyOptions::Model::kFem;
  ClothEnergy e = elastic_energy(c, o);
  const int n = c.num_vertices();
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n, n);
  const auto& off = e.bending_offsets();
  for (int i = 0; i < n; ++i)
    for (int k = off[i]; k < off[i + 1]; ++k) P(i, e.bending_columns()[k]) = e.bending_values()[k];
  EXPECT_LT((P - P.transpose()).norm(), 1e-12 * P.norm());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(P);
  std::printf("P: %d x %d, eigenvalues %.3e .. %.3e\n", n, n, es.eigenvalues().minCoeff(),
              es.eigenvalues().maxCoeff());
  EXPECT_GT(es.eigenvalues().minCoeff(), -1e-10 * es.eigenvalues().maxCoeff());
  Eigen::VectorXd one = Eigen::VectorXd::Ones(n), pu(n), pv(n);
  for (int i = 0; i < n; ++i) {
    pu[i] = c.topo.material[i].x();
    pv[i] = c.topo.material[i].y();
  }
  const double pn = P.norm();
  EXPECT_LT((P * one).norm(), 1e-10 * pn);
  EXPECT_LT((P * pu).norm(), 1e-10 * pn * 0.1);
  EXPECT_LT((P * pv).norm(), 1e-10 * pn * 0.1);
  // Bending gradient against central differences of the bending energy (exact for a quadratic).
  std::vector<Vec3> g(n, Vec3::Zero());
  e.add_bending_gradient(c.state.x, g);
  double gerr = 0, gscale = 0;
  const double eps = 1e-6;
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) {
      auto xp = c.state.x, xm = c.state.x;
      xp[i][d] += eps;
      xm[i][d] -= eps;
      const double fd = (e.bending_energy(xp) - e.bending_energy(xm)) / (2 * eps);
      gerr = std::max(gerr, std::abs(fd - g[i][d]));
      gscale = std::max(gscale, std::abs(g[i][d]));
      // Hessian column (i, d) against differences of the gradient: P_ji delta_dd'.
      std::vector<Vec3> gp(n, Vec3::Zero()), gm(n, Vec3::Zero());
      e.add_bending_gradient(xp, gp);
      e.add_bending_gradient(xm, gm);
      for (int j = 0; j < n; ++j) {
        const Vec3 col = (gp[j] - gm[j]) / (2 * eps);
        EXPECT_NEAR(col[d], P(j, i), 1e-6 * pn);
      }
    }
  std::printf("tensor bending gradient error %.3e (scale %.3e)\n", gerr, gscale);
  EXPECT_LT(gerr, 1e-6 * gscale);
  // Vertex blocks: f_i = -(membrane + bending) gradient, H contains P_ii I.
  EnergyOptions nb = o;
  nb.bending = false;
  ClothEnergy em;
  em.build(c, nb);
  for (int i = 0; i < n; ++i) {
    Vec3 f, fm;
    Mat3 H, Hm;
    e.vertex_force_hessian(i, c.state.x, c.state.mass[i], f, H);
    em.vertex_force_hessian(i, c.state.x, c.state.mass[i], fm, Hm);
    EXPECT_LT((fm - f - g[i]).norm(), 1e-9 * (g[i].norm() + 1e-12));
    EXPECT_LT((H - Hm - P(i, i) * Mat3::Identity()).norm(), 1e-9 * pn);
  }
  // The neighbour lists contain P's pattern (VBD colours stay independent).
  std::vector<int> no, nbr;
  e.vertex_neighbours(no, nbr);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (i != j && P(i, j) != 0.0) {
        EXPECT_TRUE(std::find(nbr.begin() + no[i], nbr.begin() + no[i + 1], j) !=
                    nbr.begin() + no[i + 1]);
      }
}

TEST(Energy, TensorBendingWithoutTheVertexMatrixGivesTheSameEnergyAndGradient) {
  // bending_matrix = false (XPBD): no P is assembled; the energy and gradient are summed over
  // the curvature rows and must equal those from P; the per-vertex blocks refuse to run.
  Cloth c = tensor_panel(7, 0.3, 3);
  set_height_field(c, 2, -1, 1.5);
  perturb(c, 2e-3, 9);
  EnergyOptions o;
  ClothEnergy with_p = elastic_energy(c, o);
  o.bending_matrix = false;
  ClothEnergy rows_only = elastic_energy(c, o);
  ASSERT_TRUE(with_p.has_bending_matrix());
  EXPECT_FALSE(rows_only.has_bending_matrix());
  EXPECT_TRUE(rows_only.tensor_bending());
  EXPECT_EQ(rows_only.num_bending_rows(), with_p.num_bending_rows());
  const double ep = with_p.bending_energy(c.state.x), er = rows_only.bending_energy(c.state.x);
  std::printf("bending energy with P %.9e, rows only %.9e\n", ep, er);
  ASSERT_GT(ep, 0);
  EXPECT_NEAR(er, ep, 1e-12 * ep);
  const int n = c.num_vertices();
  std::vector<Vec3> gp(n, Vec3::Zero()), gr(n, Vec3::Zero());
  with_p.add_bending_gradient(c.state.x, gp);
  rows_only.add_bending_gradient(c.state.x, gr);
  double diff = 0, scale = 0;
  for (int i = 0; i < n; ++i) {
    diff = std::max(diff, (gp[i] - gr[i]).norm());
    scale = std::max(scale, gp[i].norm());
  }
  std::printf("bending gradient: largest difference %.3e (scale %.3e)\n", diff, scale);
  ASSERT_GT(scale, 0);
  EXPECT_LT(diff, 1e-12 * scale);
  Vec3 f;
  Mat3 H;
  EXPECT_THROW(rows_only.vertex_force_hessian(n / 2, c.state.x, 1e-3, f, H), std::logic_error);
  std::vector<int> off, nb;
  EXPECT_THROW(rows_only.vertex_neighbours(off, nb), std::logic_error);
}

// Contact detection on the thread pool lists the same contacts, in the same (vertex) order, with
// the same planes and deepest penetration as on one thread: a 48^2 panel dropped on the form.
TEST(Energy, ParallelContactDetectionListsTheSameContacts) {
  Testbed sc = make_scene("form", 48);
  XpbdSolver s;
  for (int f = 0; f < 90; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
  ClothEnergy serial, parallel;
  serial.build(sc.cloth, EnergyOptions{});
  parallel.build(sc.cloth, EnergyOptions{});
  ThreadPool pool(2);
  pool.set_min_parallel(0);
  const double d1 = serial.detect_contacts(sc.cloth, sc.objects);
  const double d2 = parallel.detect_contacts(sc.cloth, sc.objects, &pool);
  std::printf("%zu contacts, deepest %.3f mm\n", serial.contacts().size(), d1 * 1e3);
  ASSERT_GT(serial.contacts().size(), 100u);
  ASSERT_EQ(serial.contacts().size(), parallel.contacts().size());
  EXPECT_EQ(d1, d2);
  for (size_t k = 0; k < serial.contacts().size(); ++k) {
    const Contact &a = serial.contacts()[k], &b = parallel.contacts()[k];
    ASSERT_EQ(a.vertex, b.vertex);
    EXPECT_EQ(a.n, b.n);
    EXPECT_EQ(a.p, b.p);
    EXPECT_EQ(parallel.contact_of(a.vertex), static_cast<int>(k));
  }
  // Detecting again (fewer or other contacts) leaves no stale index behind.
  sc.cloth.state.x[0].y() += 1.0;
  parallel.detect_contacts(sc.cloth, sc.objects, &pool);
  int indexed = 0;
  for (int i = 0; i < sc.cloth.num_vertices(); ++i) indexed += parallel.contact_of(i) >= 0;
  EXPECT_EQ(indexed, static_cast<int>(parallel.contacts().size()));
}

// ClothEnergy::clearance2: a lower bound on how far a vertex without a contact can move before a
// test finds one. Vertices scattered around the form, the floor, a sphere, a plate, a box and a
// hand; each moved by 0.999 of its clearance toward each object (and in random directions) and
// tested again: never a contact. And the bound is not vacuous: most free vertices have one.
TEST(Energy, ContactClearanceIsALowerBound) {
  Testbed sc = make_scene("form", 24);
  SceneObjects& obj = sc.objects;
  obj.spheres.push_back({Vec3(0.45, 1.0, 0.0), 0.08});
  obj.plates.push_back({Vec3(-0.45, 0.9, 0.0), 0.1, 0.1, 0.01});
  obj.boxes.push_back({Vec3(0.0, 0.9, 0.45), Vec3(0.08, 0.05, 0.06)});
  HandProxy hand;
  hand.tracked = hand.collides = true;
  hand.position = Vec3(0.0, 1.3, -0.4);
  hand.tip = Vec3(0.05, 1.35, -0.35);
  obj.hands.push_back(hand);
  Cloth& c = sc.cloth;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (auto& x : c.state.x) x = Vec3(0.6 * u(rng), 0.8 + 0.7 * u(rng), 0.6 * u(rng));
  ClothEnergy e;
  e.build(c, EnergyOptions{});
  e.detect_contacts(c, obj);
  const DressForm& form = *obj.form;
  int free = 0, with_clearance = 0, moves = 0;
  double largest = 0;
  const std::vector<Vec3> start = c.state.x;
  for (int i = 0; i < c.num_vertices(); ++i) {
    if (e.tested_contact(i).vertex >= 0) continue;
    ++free;
    const double cl = std::sqrt(e.clearance2(i));
    if (!(cl > 0)) continue;
    ++with_clearance;
    largest = std::max(largest, cl);
    const Vec3 p = start[i];
    const Vec2 ax = form.centre_at(p.y());
    std::vector<Vec3> dirs = {Vec3(0, -1, 0),
                              Vec3(ax.x() - p.x(), 0, ax.y() - p.z()),
                              Vec3(ax.x() - p.x(), 0.3, ax.y() - p.z()),
                              obj.spheres[0].centre - p,
                              obj.plates[0].centre - p,
                              obj.boxes[0].centre - p,
                              hand.position - p,
                              hand.tip - p};
    for (int k = 0; k < 4; ++k) dirs.emplace_back(u(rng), u(rng), u(rng));
    for (const Vec3& d : dirs) {
      if (d.norm() < 1e-9) continue;
      c.state.x[i] = p + 0.999 * cl * d.normalized();
      e.retest_contact(c, obj, i);
      ++moves;
      EXPECT_LT(e.tested_contact(i).vertex, 0)
          << "vertex " << i << " at " << p.transpose() << " moved " << cl << " m";
    }
    c.state.x[i] = p;
    e.retest_contact(c, obj, i);  // its own clearance again
  }
  std::printf("%d vertices without a contact, %d with a clearance (largest %.3f m), %d moves\n",
              free, with_clearance, largest, moves);
  EXPECT_GT(with_clearance, free / 2);
}
