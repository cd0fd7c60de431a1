// The dress form's section model: lookup, interpolation, girth, O(1) collision and export
// (method 1 and 2.2). Builders live in form_parametric.cpp and form_mesh.cpp.
#include "sim/form/dress_form.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "sim/core/mesh.hpp"

namespace drape::sim {

namespace {
constexpr double kTwoPi = 2.0 * 3.14159265358979323846;
constexpr double kAnglesPerRadian = DressForm::kAngles / kTwoPi;
}  // namespace

DressForm::DressForm(double y0, double dy, std::vector<Vec2> centres, std::vector<double> radii,
                     FormLandmarks landmarks)
    : y0_(y0),
      dy_(dy),
      num_sections_(static_cast<int>(centres.size())),
      centres_(std::move(centres)),
      radii_(std::move(radii)),
      landmarks_(landmarks) {
  if (radii_.size() != static_cast<size_t>(num_sections_) * kAngles) {
    // A malformed radius array is a programming error; keep the object in a usable empty state.
    num_sections_ = 0;
    centres_.clear();
    radii_.clear();
  }
  if (!(dy_ > 0)) dy_ = 1.0;
  max_radius_.resize(num_sections_);
  for (int j = 0; j < num_sections_; ++j) {
    const double* r = &radii_[static_cast<size_t>(j) * kAngles];
    max_radius_[j] = *std::max_element(r, r + kAngles);
  }
  // |grad F|^2 = 1 + (r_th / rho)^2 + g_y^2 with |g_y| <= |c'| (1 + |r_th| / rho) + |r_y|; within
  // reach of the surface rho >= r - reach, so r_th / rho is bounded with the cell's smallest
  // radius less a centimetre (contacts reach a few millimetres).
  max_gradient_.assign(num_sections_, 1.0);
  for (int j = 0; j + 1 < num_sections_; ++j) {
    const double* r0 = &radii_[static_cast<size_t>(j) * kAngles];
    const double* r1 = r0 + kAngles;
    double rth = 0, ry = 0, rmin = std::numeric_limits<double>::infinity();
    for (int n = 0; n < kAngles; ++n) {
      const int n1 = (n + 1) & (kAngles - 1);
      rth = std::max({rth, std::abs(r0[n1] - r0[n]), std::abs(r1[n1] - r1[n])});
      ry = std::max(ry, std::abs(r1[n] - r0[n]));
      rmin = std::min({rmin, r0[n], r1[n]});
    }
    const double a = rth * kAnglesPerRadian / std::max(rmin - 0.01, 1e-3);
    const double cy = (centres_[j + 1] - centres_[j]).norm() / dy_;
    const double gy = cy * (1 + a) + ry / dy_;
    max_gradient_[j] = std::sqrt(1 + a * a + gy * gy);
  }
  // The normals use central differences, which mix a cell's slopes with its neighbours'.
  if (num_sections_ >= 2) {
    std::vector<double> own = max_gradient_;
    for (int j = 0; j + 1 < num_sections_; ++j)
      max_gradient_[j] = std::max({own[std::max(j - 1, 0)], own[j], own[j + 1]});
  }
  max_gradient_all_ =
      max_gradient_.empty() ? 1.0 : *std::max_element(max_gradient_.begin(), max_gradient_.end());
  // The samples' slopes, once (each contact test interpolates four of them).
  slopes_.resize(radii_.size());
  centre_slopes_.resize(num_sections_);
  for (int j = 0; j < num_sections_; ++j) {
    centre_slopes_[j] = centre_slope(j);
    for (int n = 0; n < kAngles; ++n)
      slopes_[static_cast<size_t>(j) * kAngles + n] = {radius_slope_y(j, n),
                                                       radius_slope_theta(j, n)};
  }
}

Vec3 DressForm::direction(double theta) {
  return Vec3(std::sin(theta), 0.0, std::cos(theta));
}

Vec3 DressForm::point(int j, int n) const {
  const Vec2& c = centres_[j];
  const double r = radius(j, n);
  const double t = theta(n);
  return Vec3(c.x() + r * std::sin(t), section_y(j), c.y() + r * std::cos(t));
}

namespace {
// Section index and fraction for height y, clamped to the model.
inline void locate(double y, double y0, double dy, int ns, int& j, double& t) {
  double s = (y - y0) / dy;
  if (!(s > 0)) s = 0;  // also catches NaN
  const double smax = ns - 1;
  if (s >= smax) {
    j = std::max(ns - 2, 0);
    t = ns >= 2 ? 1.0 : 0.0;
    return;
  }
  j = static_cast<int>(s);
  t = s - j;
}
// Angle index and fraction for theta (any real).
inline void locate_angle(double theta, int& n, double& u) {
  double a = theta * kAnglesPerRadian;
  if (!std::isfinite(a)) a = 0.0;  // NaN/inf angle: use centre front rather than index garbage
  a -= DressForm::kAngles * std::floor(a / DressForm::kAngles);
  n = static_cast<int>(a);
  if (n >= DressForm::kAngles) n = 0, a = 0;
  u = a - n;
}
}  // namespace

double DressForm::radius_in(int j, double t, double th) const {
  int n;
  double u;
  locate_angle(th, n, u);
  const int n1 = (n + 1) & (kAngles - 1);
  const int j1 = std::min(j + 1, num_sections_ - 1);
  const double* r0 = &radii_[static_cast<size_t>(j) * kAngles];
  const double* r1 = &radii_[static_cast<size_t>(j1) * kAngles];
  const double a = r0[n] + (r0[n1] - r0[n]) * u;
  const double b = r1[n] + (r1[n1] - r1[n]) * u;
  return a + (b - a) * t;
}

Vec2 DressForm::centre_in(int j, double t) const {
  const int j1 = std::min(j + 1, num_sections_ - 1);
  return centres_[j] + (centres_[j1] - centres_[j]) * t;
}

double DressForm::radius_at(double y, double th) const {
  if (num_sections_ == 0) return 0.0;
  int j;
  double t;
  locate(y, y0_, dy_, num_sections_, j, t);
  return radius_in(j, t, th);
}

Vec2 DressForm::centre_at(double y) const {
  if (num_sections_ == 0) return Vec2::Zero();
  int j;
  double t;
  locate(y, y0_, dy_, num_sections_, j, t);
  return centre_in(j, t);
}

Vec3 DressForm::surface_at(double y, double th) const {
  const Vec2 c = centre_at(y);
  const double r = radius_at(y, th);
  return Vec3(c.x() + r * std::sin(th), y, c.y() + r * std::cos(th));
}

double DressForm::girth_at(double y) const {
  if (num_sections_ == 0) return 0.0;
  int j;
  double t;
  locate(y, y0_, dy_, num_sections_, j, t);
  const int j1 = std::min(j + 1, num_sections_ - 1);
  const double* r0 = &radii_[static_cast<size_t>(j) * kAngles];
  const double* r1 = &radii_[static_cast<size_t>(j1) * kAngles];
  // Precomputed unit directions: the polygon of the 256 interpolated samples.
  static const std::array<Vec2, kAngles> dirs = [] {
    std::array<Vec2, kAngles> d;
    for (int n = 0; n < kAngles; ++n) d[n] = Vec2(std::sin(theta(n)), std::cos(theta(n)));
    return d;
  }();
  double perimeter = 0.0;
  Vec2 first = dirs[0] * (r0[0] + (r1[0] - r0[0]) * t);
  Vec2 prev = first;
  for (int n = 1; n < kAngles; ++n) {
    const Vec2 p = dirs[n] * (r0[n] + (r1[n] - r0[n]) * t);
    perimeter += (p - prev).norm();
    prev = p;
  }
  perimeter += (first - prev).norm();
  return perimeter;
}

double DressForm::push_outside(Vec3& p, double offset) const {
  // Along the surface's normal (as the energy's contacts: normal_distance_within), so that a
  // point on a slope (shoulders, bust) is lifted off it rather than shoved sideways. The
  // distance along the normal is first order, and the normal's slopes are interpolated (within
  // ~15 % of the radial distance's own gradient): corrections take it to the offset within
  // kPushTolerance, each gaining ~10x. The radial push instead (it always ends on the shell)
  // deeper than kNormalPushDepth, or when six corrections do not settle the point or move it
  // more than 1.5x the first push (a concave crease, where a step along the normal goes
  // deeper; ~1 % of points 0-4 mm in, DressForm tests).
  if (num_sections_ >= 2) {
    Vec3 n;
    const double d = normal_distance_within(p, offset, &n);
    if (!(d < offset)) return 0.0;  // clear of the shell, outside the height range or NaN
    const double pen = offset - d;
    if (pen < kNormalPushDepth) {
      Vec3 q = p + pen * n;
      bool settled = false;
      for (int k = 0; k < 6; ++k) {
        // Reach past the offset: a correction that overshot gets the exact distance and a
        // fresh normal, not the lower bound (which leaves `n` as it was).
        const double dk = normal_distance_within(q, offset + kNormalPushDepth, &n);
        if (std::abs(dk - offset) < kPushTolerance || std::isinf(dk)) {
          settled = true;
          break;
        }
        q += (offset - dk) * n;
      }
      if (settled && q.allFinite() && (q - p).norm() <= 1.5 * pen) {
        p = q;
        return pen;
      }
    }
  }
  return push_radially(p, offset);
}

bool DressForm::section_of(const Vec3& p, int& j, double& t, double& dx, double& dz) const {
  const double s = (p.y() - y0_) / dy_;
  if (!(s >= 0.0) || s > num_sections_ - 1) return false;  // outside the height range (or NaN)
  locate(p.y(), y0_, dy_, num_sections_, j, t);
  const Vec2 c = centre_in(j, t);
  dx = p.x() - c.x();
  dz = p.z() - c.y();
  return true;
}

double DressForm::push_radially(Vec3& p, double offset) const {
  if (num_sections_ == 0) return 0.0;
  int j;
  double t, dx, dz;
  if (!section_of(p, j, t, dx, dz)) return 0.0;
  const Vec2 c = centre_in(j, t);
  const double d2 = dx * dx + dz * dz;
  if (!std::isfinite(d2)) return 0.0;  // NaN/inf coordinates: leave the point alone
  // th: 0 at +z (centre front), +pi/2 at +x (left side).
  const double target = radius_in(j, t, std::atan2(dx, dz)) + offset;
  if (d2 >= target * target) return 0.0;
  const double d = std::sqrt(d2);
  double ux, uz;
  if (d > 1e-12) {
    ux = dx / d, uz = dz / d;
  } else {  // on the axis: push toward centre front
    ux = 0.0, uz = 1.0;
  }
  p.x() = c.x() + ux * target;
  p.z() = c.y() + uz * target;
  return target - d;
}

double DressForm::signed_distance(const Vec3& p) const {
  int j;
  double t, dx, dz;
  if (num_sections_ == 0 || !section_of(p, j, t, dx, dz))
    return std::numeric_limits<double>::infinity();
  return std::sqrt(dx * dx + dz * dz) - radius_in(j, t, std::atan2(dx, dz));
}

double DressForm::radius_slope_y(int j, int n) const {
  const int a = std::max(j - 1, 0), b = std::min(j + 1, num_sections_ - 1);
  return (radii_[static_cast<size_t>(b) * kAngles + n] -
          radii_[static_cast<size_t>(a) * kAngles + n]) /
         (dy_ * (b - a));
}

double DressForm::radius_slope_theta(int j, int n) const {
  const double* r = &radii_[static_cast<size_t>(j) * kAngles];
  return (r[(n + 1) & (kAngles - 1)] - r[(n + kAngles - 1) & (kAngles - 1)]) *
         (kAnglesPerRadian / 2);
}

Vec2 DressForm::centre_slope(int j) const {
  const int a = std::max(j - 1, 0), b = std::min(j + 1, num_sections_ - 1);
  return (centres_[b] - centres_[a]) / (dy_ * (b - a));
}

double DressForm::normal_distance_within(const Vec3& p, double reach, Vec3* normal) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  int j;
  double t, dx, dz;
  if (num_sections_ < 2 || !section_of(p, j, t, dx, dz)) return kInf;
  const double rho = std::sqrt(dx * dx + dz * dz);
  if (!(rho > 1e-9)) return kInf;
  const double bound = (rho - std::max(max_radius_[j], max_radius_[j + 1])) / max_gradient_[j];
  if (bound >= reach) return bound;
  int n;
  double u;
  locate_angle(std::atan2(dx, dz), n, u);
  const int n1 = (n + 1) & (kAngles - 1);
  const double* r0 = &radii_[static_cast<size_t>(j) * kAngles];
  const double* r1 = r0 + kAngles;
  const double a = r0[n] + (r0[n1] - r0[n]) * u;
  const double b = r1[n] + (r1[n1] - r1[n]) * u;
  const double F = rho - (a + (b - a) * t);
  // dr/dtheta, dr/dy and the centre's drift dc/dy: central differences at the four samples,
  // interpolated bilinearly as the radius is. The bilinear cell's own slopes jump from one cell
  // to the next (every 2.5 mm of height, every 1.4 degrees), and a contact plane that flips
  // there kept the static solve's active set from settling; these normals are continuous.
  const auto* s0 = &slopes_[static_cast<size_t>(j) * kAngles];
  const auto* s1 = s0 + kAngles;
  const double ry_a = s0[n][0] + (s0[n1][0] - s0[n][0]) * u;
  const double ry_b = s1[n][0] + (s1[n1][0] - s1[n][0]) * u;
  const double rt_a = s0[n][1] + (s0[n1][1] - s0[n][1]) * u;
  const double rt_b = s1[n][1] + (s1[n1][1] - s1[n][1]) * u;
  const double r_y = ry_a + (ry_b - ry_a) * t;
  const double r_th = rt_a + (rt_b - rt_a) * t;
  const Vec2 dc = centre_slopes_[j] + (centre_slopes_[j + 1] - centre_slopes_[j]) * t;
  // Radial unit u = (ux, 0, uz), angular unit w = (uz, 0, -ux) (toward growing theta).
  const double ux = dx / rho, uz = dz / rho, k = r_th / rho;
  const double gx = ux - k * uz, gz = uz + k * ux;
  const double gy = -(ux * dc.x() + uz * dc.y()) + k * (uz * dc.x() - ux * dc.y()) - r_y;
  const double g = std::sqrt(gx * gx + gy * gy + gz * gz);
  *normal = Vec3(gx / g, gy / g, gz / g);
  return F / g;
}

