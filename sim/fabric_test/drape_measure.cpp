// Drape-test measurement from a top-view shadow (sim/fabric_test/drape_measure.hpp).
#include "sim/fabric_test/drape_measure.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape::sim {

namespace {
constexpr double kPi = 3.14159265358979323846;

int cell_floor(const ShadowRaster& r, double c) {
  return static_cast<int>(std::floor((c + r.half_width) / r.pixel));
}

// Cells [lo, hi] of the raster whose centres can lie in [a, b].
void cell_range(const ShadowRaster& r, double a, double b, int& lo, int& hi) {
  lo = std::max(0, cell_floor(r, a));
  hi = std::min(r.size - 1, cell_floor(r, b));
}

double edge(const Vec2& a, const Vec2& b, const Vec2& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}

void rasterize_triangle(const Vec2& a, const Vec2& b, const Vec2& c, ShadowRaster& r) {
  const double area = edge(a, b, c);
  if (std::abs(area) < 1e-16) return;
  const double s = area > 0 ? 1.0 : -1.0;
  int i0, i1, j0, j1;
  cell_range(r, std::min({a.x(), b.x(), c.x()}), std::max({a.x(), b.x(), c.x()}), i0, i1);
  cell_range(r, std::min({a.y(), b.y(), c.y()}), std::max({a.y(), b.y(), c.y()}), j0, j1);
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const Vec2 p(r.centre(i), r.centre(j));
      if (s * edge(a, b, p) >= 0 && s * edge(b, c, p) >= 0 && s * edge(c, a, p) >= 0)
        r.cells[static_cast<size_t>(j) * r.size + i] = 1;
    }
  }
}
}  // namespace

void ShadowRaster::reset(double half_width_m, double pixel_m) {
  pixel = pixel_m;
  size = static_cast<int>(std::ceil(2 * half_width_m / pixel_m));
  half_width = 0.5 * size * pixel;
  cells.assign(static_cast<size_t>(size) * size, 0);
}

double ShadowRaster::area() const {
  return static_cast<double>(std::count(cells.begin(), cells.end(), 1)) * pixel * pixel;
}

void rasterize_mesh(const TriMesh& mesh, ShadowRaster& raster) {
  auto top = [&](int v) { return Vec2(mesh.vertices[v].x(), -mesh.vertices[v].z()); };
  for (const auto& t : mesh.triangles) rasterize_triangle(top(t[0]), top(t[1]), top(t[2]), raster);
}

void rasterize_polygon(const std::vector<Vec2>& outline, ShadowRaster& r) {
  const size_t n = outline.size();
  if (n < 3) return;
  std::vector<double> xs;
  for (int j = 0; j < r.size; ++j) {
    const double w = r.centre(j);
    xs.clear();
    for (size_t k = 0; k < n; ++k) {
      const Vec2& a = outline[k];
      const Vec2& b = outline[(k + 1) % n];
      if ((a.y() <= w) == (b.y() <= w)) continue;
      xs.push_back(a.x() + (w - a.y()) / (b.y() - a.y()) * (b.x() - a.x()));
    }
    std::sort(xs.begin(), xs.end());
    for (size_t k = 0; k + 1 < xs.size(); k += 2) {
      const int i0 =
          std::max(0, static_cast<int>(std::ceil((xs[k] + r.half_width) / r.pixel - 0.5)));
      const int i1 = std::min(
          r.size - 1, static_cast<int>(std::floor((xs[k + 1] + r.half_width) / r.pixel - 0.5)));
      for (int i = i0; i <= i1; ++i) r.cells[static_cast<size_t>(j) * r.size + i] = 1;
    }
  }
}

void fill_holes(ShadowRaster& r) {
  // Flood the empty cells reachable from the border (4-connected); the rest becomes shadow.
  const int n = r.size;
  std::vector<uint8_t> outside(r.cells.size(), 0);
  std::vector<int> stack;
  auto push = [&](int i, int j) {
    const size_t k = static_cast<size_t>(j) * n + i;
    if (r.cells[k] || outside[k]) return;
    outside[k] = 1;
    stack.push_back(static_cast<int>(k));
  };
  for (int k = 0; k < n; ++k) {
    push(k, 0);
    push(k, n - 1);
    push(0, k);
    push(n - 1, k);
  }
  while (!stack.empty()) {
    const int k = stack.back();
    stack.pop_back();
    const int i = k % n, j = k / n;
    if (i > 0) push(i - 1, j);
    if (i + 1 < n) push(i + 1, j);
    if (j > 0) push(i, j - 1);
    if (j + 1 < n) push(i, j + 1);
  }
  for (size_t k = 0; k < r.cells.size(); ++k) r.cells[k] = outside[k] ? 0 : 1;
}

