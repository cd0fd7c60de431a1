// The sewn garment draped on the form by XPBD (garment_sim.hpp).
#include "sim/draping/garment_sim.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <numeric>

#include "sim/core/stopwatch.hpp"
#include "sim/core/strain.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"

namespace drape::sim {
namespace {

// The ease and girths of one band of heights around y (the cloth kept `offset` off the form).
FitBand fit_band(const GarmentSimResult& r, const Garment& geometric, const MappingSurface& surf,
                 double y, double offset, double band) {
  FitBand b;
  b.y = y;
  double sum = 0;
  for (int i = 0; i < r.cloth.num_vertices(); ++i) {
    if (std::abs(r.cloth.state.x[i].y() - y) > band || !std::isfinite(r.ease[i])) continue;
    b.ease_max_mm = std::max(b.ease_max_mm, r.ease[i] * 1000);
    sum += r.ease[i] * 1000;
    ++b.vertices;
  }
  b.ease_mean_mm = b.vertices ? sum / b.vertices : 0;
  if (!b.vertices) return b;
  Garment sim = geometric;
  sim.x = r.cloth.state.x;
  b.girth_mm = garment_girth(sim, surf, y) * 1000;
  b.girth_geometric_mm = garment_girth(geometric, surf, y) * 1000;
  b.girth_expected_mm = b.girth_geometric_mm + 2 * 3.14159265358979 * offset * 1000;
  b.girth_error_pct = (b.girth_mm - b.girth_expected_mm) / b.girth_expected_mm * 100;
  return b;
}

// Ease per vertex, the deepest penetration, strain per triangle and its statistics.
void measure_fit(GarmentSimResult& r, const DressForm& form) {
  const auto& x = r.cloth.state.x;
  r.ease.assign(x.size(), std::numeric_limits<double>::quiet_NaN());
  for (size_t i = 0; i < x.size(); ++i) {
    const double d = form.signed_distance(x[i]);
    if (!std::isfinite(d)) continue;
    r.ease[i] = d;
    r.penetration_max_mm = std::max(r.penetration_max_mm, -d * 1000);
  }
  const int nt = r.cloth.topo.num_triangles();
  r.strain.assign(nt, 0.0);
  double sq = 0;
  for (int t = 0; t < nt; ++t) {
    r.strain[t] = triangle_strain(r.cloth, t);
    r.strain_max_pct = std::max(r.strain_max_pct, std::abs(r.strain[t]) * 100);
    sq += r.strain[t] * r.strain[t];
  }
  r.strain_rms_pct = nt ? std::sqrt(sq / nt) * 100 : 0;
  std::vector<double> a(nt);
  for (int t = 0; t < nt; ++t) a[t] = std::abs(r.strain[t]);
  if (nt) {
    std::nth_element(a.begin(), a.begin() + nt / 2, a.end());
    r.strain_median_pct = a[nt / 2] * 100;
    std::nth_element(a.begin(), a.begin() + nt * 95 / 100, a.end());
    r.strain_p95_pct = a[nt * 95 / 100] * 100;
  }
}

// Steps the solver until the garment rests (or max_frames); false when it diverged.
bool run_to_rest(XpbdSolver& solver, GarmentSimResult& r, const SceneObjects& scene,
                 const GarmentSimOptions& opt) {
  Cloth& cloth = r.cloth;
  int slow = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (r.frames = 0; r.frames < opt.max_frames;) {
    const StepStats st = solver.step(cloth, scene, opt.dt);
    ++r.frames;
    double vmax2 = 0;
    bool finite = true;
    for (const Vec3& v : cloth.state.v) {
      finite = finite && v.allFinite();
      vmax2 = std::max(vmax2, v.squaredNorm());
    }
    if (st.diverged || !finite) return false;
    r.max_speed_end = std::sqrt(vmax2);
    slow = r.max_speed_end < opt.rest_speed ? slow + 1 : 0;
    if (r.frames >= opt.min_frames && slow >= opt.rest_frames) {
      r.at_rest = true;
      break;
    }
  }
  r.wall_ms = ms_since(t0);
  r.ms_per_frame = r.frames ? r.wall_ms / r.frames : 0;
  return true;
}

}  // namespace

XpbdOptions garment_xpbd_options(const GarmentSimOptions& opt) {
  XpbdOptions xo;
  xo.substeps = opt.substeps;
  xo.threads = opt.threads;
  // The coarse correction's lattice knows no ties: it would move the pieces apart at the seams.
  xo.coarse_factor = 0;
  // Double-precision kernels: in single precision the remeshed pieces' irregular triangles
  // (some a few mm across, next to 12 mm ones) never come to rest (the tight skirt's fastest
  // vertex still at 5 cm/s after 1800 frames, its hip 1 % wide); in double they rest in 501.
  xo.single_precision = false;
  // The static finish of a sleeping piece knows no ties either (it would open the seams).
  xo.finish = false;
  return xo;
}

double triangle_strain(const Cloth& cloth, int t) {
  const auto& tri = cloth.topo.triangles[t];
  const auto& m = cloth.topo.material;
  const auto& x = cloth.state.x;
  return triangle_strain_of(x[tri[0]], x[tri[1]], x[tri[2]], m[tri[0]], m[tri[1]], m[tri[2]],
                            0.5e-14)
      .strain;
}

Cloth garment_cloth(const Garment& g, const FabricParams& fabric) {
  Cloth c;
  c.fabric = fabric;
  const int n = static_cast<int>(g.x.size());
  c.topo.triangles = g.triangles;
  c.topo.material = g.material;
  c.topo.vertex_zone.assign(n, 0);
  c.topo.triangle_zone.assign(g.triangles.size(), 0);
  c.topo.vertex_origin.resize(n);
  std::iota(c.topo.vertex_origin.begin(), c.topo.vertex_origin.end(), 0);
  // The nominal spacing: the mean material edge.
  double sum = 0;
  for (const auto& t : g.triangles)
    for (int k = 0; k < 3; ++k) sum += (g.material[t[(k + 1) % 3]] - g.material[t[k]]).norm();
  if (!g.triangles.empty()) c.topo.spacing = sum / (3.0 * g.triangles.size());
  c.state.x = g.x;
  c.state.x_prev = g.x;
  c.state.v.assign(n, Vec3::Zero());
  c.state.flags.assign(n, 0);
  c.relump_masses();
  return c;
}

Result<GarmentSimResult> simulate_garment(const Garment& garment,
                                          std::shared_ptr<const DressForm> form,
                                          const MappingSurface& surf, const FabricParams& fabric,
                                          const GarmentSimOptions& opt) {
  if (!form) return Error{"simulate_garment: no form"};
  if (garment.material.size() != garment.x.size() || garment.triangles.empty())
    return Error{"simulate_garment: the garment has no flat pattern (material coordinates)"};
  GarmentSimResult r;
  r.cloth = garment_cloth(garment, fabric);
  if (std::string e = r.cloth.validate(); !e.empty()) return Error{"simulate_garment: " + e};
  // The geometric garment lies on the form; the contacts keep the cloth contact_offset off it.
  // Left on the form, the first substep's contacts would move every vertex the offset out in
  // 1/(90 substeps) s, a speed the later substeps carry on (the bodice flew 35 mm off the form in
  // its first frame): the cloth starts the offset off the form instead.
  for (Vec3& p : r.cloth.state.x) form->push_outside(p, opt.contact_offset);
  r.cloth.state.x_prev = r.cloth.state.x;
  for (const SeamTie& t : garment.ties) r.ties.push_back({t.a, t.b0, t.b1, t.t});
  r.seam_gap_start_mm = xpbd::max_tie_gap(r.ties, r.cloth.state.x) * 1000;
  SceneObjects scene;
  scene.form = form;
  scene.friction = opt.friction;
  scene.offset = opt.contact_offset;
  XpbdSolver solver(garment_xpbd_options(opt));
  solver.set_ties(r.ties, opt.tie_passes);
  if (!run_to_rest(solver, r, scene, opt))
    return Error{"simulate_garment: the solver diverged at frame " + std::to_string(r.frames)};
  r.seam_gap_max_mm = xpbd::max_tie_gap(r.ties, r.cloth.state.x) * 1000;
  measure_fit(r, *form);
  const FormLandmarks& lm = form->landmarks();
  // The waist band a band's height below the simulated waist seam (its mean height), both
  // garments sliced there: the seam settles a few mm to cm below the form's waist line (a flared
  // skirt further: only the cone between waist and hip holds it), so a slice at the line itself
  // may miss the cloth. The hip band at the form's hip line.
  const auto seam_y = [&](const std::vector<Vec3>& x) {
    double y = 0;
    for (int v : garment.waist_vertices) y += x[v].y();
    return garment.waist_vertices.empty() ? lm.waist_y : y / garment.waist_vertices.size();
  };
  r.waist_seam_drop_mm = (seam_y(garment.x) - seam_y(r.cloth.state.x)) * 1000;
  const double waist_band_y =
      seam_y(r.cloth.state.x) + (opt.waist_band_above ? opt.band : -opt.band);
  r.waist = fit_band(r, garment, surf, waist_band_y, opt.contact_offset, opt.band);
  r.hip = fit_band(r, garment, surf, lm.hip_y, opt.contact_offset, opt.band);
  r.bust = fit_band(r, garment, surf, lm.bust_y, opt.contact_offset, opt.band);
  return r;
}

std::string GarmentSimResult::to_json() const {
  using json = nlohmann::json;
  const auto band = [](const FitBand& b) {
    if (!b.vertices) return json(nullptr);  // no cloth at that height
    return json{{"y_m", b.y},
                {"ease_max_mm", b.ease_max_mm},
                {"ease_mean_mm", b.ease_mean_mm},
                {"girth_mm", b.girth_mm},
                {"girth_geometric_mm", b.girth_geometric_mm},
                {"girth_expected_mm", b.girth_expected_mm},
                {"girth_error_pct", b.girth_error_pct},
                {"vertices", b.vertices}};
  };
  json j;
  j["solver"] = "xpbd";
  j["vertices"] = cloth.num_vertices();
  j["triangles"] = cloth.topo.num_triangles();
  j["ties"] = ties.size();
  j["frames"] = frames;
  j["at_rest"] = at_rest;
  j["wall_ms"] = wall_ms;
  j["ms_per_frame"] = ms_per_frame;
  j["max_speed_end_m_per_s"] = max_speed_end;
  j["seam_gap_start_mm"] = seam_gap_start_mm;
  j["seam_gap_max_mm"] = seam_gap_max_mm;
  j["penetration_max_mm"] = penetration_max_mm;
  j["strain_max_pct"] = strain_max_pct;
  j["strain_rms_pct"] = strain_rms_pct;
  j["strain_median_pct"] = strain_median_pct;
  j["strain_p95_pct"] = strain_p95_pct;
  j["waist_seam_drop_mm"] = waist_seam_drop_mm;
  j["waist"] = band(waist);
  j["hip"] = band(hip);
  j["bust"] = band(bust);
  return j.dump(2);
}

}  // namespace drape::sim
