// Real fabrics against the virtual drape tester (docs/fabrics.md): for each of the five fabrics
// of the measured calibration set (shared data real-drape.md: Cusick tests of a 0.30 m specimen
// on a 0.18 m disc) two calibrations, each preset then draped on fresh seeds beside the measured
// figures:
//   dc        the bending fitted to the measured DC alone (warp/weft 1.6): the node count and
//             R_min / R_max are predictions
//   dc+depth  the warp/weft ratio fitted to the measured fold depth R_max - R_min too, B to DC
//             at each ratio: the node count is a prediction (the presets of assets/fabrics.json)
// Writes out/bench/fabrics.csv and .json (a row per fabric and fit), the dc+depth presets
// (out/bench/fabrics_presets.json) and a DC-against-resolution table
// (out/bench/fabrics_convergence.csv). Usage: fabrics_bench [--resolution N] [--seeds K]
// [--convergence 10,15,20,30] [--only NAME].
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/fabric_test/calibrate.hpp"

namespace {

using drape::sim::CalibrationOptions;
using drape::sim::CalibrationResult;

// The measured figures (real-drape.md: means over 20-24 drapes per fabric, nodes the median).
struct Measured {
  const char* name;
  double gsm, dc, dc_sd;
  int nodes;
  double rmin_mm, rmax_mm;
};
constexpr Measured kFabrics[] = {
    {"cotton_white", 59, 0.466, 0.024, 9, 99.0, 140.6},
    {"cotton_blue", 192, 0.696, 0.052, 8, 119.0, 148.5},
    {"viscose_white", 213, 0.150, 0.011, 12, 90.8, 120.8},
    {"cotton_pink", 114, 0.621, 0.037, 8, 112.7, 146.2},
    {"wool_red", 274, 0.769, 0.019, 8, 128.0, 147.4},
};

struct Row {
  const Measured* m;
  const char* fit;  // "dc" or "dc+depth"
  CalibrationResult cal;
  drape::sim::DrapeSeries check;  // the fitted preset on fresh seeds
};

void print_table(const std::vector<Row>& rows) {
  // Nodes: the measured median beside the simulated drapes' median (and mean).
  std::printf(
      "\n%-14s %-8s %5s | %6s %6s %5s | %5s %5s %5s | %6s %6s | %6s %6s | %9s %9s %5s | %5s\n",
      "fabric", "fit", "g/m2", "DC", "sim", "sd", "nodes", "sim", "mean", "Rmin", "sim", "Rmax",
      "sim", "B_warp", "B_weft", "ratio", "s");
  for (const Row& r : rows) {
    const auto& s = r.check;
    std::printf(
        "%-14s %-8s %5.0f | %6.3f %6.3f %5.3f | %5d %5.1f %5.2f | %6.1f %6.1f | %6.1f %6.1f | "
        "%9.3g %9.3g %5.2f | %5.1f\n",
        r.m->name, r.fit, r.m->gsm, r.m->dc, s.dc_mean, s.dc_sd, r.m->nodes, s.nodes_median,
        s.nodes_mean, r.m->rmin_mm, s.rmin_mean * 1e3, r.m->rmax_mm, s.rmax_mean * 1e3,
        r.cal.fabric.bending_warp, r.cal.fabric.bending_weft, r.cal.ratio, r.cal.seconds);
  }
}

void write_outputs(const std::vector<Row>& rows) {
  std::ofstream csv("out/bench/fabrics.csv");
  csv << "fabric,density_gsm,dc_measured,dc_sim,dc_sim_sd,nodes_measured,nodes_sim,"
         "rmin_measured_mm,rmin_sim_mm,rmax_measured_mm,rmax_sim_mm,bending_warp,bending_weft,"
         "seconds,fit,warp_weft_ratio,nodes_sim_mean,nodes_sim_min,nodes_sim_max\n";
  nlohmann::ordered_json js = nlohmann::ordered_json::array();
  for (const Row& r : rows) {
    const auto& s = r.check;
    char line[512];
    std::snprintf(
        line, sizeof line,
        "%s,%.0f,%.3f,%.4f,%.4f,%d,%.1f,%.1f,%.2f,%.1f,%.2f,%.4g,%.4g,%.1f,%s,%.3f,%.2f,%d,"
        "%d\n",
        r.m->name, r.m->gsm, r.m->dc, s.dc_mean, s.dc_sd, r.m->nodes, s.nodes_median, r.m->rmin_mm,
        s.rmin_mean * 1e3, r.m->rmax_mm, s.rmax_mean * 1e3, r.cal.fabric.bending_warp,
        r.cal.fabric.bending_weft, r.cal.seconds, r.fit, r.cal.ratio, s.nodes_mean, s.nodes_min,
        s.nodes_max);
    csv << line;
    js.push_back({{"fabric", r.m->name},
                  {"density_gsm", r.m->gsm},
                  {"dc_measured", r.m->dc},
                  {"dc_sim", s.dc_mean},
                  {"dc_sim_sd", s.dc_sd},
                  {"nodes_measured", r.m->nodes},
                  {"nodes_sim", s.nodes_median},
                  {"nodes_sim_mean", s.nodes_mean},
                  {"nodes_sim_min", s.nodes_min},
                  {"nodes_sim_max", s.nodes_max},
                  {"rmin_measured_mm", r.m->rmin_mm},
                  {"rmin_sim_mm", s.rmin_mean * 1e3},
                  {"rmax_measured_mm", r.m->rmax_mm},
                  {"rmax_sim_mm", s.rmax_mean * 1e3},
                  {"bending_warp", r.cal.fabric.bending_warp},
                  {"bending_weft", r.cal.fabric.bending_weft},
                  {"seconds", r.cal.seconds},
                  {"fit", r.fit},
                  {"warp_weft_ratio", r.cal.ratio},
                  {"ratio_fits", r.cal.ratio_fits},
                  {"calibration_dc", r.cal.series.dc_mean},
                  {"evaluations", r.cal.steps.size()}});
  }
  std::ofstream("out/bench/fabrics.json") << js.dump(2) << "\n";
  std::printf("wrote out/bench/fabrics.csv, out/bench/fabrics.json\n");
}

// DC (mean of `seeds` drapes) of one fitted preset at each resolution, with the time per drape.
void convergence(const Row& row, const std::vector<int>& resolutions, int seeds,
                 const drape::sim::DrapeTestOptions& base) {
  std::ofstream csv("out/bench/fabrics_convergence.csv");
  csv << "fabric,resolution,rim_spacing,edge_mm,vertices,dc_sim,dc_sim_sd,nodes_sim,"
         "seconds_per_drape\n";
  std::printf("\nDC against resolution (%s, its fitted bending, %d seeds):\n", row.m->name, seeds);
  std::printf("%5s %5s %8s %8s %7s %6s %6s %9s\n", "rings", "rim", "edge mm", "vertices", "DC",
              "sd", "nodes", "s/drape");
  for (double rim : {1.0, base.rim_spacing})
    for (int n : resolutions) {
      drape::sim::DrapeTestOptions o = base;
      o.resolution = n;
      o.rim_spacing = rim;
      o.seed = 1000;
      auto s = drape::sim::run_drape_series(row.cal.fabric, o, seeds, 1);
      if (!s) {
        std::printf("%5d  failed: %s\n", n, s.error().c_str());
        continue;
      }
      const double edge = 0.5 * o.specimen_diameter / n * 1e3;
      const int nv = s->runs[0].cloth.num_vertices();
      const double per = s->seconds / seeds;
      std::printf("%5d %5.2f %8.2f %8d %7.4f %6.4f %6.2f %9.2f\n", n, rim, edge, nv, s->dc_mean,
                  s->dc_sd, s->nodes_mean, per);
      char line[256];
      std::snprintf(line, sizeof line, "%s,%d,%.2f,%.2f,%d,%.4f,%.4f,%.2f,%.2f\n", row.m->name, n,
                    rim, edge, nv, s->dc_mean, s->dc_sd, s->nodes_mean, per);
      csv << line;
    }
  std::printf("wrote out/bench/fabrics_convergence.csv\n");
}

// One fabric's calibration (`fit`: "dc" or "dc+depth", o.fold_depth set for the latter), its
// preset then draped on `seeds` fresh seeds; the dc+depth preset saved to
// out/bench/fabrics_presets.json.
drape::sim::Result<Row> fit_fabric(const Measured& m, const char* fit, const CalibrationOptions& o,
                                   int seeds) {
  auto cal = drape::sim::calibrate_bending(m.gsm, m.dc, o);
  if (!cal) return drape::sim::Error{cal.error()};
  std::printf("%-14s %-8s fitted in %.1f s, %zu evaluations (B, ratio, DC, depth mm):", m.name, fit,
              cal->seconds, cal->steps.size());
  for (const auto& st : cal->steps)
    std::printf(" (%.3g, %.2f, %.3f, %.1f)", st.bending, st.ratio, st.dc, st.depth * 1e3);
  std::printf("\n");
  drape::sim::DrapeTestOptions t = o.test;
  t.seed = 100;
  auto check = drape::sim::run_drape_series(cal->fabric, t, seeds, o.threads);
  if (!check) return drape::sim::Error{check.error()};
  if (o.fold_depth > 0) {
    char src[256];
    std::snprintf(src, sizeof src,
                  "measured DC %.3f, R_max - R_min %.1f mm (real-drape.md); tester DC %.3f sd "
                  "%.3f, R_max - R_min %.1f mm",
                  m.dc, m.rmax_mm - m.rmin_mm, check->dc_mean, check->dc_sd,
                  (check->rmax_mean - check->rmin_mean) * 1e3);
    const std::string e =
        drape::sim::save_fabric_preset("out/bench/fabrics_presets.json", m.name, cal->fabric, src);
    if (!e.empty()) return drape::sim::Error{e};
  }
  return Row{&m, fit, std::move(*cal), std::move(*check)};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Five real fabrics: bending fitted to the measured DC, nodes and radii predicted "
      "(out/bench/fabrics.csv)."};
  CalibrationOptions opt;
  int check_seeds = 12, conv_seeds = 2;  // a Cusick test averages 20-24 drapes
  std::vector<int> conv{10, 15, 20, 30, 40};
  std::string only, conv_fabric = "cotton_pink";
  app.add_option("--resolution", opt.test.resolution, "rings from centre to rim")
      ->check(CLI::Range(4, 200))
      ->capture_default_str();
  app.add_option("--rim-spacing", opt.test.rim_spacing,
                 "ring spacing at the disc's rim (1: uniform)")
      ->check(CLI::Range(0.1, 1.0))
      ->capture_default_str();
  app.add_option("--seeds", check_seeds, "drapes of each fitted preset (fresh seeds)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--convergence", conv, "resolutions of the convergence table (empty: none)")
      ->delimiter(',');
  app.add_option("--only", only, "one fabric");
  CLI11_PARSE(app, argc, argv);
  std::filesystem::create_directories("out/bench");
  std::vector<Row> rows;
  for (const Measured& m : kFabrics) {
    if (!only.empty() && only != m.name) continue;
    for (const char* fit : {"dc", "dc+depth"}) {
      CalibrationOptions o = opt;
      if (std::string(fit) == "dc+depth") o.fold_depth = (m.rmax_mm - m.rmin_mm) * 1e-3;
      auto row = fit_fabric(m, fit, o, check_seeds);
      if (!row) {
        std::fprintf(stderr, "%s (%s): %s\n", m.name, fit, row.error().c_str());
        return 1;
      }
      rows.push_back(std::move(*row));
    }
  }
  print_table(rows);
  write_outputs(rows);
  for (const Row& r : rows)
    if (r.m->name == conv_fabric ||
        (!only.empty() && !conv.empty() && std::string(r.fit) == "dc+depth")) {
      convergence(r, conv, conv_seeds, opt.test);
      break;
    }
  return 0;
}
