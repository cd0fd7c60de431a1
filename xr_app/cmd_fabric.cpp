// `drape fabric test|calibrate`: the virtual drape tester on a preset or a fabrics file, and the
// calibration of a preset's bending to a measured drape coefficient (docs/fabrics.md).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <string>

#include "sim/fabric_test/calibrate.hpp"
#include "sim/fabric_test/drape_photo.hpp"
#include "xr_app/command.hpp"
#include "xr_app/paths.hpp"

namespace {

using drape::sim::DrapeTestOptions;
using drape::sim::FabricParams;
namespace fs = std::filesystem;

// A fabric by preset name (assets/fabrics.json) or from a fabrics JSON file: its only preset,
// or the one named after a colon (file.json:name).
drape::sim::Result<FabricParams> find_fabric(const std::string& spec) {
  const size_t colon = spec.rfind(':');
  const std::string file = colon == std::string::npos ? spec : spec.substr(0, colon);
  if (fs::is_regular_file(file)) {
    auto all = drape::sim::load_fabric_presets(file);
    if (!all) return drape::sim::Error{all.error()};
    if (colon != std::string::npos) return drape::sim::load_fabric(file, spec.substr(colon + 1));
    if (all->size() == 1) return all->begin()->second;
    return drape::sim::make_error(file, "holds several presets: name one as " + file + ":NAME");
  }
  if (spec.find('/') != std::string::npos || spec.ends_with(".json"))
    return drape::sim::make_error(spec, "no such file");
  return drape::sim::load_fabric(drape::app::asset("fabrics.json").string(), spec);
}

void add_tester_options(CLI::App& c, DrapeTestOptions& o) {
  c.add_option("--specimen", o.specimen_diameter, "specimen diameter (m)")
      ->check(drape::app::positive_up_to(2.0))
      ->capture_default_str();
  c.add_option("--disc", o.disc_diameter, "support disc diameter (m), below the specimen's")
      ->check(drape::app::positive_up_to(2.0))
      ->capture_default_str();
  c.add_option("--resolution", o.resolution, "rings of vertices from the centre to the rim")
      ->check(CLI::Range(4, 200))
      ->capture_default_str();
  c.add_option("--rim-spacing", o.rim_spacing,
               "radial ring spacing at the disc's rim, a fraction of the nominal edge")
      ->check(CLI::Range(0.1, 1.0))
      ->capture_default_str();
  c.add_option("--seed", o.seed, "first seed of the start's perturbation")->capture_default_str();
}

void print_run(uint64_t seed, const drape::sim::DrapeTestResult& r) {
  const auto& m = r.measures;
  std::printf(
      "seed %-4llu DC %.4f  nodes %2d  R_min %6.1f mm  R_max %6.1f mm  (%.1f s simulated, "
      "%d finish cycles, last move %.2g mm, %.1f s)\n",
      static_cast<unsigned long long>(seed), m.dc, m.nodes, m.r_min * 1e3, m.r_max * 1e3,
      r.sim_time, r.finish_cycles, r.finish_last_move * 1e3, r.seconds);
}

// Writes each drape's shadow PNG, its glTF and its R(theta) CSV under `dir`.
int write_runs(const drape::sim::DrapeSeries& s, const DrapeTestOptions& o, const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "drape fabric test: %s: %s\n", dir.string().c_str(), ec.message().c_str());
    return 1;
  }
  drape::sim::DrapeMeasureOptions mo;
  mo.specimen_diameter = o.specimen_diameter;
  mo.disc_diameter = o.disc_diameter;
  for (size_t k = 0; k < s.runs.size(); ++k) {
    const std::string stem = (dir / ("seed" + std::to_string(o.seed + k))).string();
    std::string e = drape::sim::write_shadow_png(s.runs[k].shadow, mo, stem + "_shadow.png");
    if (e.empty()) e = drape::sim::write_drape_mesh(s.runs[k], o, stem + "_drape.gltf");
    if (!e.empty()) {
      std::fprintf(stderr, "drape fabric test: %s\n", e.c_str());
      return 1;
    }
    if (FILE* f = std::fopen((stem + "_profile.csv").c_str(), "w")) {
      std::fprintf(f, "theta_deg,r_mm\n");
      for (int b = 0; b < drape::sim::kProfileBins; ++b)
        std::fprintf(f, "%d,%.2f\n", b, s.runs[k].measures.profile[b] * 1e3);
      std::fclose(f);
    }
  }
  std::printf("wrote %s/seed*_shadow.png, _drape.gltf, _profile.csv\n", dir.string().c_str());
  return 0;
}

