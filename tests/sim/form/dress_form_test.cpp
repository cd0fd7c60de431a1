// The section model: parametric girths, O(1) collision vs analytic, interpolation, landmarks.
#include "sim/form/dress_form.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <set>

#include "sim/io/mesh_io.hpp"

namespace drape::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kN = DressForm::kAngles;

DressForm circle_form(double r, Vec2 c, double y0 = 0.5, double dy = 0.01, int ns = 50) {
  std::vector<Vec2> centres(ns, c);
  std::vector<double> radii(static_cast<size_t>(ns) * kN, r);
  FormLandmarks lm;
  lm.bottom_y = y0, lm.top_y = y0 + dy * (ns - 1);
  return DressForm(y0, dy, centres, radii, lm);
}

TEST(DressForm, ParametricGirthsAllSizes) {
  for (const char* size : {"7AR", "9AR", "11AR", "13AR"}) {
    auto m = measurements_for_size(size);
    ASSERT_TRUE(m.ok()) << m.error();
    auto f = DressForm::from_measurements(*m);
    ASSERT_TRUE(f.ok()) << f.error();
    const auto& lm = f->landmarks();
    const double gb = f->girth_at(lm.bust_y), gw = f->girth_at(lm.waist_y),
                 gh = f->girth_at(lm.hip_y);
    std::printf("%s: bust %.2f (want %.1f) waist %.2f (want %.1f) hip %.2f (want %.1f) mm\n", size,
                gb * 1e3, m->bust_girth * 1e3, gw * 1e3, m->waist_girth * 1e3, gh * 1e3,
                m->hip_girth * 1e3);
    EXPECT_NEAR(gb, m->bust_girth, 0.002);
    EXPECT_NEAR(gw, m->waist_girth, 0.002);
    EXPECT_NEAR(gh, m->hip_girth, 0.002);
    EXPECT_DOUBLE_EQ(lm.bust_y, m->bust_height);
    EXPECT_DOUBLE_EQ(lm.waist_y, m->waist_height);
    EXPECT_DOUBLE_EQ(lm.hip_y, m->hip_height);
    EXPECT_NEAR(f->min_y(), m->bottom_height, 1e-12);
    EXPECT_NEAR(f->max_y(), m->neck_height, 0.0025);
  }
}

TEST(DressForm, ParametricOffGridLandmarksExact) {
  FormMeasurements m;  // 9AR defaults with heights off the 2.5 mm grid
  m.bust_height = 1.1517, m.waist_height = 0.9691, m.hip_height = 0.7813;
  auto f = DressForm::from_measurements(m, 0.0025);
  ASSERT_TRUE(f.ok()) << f.error();
  const double eb = f->girth_at(m.bust_height) - m.bust_girth;
  const double ew = f->girth_at(m.waist_height) - m.waist_girth;
  const double eh = f->girth_at(m.hip_height) - m.hip_girth;
  std::printf("off-grid errors: bust %.4f waist %.4f hip %.4f mm\n", eb * 1e3, ew * 1e3, eh * 1e3);
  EXPECT_LT(std::abs(eb), 1e-4);
  EXPECT_LT(std::abs(ew), 1e-4);
  EXPECT_LT(std::abs(eh), 1e-4);
}

