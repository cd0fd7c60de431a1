// Mapping of the flat panel onto the form along the grain (eqs. 2-1..2-10 of docs/draping.md).
#include "sim/draping/mapping.hpp"

#include <algorithm>
#include <cmath>

#include "sim/form/dress_form.hpp"

namespace drape::sim {
namespace {
constexpr double kTwoPi = 6.283185307179586;
constexpr int kN = DressForm::kAngles;
constexpr double kStep = kTwoPi / kN;

double wrap_positive(double a) {
  a = std::fmod(a, kTwoPi);
  return a < 0 ? a + kTwoPi : a;
}
}  // namespace

MappingSurface::MappingSurface(const DressForm& form, double ease, bool hip_shape_below_hip)
    : form_(&form), ease_(ease), offset_(ease / kTwoPi), hip_below_(hip_shape_below_hip) {
  // A radial offset of ease / 2pi adds exactly `ease` only to a circle. Per form section solve
  // (secant) for the radial offset whose polygon perimeter is the section's plus `ease`.
  const int ns = form.num_sections();
  section_offset_.assign(static_cast<size_t>(std::max(ns, 1)), offset_);
  if (ease != 0.0) solve_offsets();
  if (!hip_below_ || ns < 2) return;
  // Envelope below the hip: per angle the outermost of the hip shape and the form's section
  // polygon along the ray from the hip centre (the polygons' centres differ by millimetres, so
  // only edges within +-24 samples of the ray's angle can be hit).
  const double hip = form.landmarks().hip_y;
  hip_below_ = false;  // sample the plain form shape at the hip
  hip_r_.resize(kN);
  for (int n = 0; n < kN; ++n) hip_r_[n] = sample_radius(hip, n);
  hip_below_ = true;
  const Vec2 ch = centre(hip);
  env_.assign(static_cast<size_t>(ns) * kN, 0.0);
  for (int j = 0; j < ns && form.section_y(j) < hip; ++j) {
    const Vec2 cj = form.centre(j);
    const double off = section_offset_[static_cast<size_t>(j)];
    const auto corner = [&](int k) {
      const int kk = ((k % kN) + kN) % kN;
      const double r = form.radius(j, kk) + off, t = kk * kStep;
      return Vec2(cj.x() + r * std::sin(t), cj.y() + r * std::cos(t));
    };
    for (int n = 0; n < kN; ++n) {
      const Vec2 d(std::sin(n * kStep), std::cos(n * kStep));
      double best = hip_r_[n];
      for (int k = n - 24; k < n + 24; ++k) {
        const Vec2 a = corner(k), e = corner(k + 1) - a, w = a - ch;
        const double den = d.x() * e.y() - d.y() * e.x();
        if (std::abs(den) < 1e-15) continue;
        const double t = (w.x() * e.y() - w.y() * e.x()) / den;
        const double sg = (w.x() * d.y() - w.y() * d.x()) / den;
        if (sg >= 0 && sg <= 1 && t > best) best = t;
      }
      env_[static_cast<size_t>(j) * kN + n] = best;
    }
  }
}

double MappingSurface::env_radius(int j, int n) const {
  return env_[static_cast<size_t>(j) * kN + n];
}

void MappingSurface::solve_offsets() {
  const DressForm& form = *form_;
  const int ns = form.num_sections();
  const double ease = ease_;
  auto perim = [&](int j, double d) {
    double g = 0;
    for (int n = 0; n < kN; ++n) {
      const double r0 = form.radius(j, n) + d, r1 = form.radius(j, (n + 1) % kN) + d;
      const double t0 = n * kStep, t1 = (n + 1) * kStep;
      g += std::hypot(r1 * std::sin(t1) - r0 * std::sin(t0), r1 * std::cos(t1) - r0 * std::cos(t0));
    }
    return g;
  };
  for (int j = 0; j < ns; ++j) {
    const double target = perim(j, 0.0) + ease;
    double d0 = 0.0, p0 = target - ease, d1 = offset_, p1 = perim(j, d1);
    for (int it = 0; it < 8 && std::abs(p1 - target) > 1e-10 && p1 != p0; ++it) {
      const double d2 = d1 + (target - p1) * (d1 - d0) / (p1 - p0);
      d0 = d1;
      p0 = p1;
      d1 = d2;
      p1 = perim(j, d1);
    }
    section_offset_[static_cast<size_t>(j)] = d1;
  }
}

double MappingSurface::shape_y(double y) const {
  const double hip = form_->landmarks().hip_y;
  if (hip_below_ && y < hip) y = hip;
  return std::clamp(y, form_->min_y(), form_->max_y());
}

double MappingSurface::sample_radius(double y, int n) const {
  const int ns = form_->num_sections();
  n = ((n % kN) + kN) % kN;
  const double hip = form_->landmarks().hip_y;
  if (hip_below_ && y < hip && !env_.empty()) {
    if (y <= form_->min_y()) return env_radius(0, n);  // straight down from the form's end
    const int j = std::min(
        static_cast<int>(std::floor((y - form_->min_y()) / form_->section_spacing())), ns - 2);
    const double yj = form_->section_y(j);
    if (form_->section_y(j + 1) < hip) {
      const double rh = (y - yj) / form_->section_spacing();
      return env_radius(j, n) + (env_radius(j + 1, n) - env_radius(j, n)) * rh;
    }
    const double rh = (y - yj) / (hip - yj);
    return env_radius(j, n) + (hip_r_[n] - env_radius(j, n)) * rh;
  }
  const double ys = shape_y(y);
  if (ns < 2) return form_->radius(0, n) + section_offset_[0];
  const double f = (ys - form_->min_y()) / form_->section_spacing();
  const int j = std::clamp(static_cast<int>(std::floor(f)), 0, ns - 2);
  const double rh = std::clamp(f - j, 0.0, 1.0);  // eq. 2-2
  const double r0 = form_->radius(j, n) + section_offset_[static_cast<size_t>(j)];
  const double r1 = form_->radius(j + 1, n) + section_offset_[static_cast<size_t>(j) + 1];
  return r0 + (r1 - r0) * rh;
}

Vec2 MappingSurface::centre(double y) const {
  const double ys = shape_y(y);
  const int ns = form_->num_sections();
  if (ns < 2) return form_->centre(0);
  const double f = (ys - form_->min_y()) / form_->section_spacing();
  const int j = std::clamp(static_cast<int>(std::floor(f)), 0, ns - 2);
  const double rh = std::clamp(f - j, 0.0, 1.0);
  return form_->centre(j) + (form_->centre(j + 1) - form_->centre(j)) * rh;
}

double MappingSurface::radius(double y, double theta) const {
  const double t = wrap_positive(theta) / kStep;
  const int k = static_cast<int>(std::floor(t));
  const double ru = t - k;
  const double r0 = sample_radius(y, k), r1 = sample_radius(y, k + 1);
  return r0 + (r1 - r0) * ru;  // eq. 2-8
}

Vec3 MappingSurface::point(double y, double theta) const {
  const Vec2 c = centre(y);
  const double r = radius(y, theta);
  return Vec3(c.x() + r * std::sin(theta), y, c.y() + r * std::cos(theta));  // eq. 2-9
}

double MappingSurface::girth(double y) const {
  double g = 0;
  for (int n = 0; n < kN; ++n) {
    const double r0 = sample_radius(y, n), r1 = sample_radius(y, n + 1);
    const double t0 = n * kStep, t1 = (n + 1) * kStep;
    g += std::hypot(r1 * std::sin(t1) - r0 * std::sin(t0), r1 * std::cos(t1) - r0 * std::cos(t0));
  }
  return g;
}

ArcTable ArcTable::build(const MappingSurface& s, double y, double theta0, int dir) {
  ArcTable T;
  T.theta0 = theta0;
  T.dir = dir;
  T.cum.resize(kN + 1);
  T.cum[0] = 0;
  const int n0 = static_cast<int>(std::lround(theta0 / kStep));
  double rp = s.sample_radius(y, n0);
  double tp = theta0;
  for (int m = 1; m <= kN; ++m) {  // eq. 2-3: chord lengths L_n from the centre-line point
    const double t = theta0 + dir * m * kStep;
    const double r = s.sample_radius(y, n0 + dir * m);
    T.cum[m] = T.cum[m - 1] +
               std::hypot(r * std::sin(t) - rp * std::sin(tp), r * std::cos(t) - rp * std::cos(tp));
    rp = r;
    tp = t;
  }
  return T;
}

double ArcTable::theta_at(double l) const {
  if (l <= 0) return theta0 + dir * l / (cum[1] - cum[0]) * kStep;
  if (l >= cum[kN]) return theta0 + dir * (kN + (l - cum[kN]) / (cum[kN] - cum[kN - 1])) * kStep;
  const int k = static_cast<int>(std::upper_bound(cum.begin(), cum.end(), l) - cum.begin()) - 1;
  const double ru = (l - cum[k]) / (cum[k + 1] - cum[k]);  // eq. 2-4
  return theta0 + dir * (k + ru) * kStep;                  // eq. 2-6
}

double ArcTable::arc_at(double theta) const {
  double t = dir * (theta - theta0);
  // Angles just "behind" the centre line (up to 1/8 turn) stay negative (an overshoot, e.g. a
  // dart's zone start while solving for its constant); all others wrap into [0, 7/8 turn).
  t = std::fmod(t, kTwoPi);
  if (t < -kTwoPi / 8) t += kTwoPi;
  if (t >= kTwoPi - kTwoPi / 8) t -= kTwoPi;
  const double f = t / kStep;
  if (f < 0) return f * (cum[1] - cum[0]);
  const int k = std::min(static_cast<int>(std::floor(f)), kN - 1);
  return cum[k] + (f - k) * (cum[k + 1] - cum[k]);
}

double PieceMapping::zone_start_theta(int z, double y) const {
  const Dart& d = darts[z - 1];
  return d.theta_e - dir * d.a * std::max(0.0, y - d.y_tip);  // eq. 2-10
}

double PieceMapping::shift(int zone, double y, const ArcTable& T) const {
  double c = 0;
  for (int z = 1; z <= zone && z <= static_cast<int>(darts.size()); ++z) {
    const Dart& d = darts[z - 1];
    if (y <= d.y_tip) continue;  // below the slit end the zones are one piece of cloth
    const double cz = T.arc_at(zone_start_theta(z, y)) - d.l;
    c = std::min(c, cz);  // the overlap (intake) is never negative
  }
  return c;
}

double PieceMapping::theta(int zone, double l, double y, const ArcTable& T) const {
  return T.theta_at(l + shift(zone, y, T));
}

double PieceMapping::l_at(int zone, double y, double th, const ArcTable& T) const {
  return T.arc_at(th) - shift(zone, y, T);
}

PieceMapping make_piece_mapping(const Panel& panel, const MappingSurface& surf, double theta_centre,
                                int dir, double theta_side, double waist_y) {
  PieceMapping pm;
  pm.theta_centre = theta_centre;
  pm.dir = dir;
  pm.theta_side = theta_side;
  pm.y_top = waist_y + panel.design.top_above_waist;
  pm.h_max = panel.design.height;
  const ArcTable Tw = ArcTable::build(surf, waist_y, theta_centre, dir);
  for (size_t s = 0; s < panel.slits.size(); ++s) {
    const PanelSlit& ps = panel.slits[s];
    PieceMapping::Dart d;
    d.l = ps.l;
    d.y_tip = pm.y_of_v(ps.v_tip);
    d.intake = ps.intake;
    const ArcTable Tt = ArcTable::build(surf, d.y_tip, theta_centre, dir);
    d.theta_e = pm.theta(static_cast<int>(s), d.l, d.y_tip, Tt);
    pm.darts.push_back(d);
    // Bisection for a: the intake at the waist grows monotonically with a.
    const double c_prev = pm.shift(static_cast<int>(s), waist_y, Tw);
    const double rise = waist_y - d.y_tip;
    if (rise <= 0 || d.intake <= 0) continue;
    // The zone start turns by at most 1/8 turn either way (an intake of ~0.1 m at the waist):
    // inside the range where arc_at is continuous, so the bisection is monotonic. a may be
    // negative: the form's taper alone (a = 0) already gives an overlap (the arc to the tip's
    // angle is shorter at the narrower waist), which can exceed a small wanted intake.
    double lo = -(kTwoPi / 8) / rise, hi = (kTwoPi / 8) / rise;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      pm.darts.back().a = mid;
      const double intake =
          c_prev - (Tw.arc_at(pm.zone_start_theta(static_cast<int>(s) + 1, waist_y)) - d.l);
      (intake < d.intake ? lo : hi) = mid;
    }
    pm.darts.back().a = 0.5 * (lo + hi);
  }
  return pm;
}

