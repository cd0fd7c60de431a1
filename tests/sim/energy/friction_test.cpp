// Coulomb friction of the cloth on the scene's objects (SceneObjects::friction): the
// position-based solvers' projection (XPBD, Verlet), the lagged dissipation potential of the
// energy-based ones (VBD, Newton) and of the static solve, against the block-on-an-incline
// results: below the angle of repose the cloth stays, above it slides with
// a = g (sin theta - mu cos theta).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "sim/core/cloth.hpp"
#include "sim/core/fabric.hpp"
#include "sim/energy/energy.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/solvers/solver_factory.hpp"
#include "sim/solvers/solver_newton.hpp"

using namespace drape::sim;

namespace {

// A 10 x 10 cm muslin square lying on an incline of angle theta: the top of a sphere of radius
// 1 km, touched at (0, 1, 0) + ... where its normal is (sin theta, cos theta, 0) (over the
// 0.2 m the cloth slides, the slope changes by 0.01 degrees).
struct Incline {
  Cloth cloth;
  SceneObjects objects;
  Vec3 down;  // unit vector down the slope
};

Incline make_incline(double theta_deg, double mu) {
  const double th = theta_deg * M_PI / 180;
  const Vec3 n(std::sin(th), std::cos(th), 0);
  Incline s;
  s.down = Vec3(std::cos(th), -std::sin(th), 0);
  const double R = 1000;
  const Vec3 touch(0, 1, 0);
  Sphere sp;
  sp.radius = R;
  sp.centre = touch - R * n;
  s.objects.spheres.push_back(sp);
  s.objects.floor = false;
  s.objects.friction = mu;
  PanelSpec p;
  p.width = p.height = 0.1;
  p.nx = p.ny = 6;
  s.cloth = make_panel(p, FabricParams{});
  const Vec3 side(0, 0, 1);
  place_spread(s.cloth, touch + s.objects.offset * n - 0.05 * s.down - 0.05 * side, s.down, side);
  s.cloth.relump_masses();
  return s;
}

Vec3 centroid(const Cloth& c) {
  Vec3 m = Vec3::Zero();
  for (const Vec3& x : c.state.x) m += x;
  return m / static_cast<double>(c.num_vertices());
}

// Distance slid down the slope in `seconds` (1/90 s frames), no air drag.
double slide(const std::string& solver, double theta_deg, double mu, double seconds) {
  Incline s = make_incline(theta_deg, mu);
  SolverConfig cfg;
  cfg.air_drag = 0;
  cfg.threads = 1;
  cfg.settle = false;  // an inertia-scaled piece would still slide the same way, but slower
  auto sv = make_solver(solver, cfg);
  EXPECT_TRUE(sv.ok());
  const Vec3 c0 = centroid(s.cloth);
  const int frames = static_cast<int>(std::lround(seconds * 90));
  for (int f = 0; f < frames; ++f) (*sv)->step(s.cloth, s.objects, 1.0 / 90);
  return (centroid(s.cloth) - c0).dot(s.down);
}

struct Tolerance {
  const char* solver;
  double stick_mm;   // largest creep below the angle of repose in 1 s
  double slide_rel;  // relative error of the slid distance above it
};

}  // namespace

