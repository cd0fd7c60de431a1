// Parametric dress form from body measurements (girths and landmark heights), and the
// measurement files (assets/forms/*.json). See docs/dress-form.md for the construction.
//
// Each section is an asymmetric superellipse |x/a|^p + |z/d|^p = 1 (p_front for the front half,
// p_back for the back half) around a centre (0, z_c), with Gaussian bumps for the bust points
// and the seat, made convex (a tape measure bridges hollows) and scaled so its 256-sample
// polygon perimeter equals the girth interpolated (monotone cubic) between the landmarks.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sim/form/dress_form.hpp"

namespace drape::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kN = DressForm::kAngles;

// ---------------------------------------------------------------------------------------------
// Monotone cubic interpolation (Fritsch & Carlson 1980): no overshoot between knots, so a girth
// never dips below both neighbouring landmark girths.
class MonotoneCubic {
 public:
  MonotoneCubic(std::vector<double> x, std::vector<double> y) : x_(std::move(x)), y_(std::move(y)) {
    const size_t n = x_.size();
    m_.assign(n, 0.0);
    std::vector<double> delta(n - 1);
    for (size_t i = 0; i + 1 < n; ++i) delta[i] = (y_[i + 1] - y_[i]) / (x_[i + 1] - x_[i]);
    m_[0] = delta[0];
    m_[n - 1] = delta[n - 2];
    for (size_t i = 1; i + 1 < n; ++i) {
      if (delta[i - 1] * delta[i] <= 0) {
        m_[i] = 0.0;  // local extremum at a knot: flat
      } else {        // weighted harmonic mean (Fritsch-Butland): keeps monotonicity
        const double h0 = x_[i] - x_[i - 1], h1 = x_[i + 1] - x_[i];
        const double w0 = 2 * h1 + h0, w1 = h1 + 2 * h0;
        m_[i] = (w0 + w1) / (w0 / delta[i - 1] + w1 / delta[i]);
      }
    }
  }
  double operator()(double x) const {
    if (x <= x_.front()) return y_.front();
    if (x >= x_.back()) return y_.back();
    const size_t i = std::upper_bound(x_.begin(), x_.end(), x) - x_.begin() - 1;
    const double h = x_[i + 1] - x_[i], t = (x - x_[i]) / h;
    const double t2 = t * t, t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * y_[i] + (t3 - 2 * t2 + t) * h * m_[i] +
           (-2 * t3 + 3 * t2) * y_[i + 1] + (t3 - t2) * h * m_[i + 1];
  }

 private:
  std::vector<double> x_, y_, m_;
};

// Radius of the polygon `pts` (convex, containing the origin, counter-clockwise) along the
// unit direction d.
double ray_polygon(const std::vector<Vec2>& pts, const Vec2& d) {
  double best = 0.0;
  const size_t n = pts.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec2& a = pts[i];
    const Vec2& b = pts[(i + 1) % n];
    const Vec2 e = b - a;
    const double den = d.x() * e.y() - d.y() * e.x();
    if (std::abs(den) < 1e-18) continue;
    const double t = (a.x() * e.y() - a.y() * e.x()) / den;  // along d
    const double s = (a.x() * d.y() - a.y() * d.x()) / den;  // along e
    if (t > 0 && s >= -1e-12 && s <= 1 + 1e-12) best = std::max(best, t);
  }
  return best;
}

// Replaces the star-shaped section r[n] by the radii of its convex hull (what a tape measure
// follows).
void convexify(std::array<double, kN>& r) {
  std::vector<Vec2> p(kN);
  for (int n = 0; n < kN; ++n)
    p[n] = r[n] * Vec2(std::sin(DressForm::theta(n)), std::cos(DressForm::theta(n)));
  std::vector<Vec2> s = p;
  std::sort(s.begin(), s.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  auto cross = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Vec2> h(2 * s.size());
  size_t k = 0;
  for (size_t i = 0; i < s.size(); ++i) {  // Andrew's monotone chain
    while (k >= 2 && cross(h[k - 2], h[k - 1], s[i]) <= 0) --k;
    h[k++] = s[i];
  }
  for (size_t i = s.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(h[k - 2], h[k - 1], s[i]) <= 0) --k;
    h[k++] = s[i];
  }
  h.resize(k - 1);
  for (int n = 0; n < kN; ++n) {
    const double rr = ray_polygon(h, p[n].normalized());
    if (rr > r[n]) r[n] = rr;
  }
}