void print_series(const drape::sim::DrapeSeries& s) {
  std::printf(
      "mean over %zu drapes: DC %.4f (sd %.4f)  nodes %.2f (sd %.2f; median %g, %d-%d)  "
      "R_min %.1f mm  R_max %.1f mm\n",
      s.runs.size(), s.dc_mean, s.dc_sd, s.nodes_mean, s.nodes_sd, s.nodes_median, s.nodes_min,
      s.nodes_max, s.rmin_mean * 1e3, s.rmax_mean * 1e3);
  std::printf(
      "face up / face down: not simulated apart. The cloth model has no term that tells "
      "the faces apart (no rest curvature, no curl), so a specimen turned over drapes as "
      "the mirror image of the same problem and its figures are those above.\n");
}

int run_test(const std::string& spec, DrapeTestOptions o, int seeds, int threads,
             const std::string& out) {
  auto fabric = find_fabric(spec);
  if (!fabric) {
    std::fprintf(stderr, "drape fabric test: %s\n", fabric.error().c_str());
    return 1;
  }
  auto s = drape::sim::run_drape_series(*fabric, o, seeds, threads);
  if (!s) {
    std::fprintf(stderr, "drape fabric test: %s\n", s.error().c_str());
    return 1;
  }
  std::printf(
      "fabric %s: %.0f g/m^2, bending warp %.3g weft %.3g N m; specimen %.3f m on a "
      "%.3f m disc, %d rings\n",
      fabric->name.c_str(), fabric->areal_density * 1e3, fabric->bending_warp, fabric->bending_weft,
      o.specimen_diameter, o.disc_diameter, o.resolution);
  for (size_t k = 0; k < s->runs.size(); ++k) print_run(o.seed + k, s->runs[k]);
  print_series(*s);
  return write_runs(*s, o, out);
}

struct CalibrateArgs {
  double density = 0, dc = 0;
  int nodes = -1;
  double rmin_mm = 0, rmax_mm = 0;  // measured mean R_min / R_max: the ratio fitted to their gap
  std::string name = "calibrated", out, photo;
};

// --photo: the measured figures from a top-view photo of a drape test. Returns false on error.
bool figures_from_photo(CalibrateArgs& a, const DrapeTestOptions& t) {
  drape::sim::DrapeMeasureOptions mo;
  mo.specimen_diameter = t.specimen_diameter;
  mo.disc_diameter = t.disc_diameter;
  auto ph = drape::sim::shadow_from_photo(a.photo, mo);
  if (!ph) {
    std::fprintf(stderr, "drape fabric calibrate: %s\n", ph.error().c_str());
    return false;
  }
  for (const auto& w : ph->warnings)
    std::fprintf(stderr, "drape fabric calibrate: warning: %s: %s\n", a.photo.c_str(), w.c_str());
  const auto& m = ph->measures;
  std::printf("photo %s: %.3f mm per pixel, DC %.4f, nodes %d, R_min %.1f mm, R_max %.1f mm\n",
              a.photo.c_str(), ph->metres_per_pixel * 1e3, m.dc, m.nodes, m.r_min * 1e3,
              m.r_max * 1e3);
  a.dc = m.dc;
  if (a.nodes < 0) a.nodes = m.nodes;
  if (!(a.dc > 0 && a.dc < 1)) {
    std::fprintf(stderr, "drape fabric calibrate: %s: DC %.4f cannot be fitted (needs (0, 1))\n",
                 a.photo.c_str(), a.dc);
    return false;
  }
  return true;
}

