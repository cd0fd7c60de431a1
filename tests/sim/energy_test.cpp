// The cloth energy: gradients and Hessians against finite differences, zero energy at rest,
// invariance under rigid motions, bending rigidity of a cylinder, PSD projection.
#include "sim/energy.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <random>

#include "sim/scenes.hpp"

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

}  // namespace

TEST(Energy, RestEnergyIsZeroAndGradientVanishes) {
  Cloth c = small_panel();
  EnergyOptions o;
  o.gravity = false;
  ClothEnergy e;
  e.build(c, o);
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
        auto xp = c.state.x, xm = c.state.x;
        xp[i][d] += eps;
        xm[i][d] -= eps;
        const double fd = (e.energy(xp, c.state.mass) - e.energy(xm, c.state.mass)) / (2 * eps);
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
    const auto& v = e.tri(t);
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) {
        auto xp = c.state.x, xm = c.state.x;
        xp[v[k]][d] += eps;
        xm[v[k]][d] -= eps;
        Vec3 gp[3], gm[3];
        e.tri_gradient(t, xp, gp);
        e.tri_gradient(t, xm, gm);
        for (int l = 0; l < 3; ++l) {
          const Vec3 fd = (gp[l] - gm[l]) / (2 * eps);
          const double err = (fd - H.block<3, 1>(3 * l, 3 * k + d)).norm();
          worst = std::max(worst, err / (H.norm() + 1e-12));
        }
      }
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
      const auto& v = eb.hinge(h);
      for (int k = 0; k < 4; ++k)
        for (int d = 0; d < 3; ++d) {
          auto xp = c.state.x, xm = c.state.x;
          xp[v[k]][d] += eps;
          xm[v[k]][d] -= eps;
          Vec3 gp[4], gm[4];
          eb.hinge_gradient(h, xp, gp);
          eb.hinge_gradient(h, xm, gm);
          for (int l = 0; l < 4; ++l)
            hworst = std::max(
                hworst, ((gp[l] - gm[l]) / (2 * eps) - H.block<3, 1>(3 * l, 3 * k + d)).norm() /
                            (H.norm() + 1e-12));
        }
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
  EnergyOptions o;
  o.gravity = false;
  ClothEnergy e;
  e.build(c, o);
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
        auto xp = x, xm = x;
        xp[v[k]][dd] += eps;
        xm[v[k]][dd] -= eps;
        const double fd = (e.hinge_energy(0, xp) - e.hinge_energy(0, xm)) / (2 * eps);
        gworst = std::max(gworst, std::abs(fd - g[k][dd]) / (std::abs(g[k][dd]) + 1e-9));
        Vec3 gp[4], gm[4];
        e.hinge_gradient(0, xp, gp);
        e.hinge_gradient(0, xm, gm);
        for (int l = 0; l < 4; ++l)
          hworst = std::max(
              hworst,
              ((gp[l] - gm[l]) / (2 * eps) - H.block<3, 1>(3 * l, 3 * k + dd)).norm() / H.norm());
      }
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
  EnergyOptions o;
  o.gravity = false;
  ClothEnergy e;
  e.build(c, o);
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
    EnergyOptions o;
    o.gravity = false;
    ClothEnergy e;
    e.build(c, o);
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