double polygon_perimeter(const std::array<double, kN>& r) {
  double per = 0;
  for (int n = 0; n < kN; ++n) {
    const int m = (n + 1) % kN;
    const Vec2 a = r[n] * Vec2(std::sin(DressForm::theta(n)), std::cos(DressForm::theta(n)));
    const Vec2 b = r[m] * Vec2(std::sin(DressForm::theta(m)), std::cos(DressForm::theta(m)));
    per += (b - a).norm();
  }
  return per;
}

// Wrapped angular distance.
double ang_dist(double a, double b) {
  double d = std::fmod(std::abs(a - b), 2 * kPi);
  return d > kPi ? 2 * kPi - d : d;
}

std::string validate(const FormMeasurements& m, const std::string& src) {
  struct F {
    const char* name;
    double v;
    double lo, hi;
  };
  const F fields[] = {
      {"bust_girth", m.bust_girth, 0.3, 3.0},       {"waist_girth", m.waist_girth, 0.2, 3.0},
      {"hip_girth", m.hip_girth, 0.3, 3.0},         {"height", m.height, 0.5, 2.6},
      {"bust_height", m.bust_height, 0.2, 2.5},     {"waist_height", m.waist_height, 0.2, 2.5},
      {"hip_height", m.hip_height, 0.1, 2.5},       {"neck_height", m.neck_height, 0.3, 2.6},
      {"bottom_height", m.bottom_height, 0.0, 2.5}, {"bust_aspect", m.bust_aspect, 1.0, 2.5},
      {"waist_aspect", m.waist_aspect, 1.0, 2.5},   {"hip_aspect", m.hip_aspect, 1.0, 2.5},
  };
  for (const F& f : fields) {
    if (!std::isfinite(f.v)) return src + ": field '" + f.name + "' is not a finite number";
    if (f.v < 0) return src + ": field '" + f.name + "' is negative";
    if (f.v < f.lo || f.v > f.hi) {
      std::ostringstream os;
      os << src << ": field '" << f.name << "' = " << f.v << " m is outside [" << f.lo << ", "
         << f.hi << "] (values are in metres)";
      return os.str();
    }
  }
  auto order = [&](const char* lo, double a, const char* hi, double b) -> std::string {
    if (a + 0.02 <= b) return {};
    return src + ": field '" + hi + "' must be at least 2 cm above '" + lo +
           "' (inconsistent heights)";
  };
  for (std::string e : {order("bottom_height", m.bottom_height, "hip_height", m.hip_height),
                        order("hip_height", m.hip_height, "waist_height", m.waist_height),
                        order("waist_height", m.waist_height, "bust_height", m.bust_height),
                        order("bust_height", m.bust_height, "neck_height", m.neck_height)}) {
    if (!e.empty()) return e;
  }
  if (m.neck_height > m.height)
    return src + ": field 'neck_height' is above 'height' (inconsistent heights)";
  return {};
}

// Built-in copies of assets/forms/*.json (used when the caller gives no forms directory or it
// lacks the size; a test checks that both agree).
std::optional<FormMeasurements> builtin_size(const std::string& size) {
  FormMeasurements m;
  m.size = size;
  if (size == "7AR") {
    m.bust_girth = 0.80, m.waist_girth = 0.61, m.hip_girth = 0.87;
  } else if (size == "9AR") {
    m.bust_girth = 0.83, m.waist_girth = 0.64, m.hip_girth = 0.91;
  } else if (size == "11AR") {
    m.bust_girth = 0.86, m.waist_girth = 0.67, m.hip_girth = 0.93;
  } else if (size == "13AR") {
    m.bust_girth = 0.89, m.waist_girth = 0.70, m.hip_girth = 0.95;
  } else {
    return std::nullopt;
  }
  return m;
}

}  // namespace