TEST(DressForm, ParametricShapeIsTorsoLike) {
  auto f = DressForm::from_measurements(FormMeasurements{});
  ASSERT_TRUE(f.ok()) << f.error();
  const auto& lm = f->landmarks();
  auto width_depth = [&](double y) {
    double xmax = -1, xmin = 1, zmax = -1, zmin = 1;
    for (int n = 0; n < kN; ++n) {
      const Vec3 p = f->surface_at(y, DressForm::theta(n));
      xmax = std::max(xmax, p.x()), xmin = std::min(xmin, p.x());
      zmax = std::max(zmax, p.z()), zmin = std::min(zmin, p.z());
    }
    return std::array<double, 4>{xmax - xmin, zmax - zmin, zmax, zmin};
  };
  const auto b = width_depth(lm.bust_y), w = width_depth(lm.waist_y), h = width_depth(lm.hip_y);
  std::printf(
      "width/depth: bust %.3f waist %.3f hip %.3f; front z bust %.3f waist %.3f; back z "
      "hip %.3f waist %.3f\n",
      b[0] / b[1], w[0] / w[1], h[0] / h[1], b[2], w[2], h[3], w[3]);
  // Non-circular sections near the README's ratios (bust points and seat bumps add a little).
  EXPECT_NEAR(b[0] / b[1], 1.3, 0.15);
  EXPECT_NEAR(w[0] / w[1], 1.3, 0.15);
  EXPECT_NEAR(h[0] / h[1], 1.4, 0.15);
  EXPECT_GT(b[2], w[2] + 0.02);  // bust protrudes forward of the waist
  EXPECT_LT(h[3], w[3] - 0.02);  // seat protrudes backward of the waist
  // Symmetric about the centre front/back plane.
  EXPECT_NEAR(f->radius_at(lm.bust_y, 0.7), f->radius_at(lm.bust_y, 2 * kPi - 0.7), 1e-9);
  // Monotone interpolation: between waist and hip the girth stays within [waist, hip].
  for (double y = lm.hip_y; y <= lm.waist_y; y += 0.005) {
    const double g = f->girth_at(y);
    EXPECT_GE(g, 0.64 - 1e-6);
    EXPECT_LE(g, 0.91 + 1e-6);
  }
  // Smooth along the height: the second difference of the girth between neighbouring sections
  // (2.5 mm apart) stays small from the bottom to the armpit (above it the shoulders narrow
  // quickly into the neck).
  double worst = 0;
  for (int j = 1; j + 1 < f->num_sections() && f->section_y(j) < lm.bust_y + 0.06; ++j) {
    const double d2 = f->girth_at(f->section_y(j + 1)) - 2 * f->girth_at(f->section_y(j)) +
                      f->girth_at(f->section_y(j - 1));
    worst = std::max(worst, std::abs(d2));
  }
  std::printf("largest girth second difference below the armpit: %.3f mm\n", worst * 1e3);
  EXPECT_LT(worst, 0.0015);  // a kink (slope jump at a knot) would give several mm
}

TEST(DressForm, GirthOfCircleIsPolygonPerimeter) {
  const double r = 0.13;
  DressForm f = circle_form(r, Vec2(0.02, -0.03));
  const double expect = 2 * kN * r * std::sin(kPi / kN);
  EXPECT_NEAR(f.girth_at(0.7), expect, 1e-12);
  EXPECT_NEAR(f.girth_at(0.7), 2 * kPi * r, 2 * kPi * r * 1e-4);
}

TEST(DressForm, PushOutsideCylinderAnalytic) {
  const double r = 0.12, off = 0.004;
  const Vec2 c(0.03, -0.02);
  DressForm f = circle_form(r, c);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ang(-10, 10), rad(0.0, 0.2), hy(0.5, 0.99);
  double max_err = 0;
  for (int i = 0; i < 2000; ++i) {
    const double th = ang(rng), d = rad(rng), y = hy(rng);
    Vec3 p(c.x() + d * std::sin(th), y, c.y() + d * std::cos(th));
    const Vec3 p0 = p;
    const double pen = f.push_outside(p, off);
    if (d < r + off) {
      ASSERT_GT(pen, 0.0);
      EXPECT_NEAR(pen, r + off - d, 1e-12);
      const double nd = std::hypot(p.x() - c.x(), p.z() - c.y());
      max_err = std::max(max_err, std::abs(nd - (r + off)));
      EXPECT_DOUBLE_EQ(p.y(), y);
      if (d > 1e-6) {  // radial: same angle
        EXPECT_NEAR(std::atan2(p.x() - c.x(), p.z() - c.y()),
                    std::atan2(std::sin(th), std::cos(th)), 1e-9);
      }
    } else {
      EXPECT_EQ(pen, 0.0);
      EXPECT_EQ(p, p0);
    }
  }
  std::printf("cylinder push_outside: max radial error %.3g m\n", max_err);
  EXPECT_LT(max_err, 1e-12);
  // Outside the height range: untouched.
  Vec3 below(c.x(), 0.49, c.y()), above(c.x(), 1.0, c.y());
  EXPECT_EQ(f.push_outside(below, off), 0.0);
  EXPECT_EQ(f.push_outside(above, off), 0.0);
  EXPECT_EQ(below, Vec3(c.x(), 0.49, c.y()));
  EXPECT_TRUE(std::isinf(f.signed_distance(below)));
  EXPECT_NEAR(f.signed_distance(Vec3(c.x() + 0.2, 0.7, c.y())), 0.2 - r, 1e-12);
  EXPECT_NEAR(f.signed_distance(Vec3(c.x(), 0.7, c.y() + 0.05)), 0.05 - r, 1e-12);
  // NaN never moves anything.
  Vec3 bad(std::nan(""), 0.7, 0.0);
  EXPECT_EQ(f.push_outside(bad, off), 0.0);
}