TriMesh DressForm::to_mesh() const {
  TriMesh m;
  m.name = "dress_form";
  if (num_sections_ < 2) return m;
  const int ns = num_sections_;
  m.vertices.reserve(static_cast<size_t>(ns) * kAngles + 2);
  m.uv.reserve(static_cast<size_t>(ns) * kAngles + 2);
  for (int j = 0; j < ns; ++j) {
    for (int n = 0; n < kAngles; ++n) {
      m.vertices.push_back(point(j, n));
      // uv: arc-angle around (0 at centre front) and height: lets a renderer draw the
      // reference lines (centre front u = 0, side lines u = 0.25 / 0.75, back u = 0.5).
      m.uv.emplace_back(static_cast<double>(n) / kAngles, section_y(j));
    }
  }
  auto idx = [](int j, int n) { return j * kAngles + (n & (kAngles - 1)); };
  // Outward-facing (counter-clockwise seen from outside): theta runs from +z toward +x, i.e.
  // counter-clockwise seen from above, so (j,n) -> (j,n+1) -> (j+1,n) faces outward.
  for (int j = 0; j + 1 < ns; ++j) {
    for (int n = 0; n < kAngles; ++n) {
      const int a = idx(j, n), b = idx(j, n + 1), c = idx(j + 1, n), d = idx(j + 1, n + 1);
      m.triangles.push_back({a, b, d});
      m.triangles.push_back({a, d, c});
    }
  }
  const int bottom = static_cast<int>(m.vertices.size());
  m.vertices.emplace_back(centres_[0].x(), section_y(0), centres_[0].y());
  m.uv.emplace_back(0.0, section_y(0));
  const int top = bottom + 1;
  m.vertices.emplace_back(centres_[ns - 1].x(), section_y(ns - 1), centres_[ns - 1].y());
  m.uv.emplace_back(0.0, section_y(ns - 1));
  for (int n = 0; n < kAngles; ++n) {
    m.triangles.push_back({bottom, idx(0, n + 1), idx(0, n)});
    m.triangles.push_back({top, idx(ns - 1, n), idx(ns - 1, n + 1)});
  }
  return m;
}

