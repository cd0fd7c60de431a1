// Bending from a measured drape coefficient (sim/fabric_test/calibrate.hpp).
#include "sim/fabric_test/calibrate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace drape::sim {

namespace {
constexpr double kGravity0 = 9.81;

FabricParams with_bending(FabricParams f, double b, double ratio) {
  f.bending_warp = b * std::sqrt(ratio);
  f.bending_weft = b / std::sqrt(ratio);
  return f;
}

double logit(double p) {
  p = std::clamp(p, 1e-4, 1 - 1e-4);
  return std::log(p / (1 - p));
}

// One evaluation: the mean DC over the seeds at bending b (geometric mean).
Result<DrapeSeries> evaluate(const FabricParams& base, double b, const CalibrationOptions& o,
                             std::vector<CalibrationStep>& steps) {
  auto s = run_drape_series(with_bending(base, b, o.warp_weft_ratio), o.test, o.seeds, o.threads);
  if (s) steps.push_back({b, s->dc_mean});
  return s;
}

struct Point {
  double logb, f;  // log B, logit(DC_sim) - logit(DC_target)
};

// Regula falsi with the Illinois modification on f(log B); `lo` has f < 0, `hi` f > 0.
Result<DrapeSeries> refine(Point lo, Point hi, DrapeSeries best, double& best_b,
                           const FabricParams& base, double target, const CalibrationOptions& o,
                           std::vector<CalibrationStep>& steps) {
  int side = 0;
  while (std::abs(best.dc_mean - target) > o.dc_tolerance &&
         static_cast<int>(steps.size()) < o.max_evaluations) {
    const double x = hi.logb - hi.f * (hi.logb - lo.logb) / (hi.f - lo.f);
    auto s = evaluate(base, std::exp(x), o, steps);
    if (!s) return s;
    const Point p{x, logit(s->dc_mean) - logit(target)};
    if (std::abs(s->dc_mean - target) < std::abs(best.dc_mean - target)) {
      best = *s;
      best_b = std::exp(x);
    }
    if (p.f < 0) {
      lo = p;
      if (side == -1) hi.f *= 0.5;
      side = -1;
    } else {
      hi = p;
      if (side == 1) lo.f *= 0.5;
      side = 1;
    }
  }
  return best;
}
}  // namespace

Result<CalibrationResult> calibrate_bending(double density_gsm, double dc,
                                            const CalibrationOptions& o) {
  if (!(density_gsm > 0) || !std::isfinite(density_gsm) || density_gsm > 5000)
    return make_error("calibrate", "density must be in (0, 5000] g/m^2");
  if (!(dc > 0 && dc < 1)) return make_error("calibrate", "DC must be in (0, 1)");
  if (!(o.warp_weft_ratio > 0)) return make_error("calibrate", "warp/weft ratio must be > 0");
  const auto t0 = std::chrono::steady_clock::now();
  CalibrationResult res;
  res.dc_target = dc;
  FabricParams base = o.base;
  base.areal_density = density_gsm * 1e-3;
  // Start from a bending length c = (B / w)^(1/3) of 3 cm (w: weight per area), a mid-range
  // cloth, and step by 8x in B (2x in c) until the target lies between two evaluations.
  const double w = base.areal_density * kGravity0;
  double b = w * std::pow(0.03, 3);
  auto first = evaluate(base, b, o, res.steps);
  if (!first) return Error{first.error()};
  Point a{std::log(b), logit(first->dc_mean) - logit(dc)};
  DrapeSeries best = *first;
  double best_b = b;
  Point c = a;
  while (static_cast<int>(res.steps.size()) < o.max_evaluations &&
         std::abs(best.dc_mean - dc) > o.dc_tolerance && (a.f < 0) == (c.f < 0)) {
    a = c;
    b = std::exp(a.logb) * (a.f < 0 ? 8.0 : 0.125);
    auto s = evaluate(base, b, o, res.steps);
    if (!s) return Error{s.error()};
    c = {std::log(b), logit(s->dc_mean) - logit(dc)};
    if (std::abs(s->dc_mean - dc) < std::abs(best.dc_mean - dc)) {
      best = *s;
      best_b = b;
    }
  }
  if ((a.f < 0) != (c.f < 0)) {
    auto r = refine(a.f < 0 ? a : c, a.f < 0 ? c : a, best, best_b, base, dc, o, res.steps);
    if (!r) return Error{r.error()};
    best = *r;
  }
  res.fabric = with_bending(base, best_b, o.warp_weft_ratio);
  res.series = std::move(best);
  res.residual = res.series.dc_mean - dc;
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

std::string save_fabric_preset(const std::string& path, const std::string& name,
                               const FabricParams& f, const std::string& source) {
  nlohmann::ordered_json doc = nlohmann::ordered_json::object();
  {
    std::ifstream in(path, std::ios::binary);
    if (in) {
      std::stringstream ss;
      ss << in.rdbuf();
      try {
        doc = nlohmann::ordered_json::parse(ss.str());
      } catch (const nlohmann::json::exception& e) {
        return path + ": invalid JSON, not overwritten (" + e.what() + ")";
      }
      if (!doc.is_object()) return path + ": top level is not an object, not overwritten";
    }
  }
  doc[name] = {{"description", "calibrated with the virtual drape tester"},
               {"_source", source},
               {"areal_density", f.areal_density},
               {"thickness", f.thickness},
               {"stretch_warp", f.stretch_warp},
               {"stretch_weft", f.stretch_weft},
               {"shear", f.shear},
               {"bending_warp", f.bending_warp},
               {"bending_weft", f.bending_weft}};
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return path + ": cannot write";
    out << doc.dump(2) << "\n";
    if (!out) return path + ": write failed";
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) return path + ": cannot replace the file";
  return {};
}

}  // namespace drape::sim