TEST(DressForm, BilinearInterpolationExactForBilinearField) {
  // r(j, n) = a + b j + c n for n in [0, 255]: bilinear interpolation reproduces it exactly
  // away from the wrap between n = 255 and n = 0.
  const int ns = 20;
  const double y0 = 0.6, dy = 0.0025, a = 0.1, b = 0.001, cc = 0.0001;
  std::vector<Vec2> centres(ns);
  std::vector<double> radii(static_cast<size_t>(ns) * kN);
  for (int j = 0; j < ns; ++j) {
    centres[j] = Vec2(0.001 * j, -0.002 * j);
    for (int n = 0; n < kN; ++n) radii[static_cast<size_t>(j) * kN + n] = a + b * j + cc * n;
  }
  DressForm f(y0, dy, centres, radii, FormLandmarks{});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> su(0, ns - 1), nu(0, kN - 1);
  for (int i = 0; i < 500; ++i) {
    const double s = su(rng), nn = nu(rng);
    const double y = y0 + s * dy, th = 2 * kPi * nn / kN;
    EXPECT_NEAR(f.radius_at(y, th), a + b * s + cc * nn, 1e-12);
    const Vec3 p = f.surface_at(y, th);
    const Vec2 c = f.centre_at(y);
    EXPECT_NEAR(c.x(), 0.001 * s, 1e-12);
    EXPECT_NEAR(c.y(), -0.002 * s, 1e-12);
    const double r = a + b * s + cc * nn;
    EXPECT_NEAR(p.x(), c.x() + r * std::sin(th), 1e-12);
    EXPECT_NEAR(p.z(), c.y() + r * std::cos(th), 1e-12);
    EXPECT_DOUBLE_EQ(p.y(), y);
  }
  // Samples are hit exactly; the angle wraps (theta and theta + 2 pi agree).
  EXPECT_DOUBLE_EQ(f.radius_at(f.section_y(5), DressForm::theta(17)), f.radius(5, 17));
  EXPECT_NEAR(f.radius_at(0.61, 1.0), f.radius_at(0.61, 1.0 + 2 * kPi), 1e-12);
  EXPECT_NEAR(f.radius_at(0.61, -1.0), f.radius_at(0.61, 2 * kPi - 1.0), 1e-12);
  // Clamped outside the height range.
  EXPECT_DOUBLE_EQ(f.radius_at(0.0, 0.0), f.radius(0, 0));
  EXPECT_DOUBLE_EQ(f.radius_at(5.0, 0.0), f.radius(ns - 1, 0));
  // The frame: theta = 0 is +z (centre front), pi/2 is +x (the form's left).
  EXPECT_TRUE(DressForm::direction(0).isApprox(Vec3(0, 0, 1)));
  EXPECT_TRUE(DressForm::direction(kPi / 2).isApprox(Vec3(1, 0, 0)));
}