std::string check_reference_lines(const DressForm& form, const std::string& name) {
  const FormLandmarks& lm = form.landmarks();
  const double h = lm.top_y - lm.bottom_y, pi = 3.14159265358979323846;
  const double gw = form.girth_at(lm.waist_y), gh = form.girth_at(lm.hip_y);
  std::string missing;
  const auto add = [&](const std::string& s) { missing += (missing.empty() ? "" : "; ") + s; };
  char buf[256];
  const double band_lo = lm.bottom_y + 0.3 * h, band_hi = lm.bottom_y + 0.7 * h;
  if (gw > 0.97 * gh || lm.waist_y < band_lo + 0.01 || lm.waist_y > band_hi - 0.01) {
    std::snprintf(buf, sizeof buf,
                  "waist (no narrowing: the smallest girth between 30 %% and 70 %% of the height "
                  "is %.1f mm at %.3f m, the hip below it %.1f mm; a waist needs a girth at least "
                  "3 %% below the hip's, inside that band)",
                  gw * 1000, lm.waist_y, gh * 1000);
    add(buf);
  }
  if (lm.waist_y - lm.hip_y < 0.08) {
    std::snprintf(buf, sizeof buf,
                  "hip (the widest section below the waist is at %.3f m, %.0f mm below the "
                  "waist; at least 80 mm needed)",
                  lm.hip_y, (lm.waist_y - lm.hip_y) * 1000);
    add(buf);
  }
  const double tol = 30 * pi / 180;
  if (std::abs(lm.left_side_theta - pi / 2) > tol ||
      std::abs(lm.right_side_theta - 1.5 * pi) > tol) {
    std::snprintf(buf, sizeof buf,
                  "side lines (the widest points of the waist section are at %.1f and %.1f deg "
                  "from centre front, not within 30 deg of 90 and 270)",
                  lm.left_side_theta * 180 / pi, lm.right_side_theta * 180 / pi);
    add(buf);
  }
  return missing.empty() ? "" : name + ": reference lines not found on the form: " + missing;
}

}  // namespace drape::sim
