// Calibration of a fabric's bending from measured drape figures (docs/fabrics.md): a 1-D search
// over the bending rigidity B (the geometric mean of warp and weft, their ratio fixed) until the
// virtual drape tester's mean DC over a few seeds matches the measured DC. DC grows with B; the
// search is regula falsi (Illinois) on logit(DC) against log B, the bracket widened by steps of
// 8x in B until it holds the target. A drape test's DC and its node count are the only figures
// of the published data; the warp/weft split is not in them (an outline averaged over
// specimens turned at random), so the ratio is an input, not a fit.
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
  double warp_weft_ratio = 1.6;  // bending_warp / bending_weft (muslin's preset)
  double dc_tolerance = 0.005;   // stop once |DC_sim - DC| is below
  int max_evaluations = 10;
  // Membrane properties of the preset (not measured by a drape test): muslin's.
  FabricParams base;
};

struct CalibrationStep {
  double bending = 0;  // N m, geometric mean
  double dc = 0;       // mean over the seeds
};

struct CalibrationResult {
  FabricParams fabric;  // the preset: base, the density, the fitted bending
  double dc_target = 0;
  DrapeSeries series;   // the drapes at the fitted bending
  double residual = 0;  // DC_sim - DC_target
  std::vector<CalibrationStep> steps;
  double seconds = 0;
};

// Fits the bending of a fabric of `density_gsm` g/m^2 to a measured drape coefficient `dc`.
// Errors: density not positive and finite, DC outside (0, 1), or a drape that failed.
Result<CalibrationResult> calibrate_bending(double density_gsm, double dc,
                                            const CalibrationOptions& opt);

// Writes (or replaces) preset `name` in the fabrics JSON file `path` (created when missing),
// keeping every other entry, with `source` and the residual noted in its "_source".
std::string save_fabric_preset(const std::string& path, const std::string& name,
                               const FabricParams& f, const std::string& source);

}  // namespace drape::sim