// Deep inside (a point that tunnelled through): pushed radially, onto the offset shell. A few
// millimetres in (a step's penetration): along the surface's normal, to the offset along it.
TEST(DressForm, PushOutsideParametricAgreesWithSurface) {
  auto f = DressForm::from_measurements(FormMeasurements{});
  ASSERT_TRUE(f.ok()) << f.error();
  const double off = 0.002;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ang(0, 2 * kPi), fy(0.61, 1.33), fr(0.0, 0.99);
  std::uniform_real_distribution<double> shallow(0.0, 0.006);
  int shallow_checked = 0, along_normal = 0;
  double max_off = 0, min_along = 1;
  for (int i = 0; i < 3000; ++i) {
    const double y = fy(rng), th = ang(rng);
    const Vec2 c = f->centre_at(y);
    const bool inner = i % 2 == 0;
    const double r =
        inner ? f->radius_at(y, th) * fr(rng) : f->radius_at(y, th) + off - shallow(rng);
    Vec3 p(c.x() + r * std::sin(th), y, c.y() + r * std::cos(th));
    const Vec3 p0 = p;
    Vec3 n0, n;
    const double d0 = f->normal_distance_within(p0, off, &n0);
    const double pen = f->push_outside(p, off);
    if (!(d0 < off)) {
      EXPECT_EQ(pen, 0.0);
      continue;
    }
    ASSERT_GT(pen, 0);
    // Always ends on or outside the shell.
    EXPECT_GT(f->signed_distance(p), off - DressForm::kPushTolerance);
    if (off - d0 < 0.004) {
      ++shallow_checked;
      // The radial fallback (in concave creases, where a step along the normal goes deeper)
      // reports its own, radial, depth.
      if (std::abs(pen - (off - d0)) > 1e-12) continue;
      ++along_normal;
      const double d = f->normal_distance_within(p, 1.0, &n);
      max_off = std::max(max_off, std::abs(d - off));
      const Vec3 move = p - p0;
      min_along = std::min(min_along, move.dot(n0) / move.norm());
    }
  }
  std::printf(
      "push_outside: %d shallow points, %d along the normal, max |d - offset| %.3g m, min "
      "cos(move, n) %.6f\n",
      shallow_checked, along_normal, max_off, min_along);
  EXPECT_GT(shallow_checked, 500);
  EXPECT_GT(along_normal, 0.95 * shallow_checked);
  EXPECT_LT(max_off, DressForm::kPushTolerance);
  EXPECT_GT(min_along, 0.99);
}

// On the shoulder's slope (the radius shrinking with height) the push lifts the point: the
// radial push moved it only sideways, a plane that carries no weight.
TEST(DressForm, PushOutsideLiftsAPointOffTheShoulderSlope) {
  auto f = DressForm::from_measurements(FormMeasurements{});
  ASSERT_TRUE(f.ok()) << f.error();
  const double off = 0.002, th = kPi / 2;  // the form's left side
  int checked = 0;
  for (double y = 0.61; y < 1.33; y += 0.01) {
    const double slope = (f->radius_at(y + 1e-3, th) - f->radius_at(y - 1e-3, th)) / 2e-3;
    if (slope > -0.5) continue;  // only where the radius falls by > 0.5 mm per mm of height
    const Vec2 c = f->centre_at(y);
    const double r = f->radius_at(y, th) - 0.003;
    Vec3 p(c.x() + r * std::sin(th), y, c.y() + r * std::cos(th));
    ASSERT_GT(f->push_outside(p, off), 0);
    EXPECT_GT(p.y() - y, 1e-4) << "at y " << y << ", slope " << slope;
    ++checked;
  }
  std::printf("shoulder slope: %d heights checked\n", checked);
  EXPECT_GE(checked, 3);
}