RadiusProfile radius_profile(const ShadowRaster& r) {
  RadiusProfile prof{};
  for (int j = 0; j < r.size; ++j) {
    const double w = r.centre(j);
    for (int i = 0; i < r.size; ++i) {
      if (!r.at(i, j)) continue;
      const double x = r.centre(i);
      double deg = std::atan2(w, x) * (180 / kPi);
      if (deg < 0) deg += 360;
      const int b = std::min(kProfileBins - 1, static_cast<int>(deg));
      prof[b] = std::max(prof[b], std::hypot(x, w));
    }
  }
  return prof;
}

RadiusProfile smooth_profile(const RadiusProfile& r, double sigma_deg) {
  if (sigma_deg <= 0) return r;
  const int half = static_cast<int>(std::ceil(4 * sigma_deg));
  std::vector<double> k(2 * half + 1);
  double sum = 0;
  for (int d = -half; d <= half; ++d)
    sum += k[d + half] = std::exp(-0.5 * d * d / (sigma_deg * sigma_deg));
  RadiusProfile out{};
  for (int b = 0; b < kProfileBins; ++b) {
    double acc = 0;
    for (int d = -half; d <= half; ++d)
      acc += k[d + half] * r[((b + d) % kProfileBins + kProfileBins) % kProfileBins];
    out[b] = acc / sum;
  }
  return out;
}

namespace {
// The lowest value passed walking from peak b in direction `step` until a value above r[b]
// (infinity-free: `found` says whether one was reached within the circle).
double walk_min(const RadiusProfile& r, int b, int step, bool& found) {
  double lo = r[b];
  found = false;
  for (int s = 1; s < kProfileBins; ++s) {
    const double v = r[((b + s * step) % kProfileBins + kProfileBins) % kProfileBins];
    if (v > r[b]) {
      found = true;
      break;
    }
    lo = std::min(lo, v);
  }
  return lo;
}
}  // namespace

std::vector<int> prominent_peaks(const RadiusProfile& r, double min_prominence) {
  std::vector<int> peaks;
  const double global_min = *std::min_element(r.begin(), r.end());
  for (int b = 0; b < kProfileBins; ++b) {
    const double prev = r[(b + kProfileBins - 1) % kProfileBins];
    const double next = r[(b + 1) % kProfileBins];
    if (!(r[b] > prev && r[b] >= next)) continue;
    bool found_l = false, found_r = false;
    const double lo_l = walk_min(r, b, -1, found_l);
    const double lo_r = walk_min(r, b, +1, found_r);
    const double base = found_l || found_r ? std::max(lo_l, lo_r) : global_min;
    if (r[b] - base >= min_prominence) peaks.push_back(b);
  }
  return peaks;
}

DrapeMeasures measure_shadow(const ShadowRaster& raster, const DrapeMeasureOptions& opt) {
  DrapeMeasures m;
  const double a_disc = kPi * 0.25 * opt.disc_diameter * opt.disc_diameter;
  const double a_spec = kPi * 0.25 * opt.specimen_diameter * opt.specimen_diameter;
  m.shadow_area = raster.area();
  m.dc = (m.shadow_area - a_disc) / (a_spec - a_disc);
  m.profile = radius_profile(raster);
  m.node_bins = prominent_peaks(smooth_profile(m.profile, opt.smoothing_deg), opt.node_prominence);
  m.nodes = static_cast<int>(m.node_bins.size());
  m.r_min = *std::min_element(m.profile.begin(), m.profile.end());
  m.r_max = *std::max_element(m.profile.begin(), m.profile.end());
  return m;
}

std::string write_shadow_png(const ShadowRaster& r, const DrapeMeasureOptions& opt,
                             const std::string& path) {
  cairo_surface_t* s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, r.size, r.size);
  if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS) {
    cairo_surface_destroy(s);
    return path + ": cannot make a " + std::to_string(r.size) + " px image";
  }
  cairo_surface_flush(s);
  unsigned char* data = cairo_image_surface_get_data(s);
  const int stride = cairo_image_surface_get_stride(s);
  for (int row = 0; row < r.size; ++row) {
    auto* px = reinterpret_cast<uint32_t*>(data + static_cast<size_t>(row) * stride);
    const int j = r.size - 1 - row;  // the image's top row is the largest w (the warp up)
    for (int i = 0; i < r.size; ++i) px[i] = r.at(i, j) ? 0x202020u : 0xffffffu;
  }
  cairo_surface_mark_dirty(s);
  cairo_t* cr = cairo_create(s);
  cairo_set_source_rgb(cr, 0.55, 0.55, 0.55);
  cairo_set_line_width(cr, 1.0);
  const double c = 0.5 * r.size;
  for (double d : {opt.disc_diameter, opt.specimen_diameter}) {
    cairo_new_path(cr);
    cairo_arc(cr, c, c, 0.5 * d / r.pixel, 0, 2 * kPi);
    cairo_stroke(cr);
  }
  cairo_destroy(cr);
  const cairo_status_t st = cairo_surface_write_to_png(s, path.c_str());
  cairo_surface_destroy(s);
  if (st != CAIRO_STATUS_SUCCESS)
    return path + ": cannot write the PNG (" + cairo_status_to_string(st) + ")";
  return {};
}

}  // namespace drape::sim