void map_panel(Panel& panel, const MappingSurface& surf, const PieceMapping& pm) {
  Cloth& c = panel.cloth;
  const int nv = c.num_vertices();
  std::vector<ArcTable> rows(panel.ny);
  for (int j = 0; j < panel.ny; ++j)
    rows[j] = ArcTable::build(surf, pm.y_of_v(j * panel.dy), pm.theta_centre, pm.dir);
  for (int v = 0; v < nv; ++v) {
    const Vec2 m = c.topo.material[v];
    const int j = std::clamp(static_cast<int>(std::lround(m.y() / panel.dy)), 0, panel.ny - 1);
    const double y = pm.y_of_v(m.y());  // eq. 2-1
    const double th = pm.theta(c.topo.vertex_zone[v], panel.centre_distance(m.x()), y, rows[j]);
    c.state.x[v] = surf.point(y, th);
  }
  c.state.x_prev = c.state.x;
  for (auto& vel : c.state.v) vel.setZero();
}

GrainDeviation measure_grain(const Panel& panel, const MappingSurface& surf, double y_low,
                             double y_high) {
  GrainDeviation g;
  const auto& x = panel.cloth.state.x;
  const int nz = panel.num_zones();
  g.zone_mean_tilt_deg.assign(nz, 0);
  g.zone_max_tilt_deg.assign(nz, 0);
  std::vector<int> count(nz, 0);
  const double deg = 180.0 / 3.141592653589793;
  for (int i = 0; i < panel.nx; ++i) {
    bool near = false;
    int tip_row = panel.ny;
    for (const PanelSlit& s : panel.slits)
      if (std::abs(s.column - i) <= 3) {
        near = true;
        tip_row = std::min(tip_row, s.tip_row);
      }
    double prev = 0;
    bool have_prev = false;
    for (int j = 0; j + 1 < panel.ny; ++j) {
      const int a = j * panel.nx + i, b = a + panel.nx;
      const Vec3 mid = 0.5 * (x[a] + x[b]);
      if (mid.y() < y_low || mid.y() > y_high) {
        have_prev = false;
        continue;
      }
      const Vec2 c = surf.centre(mid.y());
      const double th = std::atan2(mid.x() - c.x(), mid.z() - c.y());
      const Vec3 t(std::cos(th), 0, -std::sin(th));
      const Vec3 d = x[b] - x[a];
      const double dt = d.dot(t);
      const double signed_tilt = std::atan2(dt, (d - dt * t).norm()) * deg;
      const double tilt = std::abs(signed_tilt);
      const int z = panel.cloth.topo.vertex_zone[a] < nz ? panel.cloth.topo.vertex_zone[a] : 0;
      g.zone_mean_tilt_deg[z] += tilt;
      g.zone_max_tilt_deg[z] = std::max(g.zone_max_tilt_deg[z], tilt);
      ++count[z];
      const bool in_dart_region = near && j >= tip_row - 3;
      if (in_dart_region) g.max_tilt_near_darts_deg = std::max(g.max_tilt_near_darts_deg, tilt);
      if (have_prev) {
        const double kink = std::abs(signed_tilt - prev);
        g.max_kink_deg = std::max(g.max_kink_deg, kink);
        if (in_dart_region) g.max_kink_near_darts_deg = std::max(g.max_kink_near_darts_deg, kink);
      }
      prev = signed_tilt;
      have_prev = true;
    }
  }
  for (int z = 0; z < nz; ++z)
    if (count[z]) g.zone_mean_tilt_deg[z] /= count[z];
  return g;
}

}  // namespace drape::sim
