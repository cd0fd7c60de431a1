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

struct Point {
  double logb, f;  // log B, logit(DC_sim) - logit(DC_target)
};

double depth(const DrapeSeries& s) {
  return s.rmax_mean - s.rmin_mean;
}

// A fit's distance from the targets, each error in units of its tolerance.
double miss(const DrapeSeries& s, double dc, const CalibrationOptions& o) {
  return std::abs(s.dc_mean - dc) / o.dc_tolerance +
         std::abs(depth(s) - o.fold_depth) / o.depth_tolerance;
}

// The search for B at one warp/weft ratio: its evaluations (appended to `steps`) and the best
// of them: the one nearest the target DC or, with `by_miss`, nearest both targets (miss). The
// search stops once an evaluation's DC is within the tolerance. Two seeds' mean DC scatters by
// about 0.015 between nearby B where the fold pattern changes, so the evaluations near the
// target DC differ in depth by several millimetres: with the depth fitted too, the one nearest
// both targets is the fit.
struct LevelSearch {
  const FabricParams& base;
  double target, ratio;
  const CalibrationOptions& o;
  std::vector<CalibrationStep>& steps;
  bool by_miss = false;
  size_t first = steps.size();
  DrapeSeries best;
  double best_b = 0;
  double nearest_dc = 1;  // the smallest |DC - target| so far

  bool more() const {
    return static_cast<int>(steps.size() - first) < o.max_evaluations &&
           nearest_dc > o.dc_tolerance;
  }
  // The mean DC over the seeds at B = exp(logb).
  Result<Point> eval(double logb) {
    const double b = std::exp(logb);
    auto s = run_drape_series(with_bending(base, b, ratio), o.test, o.seeds, o.threads);
    if (!s) return Error{s.error()};
    steps.push_back({b, ratio, s->dc_mean, depth(*s)});
    const bool better = by_miss ? miss(*s, target, o) < miss(best, target, o)
                                : std::abs(s->dc_mean - target) < std::abs(best.dc_mean - target);
    if (best_b == 0 || better) {
      best = *s;
      best_b = b;
    }
    nearest_dc = std::min(nearest_dc, std::abs(s->dc_mean - target));
    return Point{logb, logit(s->dc_mean) - logit(target)};
  }
  // Regula falsi with the Illinois modification on f(log B); `lo` has f < 0, `hi` f > 0.
  std::string refine(Point lo, Point hi) {
    int side = 0;
    while (more()) {
      auto p = eval(hi.logb - hi.f * (hi.logb - lo.logb) / (hi.f - lo.f));
      if (!p) return p.error();
      if (p->f < 0) {
        lo = *p;
        if (side == -1) hi.f *= 0.5;
        side = -1;
      } else {
        hi = *p;
        if (side == 1) lo.f *= 0.5;
        side = 1;
      }
    }
    return {};
  }
  // From B = b0, stepping by `factor` in B until the target lies between two evaluations, then
  // refined.
  std::string run(double b0, double factor) {
    auto a = eval(std::log(b0));
    if (!a) return a.error();
    Point c = *a;
    while (more() && (a->f < 0) == (c.f < 0)) {
      *a = c;
      auto n = eval(a->logb + (a->f < 0 ? 1 : -1) * std::log(factor));
      if (!n) return n.error();
      c = *n;
    }
    if ((a->f < 0) != (c.f < 0)) return refine(a->f < 0 ? *a : c, a->f < 0 ? c : *a);
    return {};
  }
};

std::string check_inputs(double density_gsm, double dc, const CalibrationOptions& o) {
  if (!(density_gsm > 0) || !std::isfinite(density_gsm) || density_gsm > 5000)
    return "density must be in (0, 5000] g/m^2";
  if (!(dc > 0 && dc < 1)) return "DC must be in (0, 1)";
  if (!(o.warp_weft_ratio > 0)) return "warp/weft ratio must be > 0";
  if (!(o.fold_depth >= 0 && o.fold_depth < 0.5 * o.test.specimen_diameter))
    return "fold depth must be in [0, the specimen's radius)";
  if (o.fold_depth > 0 && !(o.min_ratio > 0 && o.min_ratio < o.max_ratio))
    return "the warp/weft ratios searched must be 0 < min < max";
  return {};
}

}  // namespace

Result<CalibrationResult> calibrate_bending(double density_gsm, double dc,
                                            const CalibrationOptions& o) {
  if (std::string e = check_inputs(density_gsm, dc, o); !e.empty())
    return make_error("calibrate", e);
  const auto t0 = std::chrono::steady_clock::now();
  CalibrationResult res;
  res.dc_target = dc;
  FabricParams base = o.base;
  base.areal_density = density_gsm * 1e-3;
  // Start from a bending length c = (B / w)^(1/3) of 3 cm (w: weight per area), a mid-range
  // cloth, and step by 8x in B (2x in c) until the target lies between two evaluations.
  const double w = base.areal_density * kGravity0;
  LevelSearch fit{base, dc, o.warp_weft_ratio, o, res.steps};
  if (std::string e = fit.run(w * std::pow(0.03, 3), 8.0); !e.empty()) return Error{e};
  res.ratio_fits = 1;
  DrapeSeries best = fit.best;
  double best_b = fit.best_b, best_r = o.warp_weft_ratio;
  if (o.fold_depth > 0) {
    // The ratio: the depth probed at twice (or half) the ratio with B kept (DC barely moves
    // with the ratio), the ratio interpolated in log(ratio) to the measured depth (within
    // [min_ratio, max_ratio] and 4x of the first), then B fitted to DC again there from the
    // first fit's (steps of 1.5x).
    const double r0 = std::log(o.warp_weft_ratio), d0 = depth(fit.best);
    const double r1 = r0 + (d0 < o.fold_depth ? 1 : -1) * std::log(2.0);
    LevelSearch probe{base, dc, std::exp(r1), o, res.steps};
    auto p = probe.eval(std::log(fit.best_b));
    if (!p) return Error{p.error()};
    const double d1 = depth(probe.best), slope = (d1 - d0) / (r1 - r0);
    double r = slope > 0 ? r0 + (o.fold_depth - d0) / slope
                         : (std::abs(d1 - o.fold_depth) < std::abs(d0 - o.fold_depth) ? r1 : r0);
    r = std::clamp(r, r0 - std::log(4.0), r0 + std::log(4.0));
    r = std::clamp(r, std::log(o.min_ratio), std::log(o.max_ratio));
    LevelSearch next{base, dc, std::exp(r), o, res.steps, true};
    if (std::string e = next.run(fit.best_b, 1.5); !e.empty()) return Error{e};
    res.ratio_fits = 2;
    if (miss(next.best, dc, o) < miss(best, dc, o)) {
      best = next.best;
      best_b = next.best_b;
      best_r = std::exp(r);
    }
  }
  res.fabric = with_bending(base, best_b, best_r);
  res.ratio = best_r;
  res.series = std::move(best);
  res.residual = res.series.dc_mean - dc;
  if (o.fold_depth > 0) res.depth_residual = depth(res.series) - o.fold_depth;
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
  doc[name] = {{"description", "calibrated with the virtual drape tester"}, {"_source", source}};
  put_fabric_values(doc[name], f);
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