int run_calibrate(CalibrateArgs a, drape::sim::CalibrationOptions opt) {
  if ((a.dc > 0) == !a.photo.empty()) {
    std::fprintf(stderr,
                 "drape fabric calibrate: give the measured DC (--dc) or a photo "
                 "(--photo), one of them\n");
    return 2;
  }
  if ((a.rmin_mm > 0) != (a.rmax_mm > 0) || a.rmax_mm < a.rmin_mm) {
    std::fprintf(stderr,
                 "drape fabric calibrate: --rmin and --rmax go together, R_min below R_max "
                 "(got %g and %g mm)\n",
                 a.rmin_mm, a.rmax_mm);
    return 2;
  }
  opt.fold_depth = (a.rmax_mm - a.rmin_mm) * 1e-3;
  if (!a.photo.empty() && !figures_from_photo(a, opt.test)) return 1;
  auto cal = drape::sim::calibrate_bending(a.density, a.dc, opt);
  if (!cal) {
    std::fprintf(stderr, "drape fabric calibrate: %s\n", cal.error().c_str());
    return 1;
  }
  for (const auto& st : cal->steps)
    std::printf("  bending %.4g N m, warp/weft %.2f -> DC %.4f, fold depth %.1f mm\n", st.bending,
                st.ratio, st.dc, st.depth * 1e3);
  const auto& s = cal->series;
  std::printf(
      "fitted in %.1f s (%zu evaluations of %d drapes): bending warp %.4g weft %.4g N m "
      "(ratio %.2f), DC %.4f (target %.4f, residual %+.4f)\n",
      cal->seconds, cal->steps.size(), opt.seeds, cal->fabric.bending_warp,
      cal->fabric.bending_weft, cal->ratio, s.dc_mean, a.dc, cal->residual);
  if (opt.fold_depth > 0)
    std::printf("fold depth R_max - R_min %.1f mm (measured %.1f, residual %+.1f mm)\n",
                (s.rmax_mean - s.rmin_mean) * 1e3, opt.fold_depth * 1e3, cal->depth_residual * 1e3);
  std::printf("predicted: nodes %.2f%s, R_min %.1f mm, R_max %.1f mm\n", s.nodes_mean,
              a.nodes > 0 ? (" (measured " + std::to_string(a.nodes) + ")").c_str() : "",
              s.rmin_mean * 1e3, s.rmax_mean * 1e3);
  if (a.out.empty()) return 0;
  char src[256];
  int at = std::snprintf(
      src, sizeof src, "drape fabric calibrate: measured DC %.3f, tester DC %.4f", a.dc, s.dc_mean);
  if (opt.fold_depth > 0)
    std::snprintf(src + at, sizeof src - at, "; fold depth measured %.1f mm, tester %.1f mm",
                  opt.fold_depth * 1e3, (s.rmax_mean - s.rmin_mean) * 1e3);
  if (std::string e = drape::sim::save_fabric_preset(a.out, a.name, cal->fabric, src); !e.empty()) {
    std::fprintf(stderr, "drape fabric calibrate: %s\n", e.c_str());
    return 1;
  }
  std::printf("wrote preset '%s' to %s\n", a.name.c_str(), a.out.c_str());
  return 0;
}

int run(int argc, char** argv) {
  CLI::App cli{"The virtual drape tester (Cusick) and the calibration of fabric presets.",
               "drape fabric"};
  cli.require_subcommand(1, 1);
  DrapeTestOptions topt;
  std::string spec, out = "out/fabric_test";
  int seeds = 1, threads = 2;
  auto* test = cli.add_subcommand("test", "drape a specimen and report DC, nodes and R(theta)");
  test->add_option("--fabric", spec, "preset name (assets/fabrics.json) or FILE.json[:NAME]")
      ->required();
  add_tester_options(*test, topt);
  test->add_option("--seeds", seeds, "drapes (seeds seed, seed+1, ...)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  test->add_option("--threads", threads, "drapes at once")->check(CLI::Range(1, 64));
  test->add_option("--out", out, "folder for the shadow PNGs, glTFs and R(theta) CSVs")
      ->capture_default_str();
  drape::sim::CalibrationOptions copt;
  CalibrateArgs ca;
  auto* cal = cli.add_subcommand("calibrate", "fit a preset's bending to a measured drape (DC)");
  cal->add_option("--density", ca.density, "areal density (g/m^2)")
      ->required()
      ->check(drape::app::positive_up_to(5000));
  cal->add_option("--dc", ca.dc, "measured drape coefficient")
      ->check(drape::app::positive_up_to(0.999));
  cal->add_option("--photo", ca.photo,
                  "top-view photo of a drape test (dark drape on a light ground, the specimen's "
                  "circle printed around it): DC and nodes from it")
      ->type_name("FILE.png|.jpg");
  cal->add_option("--nodes", ca.nodes, "measured node count (reported beside the prediction)")
      ->check(CLI::Range(1, 60));
  cal->add_option("--rmin", ca.rmin_mm,
                  "measured mean R_min (mm), with --rmax: the warp/weft "
                  "ratio fitted to the fold depth R_max - R_min")
      ->check(drape::app::positive_up_to(1000));
  cal->add_option("--rmax", ca.rmax_mm, "measured mean R_max (mm)")
      ->check(drape::app::positive_up_to(1000));
  cal->add_option("--name", ca.name, "preset name")->capture_default_str();
  cal->add_option("--out", ca.out, "fabrics JSON to add the preset to (created if missing)");
  cal->add_option("--seeds", copt.seeds, "drapes per evaluation")->check(CLI::Range(1, 64));
  cal->add_option("--ratio", copt.warp_weft_ratio,
                  "bending warp / weft (the first tried with --rmin/--rmax)")
      ->check(drape::app::positive_up_to(100))
      ->capture_default_str();
  add_tester_options(*cal, copt.test);
  if (int rc = drape::app::parse_command_line(cli, argc, argv); rc >= 0) return rc;
  if (*test) return run_test(spec, topt, seeds, threads, out);
  return run_calibrate(ca, copt);
}

}  // namespace

DRAPE_COMMAND(fabric, "virtual drape test and calibration of fabric presets", run);