// The contact test's normal: on a cone (radius shrinking with height, the axis drifting
// sideways) the distance along the normal is the exact distance to the surface and the normal
// the cone's own, leaning upward; on the parametric form it is the finite-difference gradient of
// the radial distance, and values beyond the reach are lower bounds of it.
TEST(DressForm, NormalDistanceFollowsTheSurfaceSlope) {
  // Radius 0.3 - 2 (y - 1) over 1.0 <= y <= 1.1, axis along (0.1, 1, 0.05) (the centre drifts
  // 0.1 m in x and 0.05 m in z per metre of height).
  const int ns = 41;
  const double y0 = 1.0, dy = 0.0025, k = 2.0;
  const Vec2 drift(0.1, 0.05);
  std::vector<Vec2> centres(ns);
  std::vector<double> radii(static_cast<size_t>(ns) * kN);
  for (int j = 0; j < ns; ++j) {
    centres[j] = drift * (dy * j);
    for (int n = 0; n < kN; ++n) radii[static_cast<size_t>(j) * kN + n] = 0.3 - k * dy * j;
  }
  const DressForm f(y0, dy, centres, radii, FormLandmarks{});
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> ang(0, 2 * kPi), fy(1.02, 1.08), off(-0.004, 0.004);
  double worst_n = 0, worst_d = 0;
  for (int i = 0; i < 2000; ++i) {
    const double y = fy(rng), th = ang(rng), e = off(rng);
    const Vec3 u = DressForm::direction(th);
    // The horizontally sheared cone: F(x) = |(x - c(y))_xz| - r(y). Its gradient, from the
    // shear: d rho / dy = -u . drift, so grad F = u + (k - u . drift) y_hat.
    const Vec3 g = u + (k - (u.x() * drift.x() + u.z() * drift.y())) * Vec3::UnitY();
    const Vec3 n_exact = g.normalized();
    const Vec3 p = f.surface_at(y, th) + e * n_exact;  // e from the surface along its normal
    Vec3 n;
    const double d = f.normal_distance_within(p, 0.01, &n);
    // The gradient at p itself (its level set leans a little from the surface's: the drift).
    const Vec2 cp = f.centre_at(p.y());
    const Vec3 up = Vec3(p.x() - cp.x(), 0, p.z() - cp.y()).normalized();
    const Vec3 gp = up + (k - (up.x() * drift.x() + up.z() * drift.y())) * Vec3::UnitY();
    worst_n = std::max(worst_n, (n - gp.normalized()).norm());
    worst_d = std::max(worst_d, std::abs(d - e));
  }
  std::printf("sheared cone: normal error %.3g, distance error %.3g m (up to 4 mm off)\n", worst_n,
              worst_d);
  EXPECT_LT(worst_n, 1e-9);  // bilinear sections reproduce the cone exactly
  EXPECT_LT(worst_d, 1e-6);  // to first order: 4 mm off, the drift tilts the level set ~2e-3

  auto pf = DressForm::from_measurements(FormMeasurements{});
  ASSERT_TRUE(pf.ok()) << pf.error();
  std::uniform_real_distribution<double> py(pf->min_y() + 0.01, pf->max_y() - 0.01),
      out(-0.01, 0.03);
  const double reach = 0.012, hd = 1e-7;
  int exact = 0, bounded = 0;
  double worst_fd = 0, worst_jump = 0, worst_fd_d = 0;
  for (int i = 0; i < 5000; ++i) {
    const double y = py(rng), th = ang(rng);
    const Vec2 c = pf->centre_at(y);
    const double r = pf->radius_at(y, th) + out(rng);
    const Vec3 p(c.x() + r * std::sin(th), y, c.y() + r * std::cos(th));
    Vec3 n;
    const double d = pf->normal_distance_within(p, reach, &n);
    Vec3 n_full;
    const double d_full = pf->normal_distance_within(p, 1e9, &n_full);
    if (d >= reach) {  // a lower bound beyond the reach, or the exact value
      EXPECT_GE(d_full, d - 1e-15);
      if (d != d_full) ++bounded;
      continue;
    }
    EXPECT_EQ(d, d_full);
    ++exact;
    // Against the gradient of the radial distance F = signed_distance by central differences
    // over 0.1 um: the smoothed slopes differ from a cell's own by the curvature over a cell.
    Vec3 g;
    for (int a = 0; a < 3; ++a) {
      Vec3 dp = Vec3::Zero();
      dp[a] = hd;
      g[a] = (pf->signed_distance(p + dp) - pf->signed_distance(p - dp)) / (2 * hd);
    }
    worst_fd = std::max(worst_fd, (n - g.normalized()).norm());
    worst_fd_d = std::max(worst_fd_d, std::abs(d - pf->signed_distance(p) / g.norm()));
    // Continuous across the nearest section line (the bilinear cells' gradient jumps there).
    const double sy =
        pf->section_y(static_cast<int>(std::lround((y - pf->min_y()) / pf->section_spacing())));
    if (sy <= pf->min_y() || sy >= pf->max_y()) continue;
    const Vec2 cs = pf->centre_at(sy);
    Vec3 below(p.x() - c.x() + cs.x(), sy - 1e-9, p.z() - c.y() + cs.y()), above = below;
    above.y() = sy + 1e-9;
    Vec3 nb, na;
    pf->normal_distance_within(below, 1e9, &nb);
    pf->normal_distance_within(above, 1e9, &na);
    worst_jump = std::max(worst_jump, (na - nb).norm());
  }
  std::printf(
      "parametric form: %d within reach (normal vs the bilinear cell's gradient: up to %.3g, "
      "distance up to %.3g m; jump across a section line %.3g), %d bounded\n",
      exact, worst_fd, worst_fd_d, worst_jump, bounded);
  EXPECT_GT(exact, 2000);
  EXPECT_GT(bounded, 100);
  EXPECT_LT(worst_fd, 0.3);     // the form's sharpest turns (neck, armholes) over one cell
  EXPECT_LT(worst_fd_d, 1e-3);  // within reach (12 mm): the slope error times the distance
  EXPECT_LT(worst_jump, 1e-6);
}