// Below the angle of repose (tan 20 deg = 0.36 < mu = 0.5) the cloth stays where it was laid;
// above it (35 deg) it slides with the kinetic friction's acceleration; without friction with
// g sin theta. The position-based friction is exact per substep (the substep's tangential
// motion is cut by mu times the normal correction, which is g cos theta h^2): it sticks exactly
// and slides within 0.3 % of the analytic distance. The energy-based solvers' smoothed
// friction creeps at up to kFrictionSlipSpeed below the threshold. Newton's implicit Euler
// slides 1/N too far (N steps), with or without friction. VBD's adaptive initial guess carries
// the block's answer for vertices touching a surface (without it VBD slid 2.8 of 703 mm).
TEST(Friction, ClothOnAnInclineSticksBelowTheAngleOfReposeAndSlidesAbove) {
  const double g = kGravity, mu = kFormFriction, T = 0.5;
  const double th = 35 * M_PI / 180;
  const double expect = 0.5 * g * (std::sin(th) - mu * std::cos(th)) * T * T;
  const double expect_free = 0.5 * g * std::sin(th) * T * T;
  for (const Tolerance& t : {Tolerance{"xpbd", 1e-3, 0.01}, Tolerance{"verlet", 1e-3, 0.01},
                             Tolerance{"newton", 1.0, 0.03}, Tolerance{"vbd", 1.0, 0.03}}) {
    const double stuck = slide(t.solver, 20, mu, 1.0);
    const double slid = slide(t.solver, 35, mu, T);
    const double free = slide(t.solver, 35, 0.0, T);
    std::printf(
        "%-6s: 20 deg, 1 s: %.4f mm; 35 deg, %.1f s: %.2f mm (analytic %.2f, error %+.2f %%); "
        "frictionless %.2f mm (analytic %.2f)\n",
        t.solver, stuck * 1e3, T, slid * 1e3, expect * 1e3, 100 * (slid / expect - 1), free * 1e3,
        expect_free * 1e3);
    EXPECT_LT(std::abs(stuck), t.stick_mm * 1e-3) << t.solver;
    EXPECT_NEAR(slid, expect, t.slide_rel * expect) << t.solver;
    EXPECT_NEAR(free, expect_free, t.slide_rel * expect_free) << t.solver;
  }
}

// The same on the dress form: a 10 x 4 cm strip laid at centre front on a form whose radius
// shrinks with height so that its surface is inclined 20 degrees from the horizontal, as a
// shoulder is. Below the angle of repose it stays (0.03 mm). With the contact normal taken
// radially instead, the plane under the strip is vertical and carries no
// weight: the strip fell off the form (3.97 m down the slope's direction in the second).
TEST(Friction, ClothOnASlopeOfTheFormSticksBelowTheAngleOfRepose) {
  const double th = 20 * M_PI / 180, yt = 1.05, rt = 0.3;
  const int ns = 49, na = DressForm::kAngles;
  const double dy = 0.0025, y0 = yt - dy * (ns - 1) / 2;
  std::vector<Vec2> centres(ns, Vec2::Zero());
  std::vector<double> radii(static_cast<size_t>(ns) * na);
  for (int j = 0; j < ns; ++j)
    for (int a = 0; a < na; ++a)
      radii[static_cast<size_t>(j) * na + a] = rt - (y0 + dy * j - yt) / std::tan(th);
  SceneObjects objects;
  objects.form = std::make_shared<DressForm>(y0, dy, centres, radii, FormLandmarks{});
  objects.floor = false;
  objects.friction = kFormFriction;
  const Vec3 n(0, std::cos(th), std::sin(th)), down(0, -std::sin(th), std::cos(th)), side(1, 0, 0);
  PanelSpec p;
  p.width = 0.1;  // down the slope
  p.height = 0.04;
  p.nx = 10;
  p.ny = 4;
  // The default solver (the energy's contacts) and the explicit baseline (Verlet: the form's
  // push-out, DressForm::push_outside, and position friction along it).
  for (const char* solver : {"default", "verlet"}) {
    Cloth cloth = make_panel(p, FabricParams{});
    const Vec3 touch(0, yt, rt);
    place_spread(cloth, touch + objects.offset * n - 0.05 * down - 0.02 * side, down, side);
    cloth.relump_masses();
    SolverConfig cfg;
    cfg.air_drag = 0;
    cfg.threads = 1;
    cfg.settle = false;
    auto sv = make_solver(solver, cfg);
    ASSERT_TRUE(sv.ok());
    const Vec3 c0 = centroid(cloth);
    for (int f = 0; f < 90; ++f) (*sv)->step(cloth, objects, 1.0 / 90);
    const double slid = (centroid(cloth) - c0).dot(down);
    std::printf("%s: strip on a 20 degree slope of the form, 1 s: %.4f mm down the slope\n", solver,
                slid * 1e3);
    EXPECT_LT(std::abs(slid), 1e-3) << solver;
  }
}

