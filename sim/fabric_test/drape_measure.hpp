// What a Cusick drape test measures, from the drape's shadow seen from straight above
// (docs/fabrics.md): the shadow rasterised at 0.5 mm with its holes filled, the drape
// coefficient DC = (A_shadow - A_disc) / (A_specimen - A_disc), the outline radius R(theta) in
// 1-degree bins, and the nodes: local maxima of R(theta) after circular Gaussian smoothing
// (sigma 4 degrees) with a prominence of at least 3 mm. The top view is the stage's x-z plane
// seen from +y, with theta measured from +x (the weft) toward -z (the warp).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/core/mesh.hpp"
#include "sim/core/types.hpp"

namespace drape::sim {

// A square raster centred on the disc's axis: cell (i, j) covers x in [x0 + i p, x0 + (i+1) p)
// and the top-view second coordinate w = -z in [x0 + j p, ...), with x0 = -half_width.
struct ShadowRaster {
  double pixel = 0.0005;       // m
  double half_width = 0;       // m
  int size = 0;                // cells per side
  std::vector<uint8_t> cells;  // 1: shadow, row j = w bin

  void reset(double half_width_m, double pixel_m);
  bool at(int i, int j) const { return cells[static_cast<size_t>(j) * size + i] != 0; }
  double centre(int i) const { return -half_width + (i + 0.5) * pixel; }
  double area() const;  // m^2 covered
};

// Adds the top-view projection of every triangle (cells whose centre lies inside).
void rasterize_mesh(const TriMesh& mesh, ShadowRaster& raster);
// Adds the inside of a closed polygon given in top-view coordinates (x, w) (even-odd rule).
void rasterize_polygon(const std::vector<Vec2>& outline, ShadowRaster& raster);
// Fills every empty region not connected to the raster's border (holes in the shadow).
void fill_holes(ShadowRaster& raster);

constexpr int kProfileBins = 360;
using RadiusProfile = std::array<double, kProfileBins>;  // m, bin b covers [b, b + 1) degrees

// R(theta): per 1-degree bin, the largest distance from the axis of a shadow cell's centre.
RadiusProfile radius_profile(const ShadowRaster& raster);
// Circular Gaussian smoothing of a profile (sigma in degrees; the kernel spans +-4 sigma).
RadiusProfile smooth_profile(const RadiusProfile& r, double sigma_deg);
// Peaks of a circular signal with a prominence >= min_prominence: a peak's prominence is its
// height above the higher of the two lowest points passed on the way, left and right, to a
// higher value (the whole circle's lowest point for the highest peak). Returns the bins.
std::vector<int> prominent_peaks(const RadiusProfile& r, double min_prominence);

struct DrapeMeasureOptions {
  double specimen_diameter = 0.30;  // m
  double disc_diameter = 0.18;      // m
  double smoothing_deg = 4;         // node count: Gaussian sigma
  double node_prominence = 0.003;   // m
};

struct DrapeMeasures {
  double dc = 0;                // drape coefficient
  double shadow_area = 0;       // m^2, holes filled
  int nodes = 0;                // prominent maxima of the smoothed R(theta)
  std::vector<int> node_bins;   // their angles (degrees)
  double r_min = 0, r_max = 0;  // m, of the raw 1-degree profile
  RadiusProfile profile{};      // raw R(theta)
};

// Every figure above from a hole-filled shadow raster.
DrapeMeasures measure_shadow(const ShadowRaster& raster, const DrapeMeasureOptions& opt);

// The shadow as an 8-bit grey PNG (shadow black on white), disc outline and specimen outline
// drawn grey for reference. Returns an empty string or an error naming the file.
std::string write_shadow_png(const ShadowRaster& raster, const DrapeMeasureOptions& opt,
                             const std::string& path);

}  // namespace drape::sim
