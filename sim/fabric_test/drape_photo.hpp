// A drape test's shadow from a top-view photograph (docs/fabrics.md, "Calibration from a
// photo"): the drape segmented from a lighter background (OpenCV: Otsu threshold, the largest
// dark region, holes filled), the scale taken from the printed circle of the specimen's
// diameter around it (a Cusick tester's paper ring; HoughCircles), then resampled into a
// ShadowRaster so that DC, R(theta) and the nodes are measured as for a simulated drape.
#pragma once

#include <string>
#include <vector>

#include "sim/core/types.hpp"
#include "sim/fabric_test/drape_measure.hpp"

namespace drape::sim {

struct PhotoShadow {
  ShadowRaster raster;                // 0.5 mm cells, holes filled
  DrapeMeasures measures;             // DC, R(theta), nodes of that raster
  double metres_per_pixel = 0;        // from the reference circle
  std::vector<std::string> warnings;  // suspicious but usable (e.g. outline past the specimen)
};

// Errors name the file: unreadable or not an image, too small, no dark drape on a lighter
// background, a drape cut off by the frame, no printed circle of the specimen's diameter around
// the drape (the scale is unknown), or a DC outside [0, 1] (a wrong scale).
Result<PhotoShadow> shadow_from_photo(const std::string& path, const DrapeMeasureOptions& opt);

// A synthetic photograph of a shadow raster (tests): background grey 225, drape grey 45, the
// specimen's circle printed 2 px wide in grey 120, `pixels_per_metre`, Gaussian noise of sd
// `noise` grey levels (seeded). Written as PNG; returns an empty string or an error.
std::string write_synthetic_photo(const ShadowRaster& shadow, const DrapeMeasureOptions& opt,
                                  double pixels_per_metre, double noise, const std::string& path,
                                  bool print_circle = true);

}  // namespace drape::sim