// The lagged friction potential's gradient and Hessian block against central differences of
// its energy, in the sticking zone (|u| < eps) and sliding beyond it.
TEST(Friction, PotentialGradientAndHessianMatchFiniteDifferences) {
  Incline s = make_incline(10, 0.5);
  ClothEnergy E;
  EnergyOptions eo;
  eo.gravity = true;
  E.build(s.cloth, eo);
  E.set_contact_stiffness(1e4);
  // Push the cloth 0.1 mm into the incline: every vertex has a contact and a normal load.
  for (Vec3& x : s.cloth.state.x)
    x -= 1e-4 * Vec3(std::sin(10 * M_PI / 180), std::cos(10 * M_PI / 180), 0);
  E.detect_contacts(s.cloth, s.objects);
  ASSERT_EQ(static_cast<int>(E.contacts().size()), s.cloth.num_vertices());
  const double eps = 1e-4;
  std::vector<Vec3> anchor = s.cloth.state.x;
  E.set_friction(0.5, eps, anchor);
  E.lag_friction_penalty(s.cloth.state.x);
  const int i = 14;
  ASSERT_GT(E.friction_load(i), 0.0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double reach : {0.3 * eps, 5 * eps}) {
    std::vector<Vec3> x = s.cloth.state.x;
    x[i] += reach * Vec3(u(rng), u(rng), u(rng)).normalized();
    Vec3 g;
    Mat3 H;
    E.friction_gradient_hessian(i, x[i], g, &H);
    const std::vector<double>& m = s.cloth.state.mass;
    const double h = 1e-8;
    double worst_g = 0, worst_h = 0;
    for (int k = 0; k < 3; ++k) {
      std::vector<Vec3> xp = x, xm = x;
      xp[i][k] += h;
      xm[i][k] -= h;
      // The friction part alone: total energy minus the same without friction.
      const double ep = E.energy(xp, m), em = E.energy(xm, m);
      E.clear_friction();
      const double ep0 = E.energy(xp, m), em0 = E.energy(xm, m);
      E.set_friction(0.5, eps, anchor);
      E.lag_friction_penalty(s.cloth.state.x);
      worst_g = std::max(worst_g, std::abs(((ep - ep0) - (em - em0)) / (2 * h) - g[k]));
      Vec3 gp, gm;
      E.friction_gradient_hessian(i, xp[i], gp, nullptr);
      E.friction_gradient_hessian(i, xm[i], gm, nullptr);
      worst_h = std::max(worst_h, ((gp - gm) / (2 * h) - H.col(k)).cwiseAbs().maxCoeff());
    }
    const double scale = 0.5 * E.friction_load(i);
    std::printf(
        "|u| %.1e m: gradient error %.2e of mu lambda, Hessian error %.2e of mu lambda / eps\n",
        reach, worst_g / scale, worst_h * eps / scale);
    EXPECT_LT(worst_g, 1e-5 * scale);
    EXPECT_LT(worst_h, 1e-4 * scale / eps);
    // PSD: the smoothed potential is convex in the tangent plane.
    Eigen::SelfAdjointEigenSolver<Mat3> es(H);
    EXPECT_GT(es.eigenvalues().minCoeff(), -1e-9 * scale / eps);
  }
}

// The static solve with friction polishes a resting state in place: a cloth laid on the
// 20-degree incline (below the angle of repose) is its own frictional equilibrium, while the
// frictionless solve lets it slide off.
TEST(Friction, StaticSolveWithFrictionKeepsAClothResting) {
  Incline s = make_incline(20, kFormFriction);
  const std::vector<Vec3> start = s.cloth.state.x;
  Incline free = s;
  StaticOptions so;
  so.tolerance = 1e-8;
  so.max_iterations = 200;
  so.friction = true;
  const StaticResult r = relax_static(s.cloth, s.objects, so);
  double moved = 0;
  for (int i = 0; i < s.cloth.num_vertices(); ++i)
    moved = std::max(moved, (s.cloth.state.x[i] - start[i]).dot(s.down));
  so.friction = false;  // no equilibrium: each Newton step slides it further
  so.max_iterations = 3;
  relax_static(free.cloth, free.objects, so);
  const double slid = (centroid(free.cloth) - centroid(s.cloth)).dot(s.down);
  std::printf(
      "with friction: residual %.1e after %d iterations, largest move down the slope %.4f mm; "
      "frictionless: %.1f mm further after 3 iterations\n",
      r.residual, r.iterations, moved * 1e3, slid * 1e3);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(moved, so.friction_eps);
  EXPECT_GT(slid, 0.01);
}