Result<FormMeasurements> parse_measurements(const std::string& json_text,
                                            const std::string& source) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(json_text);
  } catch (const std::exception& e) {
    return make_error(source, std::string("not valid JSON (") + e.what() + ")");
  }
  if (!j.is_object()) return make_error(source, "expected a JSON object of measurements");
  FormMeasurements m;
  std::filesystem::path p(source);
  m.size = p.stem().string();
  if (j.contains("size")) {
    if (!j["size"].is_string()) return make_error(source, "field 'size' is not a string");
    m.size = j["size"].get<std::string>();
  }
  struct Field {
    const char* name;
    double* dst;
    bool required;
  };
  const Field fields[] = {
      {"bust_girth", &m.bust_girth, true},       {"waist_girth", &m.waist_girth, true},
      {"hip_girth", &m.hip_girth, true},         {"height", &m.height, true},
      {"bust_height", &m.bust_height, true},     {"waist_height", &m.waist_height, true},
      {"hip_height", &m.hip_height, true},       {"neck_height", &m.neck_height, true},
      {"bottom_height", &m.bottom_height, true}, {"bust_aspect", &m.bust_aspect, false},
      {"waist_aspect", &m.waist_aspect, false},  {"hip_aspect", &m.hip_aspect, false},
  };
  for (const auto& item : j.items()) {  // typos in optional fields must not pass silently
    const std::string& key = item.key();
    if (key.empty() || key[0] == '_' || key == "size") continue;
    bool known = false;
    for (const Field& f : fields) known = known || key == f.name;
    if (!known) return make_error(source, "unknown field '" + key + "'");
  }
  for (const Field& f : fields) {
    if (!j.contains(f.name)) {
      if (f.required) return make_error(source, std::string("missing field '") + f.name + "'");
      continue;
    }
    const auto& v = j[f.name];
    if (!v.is_number())
      return make_error(source, std::string("field '") + f.name + "' is not a number (metres)");
    *f.dst = v.get<double>();
  }
  std::string e = validate(m, source);
  if (!e.empty()) return Error{e};
  return m;
}

Result<FormMeasurements> load_measurements(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(path, "cannot open measurements file");
  std::stringstream ss;
  ss << in.rdbuf();
  if (ss.str().empty()) return make_error(path, "empty file");
  return parse_measurements(ss.str(), path);
}

Result<FormMeasurements> measurements_for_size(const std::string& size,
                                               const std::filesystem::path& forms_dir) {
  auto builtin = builtin_size(size);
  if (!builtin) return make_error(size, "unknown form size (known: 7AR, 9AR, 11AR, 13AR)");
  if (!forms_dir.empty()) {
    std::error_code ec;
    const auto f = forms_dir / (size + ".json");
    if (std::filesystem::is_regular_file(f, ec)) return load_measurements(f.string());
  }
  return *builtin;
}

