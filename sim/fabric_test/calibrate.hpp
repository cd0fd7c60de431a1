// Calibration of a fabric's bending from measured drape figures (docs/fabrics.md): a 1-D search
// over the bending rigidity B (the geometric mean of warp and weft, their ratio fixed) until the
// virtual drape tester's mean DC over a few seeds matches the measured DC. DC grows with B; the
// search is regula falsi (Illinois) on logit(DC) against log B, the bracket widened by steps of
// 8x in B until it holds the target.
// DC hardly depends on the warp/weft ratio at a given B, but the fold depth does: a drape's
// R_max - R_min (its deepest fold against its widest node, whatever way the specimen was turned)
// grows with the ratio, the weak direction hanging lower. Given a measured mean fold depth, the
// depth is probed at a second ratio, the ratio interpolated to the measured depth and B fitted
// to DC again there; without it the ratio is an input and the depth a prediction.
#pragma once

#include <string>
#include <vector>

#include "sim/core/fabric.hpp"
#include "sim/fabric_test/drape_tester.hpp"

namespace drape::sim {

struct CalibrationOptions {
  DrapeTestOptions test;         // the tester's set-up (resolution, diameters, ...)
  int seeds = 2;                 // drapes averaged per evaluation
  int threads = 2;               // drapes run at once
  double warp_weft_ratio = 1.6;  // bending_warp / bending_weft (muslin's preset); the first
                                 // ratio tried when fold_depth is given
  double dc_tolerance = 0.005;   // stop once |DC_sim - DC| is below
  int max_evaluations = 10;      // per fit of B
  // The measured mean fold depth R_max - R_min (m) the ratio is fitted to; 0: the ratio stays
  // warp_weft_ratio (B fitted to DC alone).
  double fold_depth = 0;
  double depth_tolerance = 0.002;  // m: the depth's scale when the better of two fits is taken
  // The ratios a fit may reach (woven fabrics measure about 1 to 4 warp against weft).
  double min_ratio = 1, max_ratio = 4;
  // Membrane properties of the preset (not measured by a drape test): muslin's.
  FabricParams base;
};

struct CalibrationStep {
  double bending = 0;  // N m, geometric mean
  double ratio = 0;    // warp / weft
  double dc = 0;       // mean over the seeds
  double depth = 0;    // m, mean R_max - R_min over the seeds
};

struct CalibrationResult {
  FabricParams fabric;  // the preset: base, the density, the fitted bending
  double dc_target = 0;
  DrapeSeries series;   // the drapes at the fitted bending
  double residual = 0;  // DC_sim - DC_target
  double ratio = 0;     // the warp/weft ratio of the preset (fitted when fold_depth was given)
  double depth_residual = 0;  // m, fold depth sim - measured (0 without a measured depth)
  int ratio_fits = 0;         // fits of B run (1 without a measured depth, else 2)
  std::vector<CalibrationStep> steps;
  double seconds = 0;
};

// Fits the bending of a fabric of `density_gsm` g/m^2 to a measured drape coefficient `dc` (and
// its warp/weft ratio to opt.fold_depth when given). Errors: density not positive and finite, DC
// outside (0, 1), a fold depth negative or beyond the specimen, a ratio range that is empty or
// not positive, or a drape that failed.
Result<CalibrationResult> calibrate_bending(double density_gsm, double dc,
                                            const CalibrationOptions& opt);

// Writes (or replaces) preset `name` in the fabrics JSON file `path` (created when missing),
// keeping every other entry, with `source` and the residual noted in its "_source".
std::string save_fabric_preset(const std::string& path, const std::string& name,
                               const FabricParams& f, const std::string& source);

}  // namespace drape::sim