TEST(DressForm, LandmarksAndReferenceLines) {
  auto f = DressForm::from_measurements(FormMeasurements{});
  ASSERT_TRUE(f.ok());
  const auto& lm = f->landmarks();
  EXPECT_EQ(lm.centre_front_theta, 0.0);
  EXPECT_NEAR(lm.centre_back_theta, kPi, 1e-12);
  EXPECT_NEAR(lm.left_side_theta, kPi / 2, 1e-12);
  EXPECT_NEAR(lm.right_side_theta, 3 * kPi / 2, 1e-12);
  EXPECT_LT(lm.bottom_y, lm.hip_y);
  EXPECT_LT(lm.hip_y, lm.waist_y);
  EXPECT_LT(lm.waist_y, lm.bust_y);
  EXPECT_LT(lm.bust_y, lm.neck_y);
  // Centre front is the +z side: the surface at theta 0 is in front of the centre.
  EXPECT_GT(f->surface_at(lm.bust_y, 0).z(), f->centre_at(lm.bust_y).y());
  EXPECT_GT(f->surface_at(lm.bust_y, kPi / 2).x(), 0.1);
}

TEST(DressForm, ToMeshClosedAndOutward) {
  auto f = DressForm::from_measurements(FormMeasurements{}, 0.01);
  ASSERT_TRUE(f.ok());
  TriMesh m = f->to_mesh();
  ASSERT_EQ(m.vertices.size(), static_cast<size_t>(f->num_sections()) * kN + 2);
  std::map<std::pair<int, int>, int> edges;
  double vol = 0;
  for (const auto& t : m.triangles) {
    for (int e = 0; e < 3; ++e) edges[{t[e], t[(e + 1) % 3]}]++;
    vol += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6.0;
  }
  for (const auto& [e, n] : edges) {  // closed and consistently oriented
    EXPECT_EQ(n, 1);
    EXPECT_EQ(edges.count({e.second, e.first}), 1u);
  }
  // Volume by the sections (sum of polygon areas x spacing) vs the mesh volume.
  double vsec = 0;
  for (int j = 0; j < f->num_sections(); ++j) {
    double area = 0;
    for (int n = 0; n < kN; ++n)
      area += 0.5 * f->radius(j, n) * f->radius(j, (n + 1) % kN) * std::sin(2 * kPi / kN);
    vsec += area * f->section_spacing() * ((j == 0 || j + 1 == f->num_sections()) ? 0.5 : 1.0);
  }
  std::printf("form volume: mesh %.5f m^3, sections %.5f m^3\n", vol, vsec);
  EXPECT_GT(vol, 0);  // outward normals
  EXPECT_NEAR(vol, vsec, 0.01 * vsec);
}

}  // namespace
}  // namespace drape::sim