Result<DressForm> DressForm::from_measurements(const FormMeasurements& m, double spacing) {
  const std::string src = "measurements '" + m.size + "'";
  if (std::string e = validate(m, src); !e.empty()) return Error{e};
  if (!(spacing >= 0.0005 && spacing <= 0.05))
    return make_error(src, "section_spacing must be in [0.0005, 0.05] m");

  // Knots: the measured landmarks plus derived ones (underbust, armpit, shoulder) placed in
  // proportion to the torso, so any consistent set of heights gives an ordered knot list.
  const double yb = m.bottom_height, yh = m.hip_height, yw = m.waist_height, yu = m.bust_height,
               yn = m.neck_height;
  const double y_under = yu - 0.39 * (yu - yw);
  const double y_arm = yu + 0.34 * (yn - yu);
  const double y_sh = yn - kShoulderBelowNeck * (yn - yu);
  const std::vector<double> ky = {yb, yh, yw, y_under, yu, y_arm, y_sh, yn};
  const double B = m.bust_girth, W = m.waist_girth, H = m.hip_girth;
  const double s = B / 0.83;  // size scale for the offsets designed on the 9AR
  MonotoneCubic girth(ky, {0.95 * H, H, W, W + 0.35 * (B - W), B, 0.97 * B, 1.10 * B, 0.42 * B});
  MonotoneCubic aspect(ky, {0.96 * m.hip_aspect, m.hip_aspect, m.waist_aspect, m.waist_aspect,
                            m.bust_aspect, 1.45, 2.6, 1.1});
  MonotoneCubic p_front(ky, {2.2, 2.3, 2.2, 2.3, 2.5, 2.6, 2.8, 2.0});
  MonotoneCubic p_back(ky, {2.3, 2.5, 2.3, 2.3, 2.4, 2.6, 2.8, 2.0});
  MonotoneCubic z_centre(
      ky, {-0.012 * s, -0.018 * s, 0.0, 0.008 * s, 0.012 * s, 0.0, -0.02 * s, -0.015 * s});

  const int ns = static_cast<int>(std::floor((yn - yb) / spacing + 1e-9)) + 1;
  if (ns < 4) return make_error(src, "form too short for the section spacing");
  std::vector<Vec2> centres(ns);
  std::vector<double> radii(static_cast<size_t>(ns) * kN);
  std::array<double, kN> r;
  const double bust_sigma = 0.045 * s, seat_sigma = 0.06 * s;
  for (int j = 0; j < ns; ++j) {
    const double y = yb + spacing * j;
    const double A = aspect(y), pf = p_front(y), pb = p_back(y);
    const double bust_amp = 0.07 * std::exp(-std::pow((y - yu) / bust_sigma, 2));
    const double seat_amp = 0.04 * std::exp(-std::pow((y - (yh + 0.01)) / seat_sigma, 2));
    for (int n = 0; n < kN; ++n) {
      const double th = theta(n);
      const double sx = std::abs(std::sin(th)) / A, cz = std::cos(th);
      const double p = cz >= 0 ? pf : pb;
      double rr = 1.0 / std::pow(std::pow(sx, p) + std::pow(std::abs(cz), p), 1.0 / p);
      // Bust points at +-0.65 rad from centre front; seat at +-0.55 rad from centre back.
      const double bust = std::exp(-std::pow(ang_dist(th, 0.65) / 0.4, 2)) +
                          std::exp(-std::pow(ang_dist(th, 2 * kPi - 0.65) / 0.4, 2));
      const double seat = std::exp(-std::pow(ang_dist(th, kPi + 0.55) / 0.5, 2)) +
                          std::exp(-std::pow(ang_dist(th, kPi - 0.55) / 0.5, 2));
      rr *= 1.0 + bust_amp * bust + seat_amp * seat;
      r[n] = rr;
    }
    convexify(r);
    const double k = girth(y) / polygon_perimeter(r);
    for (int n = 0; n < kN; ++n) radii[static_cast<size_t>(j) * kN + n] = r[n] * k;
    centres[j] = Vec2(0.0, z_centre(y));
  }

  FormLandmarks lm;
  lm.bottom_y = yb;
  lm.top_y = yb + spacing * (ns - 1);
  lm.hip_y = yh, lm.waist_y = yw, lm.bust_y = yu, lm.neck_y = yn;
  lm.shoulder_y = y_sh;
  lm.armpit_y = yu + kArmpitAboveBust * (yn - yu);

  // Exact girths at the three measured heights: when a landmark falls between two sections,
  // scale that pair so the interpolated polygon has the requested perimeter (a correction of
  // order 1e-4; girth is 1-homogeneous in the radii).
  for (int pass = 0; pass < 2; ++pass) {
    DressForm f(yb, spacing, centres, radii, lm);
    for (auto [y, g] : {std::pair{yu, B}, std::pair{yw, W}, std::pair{yh, H}}) {
      const double got = f.girth_at(y);
      const int j = std::clamp(static_cast<int>((y - yb) / spacing), 0, ns - 2);
      for (int jj : {j, j + 1})
        for (int n = 0; n < kN; ++n) radii[static_cast<size_t>(jj) * kN + n] *= g / got;
    }
  }
  return DressForm(yb, spacing, std::move(centres), std::move(radii), lm);
}

}  // namespace drape::sim
