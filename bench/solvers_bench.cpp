// The solver study (issue 3, item 5): solver x substeps (dt) x iterations x resolution on the
// shared scenes; time per 1/90 s frame and error against the converged reference (Newton
// static minimum of the same scene). Writes out/bench/solvers.csv and a Pareto chart
// out/bench/solvers.svg (error vs time, log axes, one curve per solver), prints a summary.
// Usage: solvers_bench [--quick] [--max-res N]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "sim/scenes.hpp"
#include "sim/solver_factory.hpp"
#include "sim/solver_newton.hpp"
#include "sim/watchdog.hpp"

using namespace drape::sim;

namespace {

struct Row {
  std::string scene, solver;
  int resolution;
  double dt;
  int iterations;
  double ms_per_frame, rms_mm, max_mm;
  bool stable;
};

struct Config {
  std::string solver;
  int substeps, iterations;
};

Row run(const std::string& scene, int res, const Config& c, const std::vector<Vec3>& ref) {
  StudyScene sc = make_scene(scene, res);
  SolverConfig cfg;
  cfg.substeps = c.substeps;
  cfg.iterations = c.iterations;
  cfg.springs_model = sc.springs_model;
  auto s = make_solver(c.solver, cfg);
  const double frame = 1.0 / 90;
  const int frames = static_cast<int>(std::lround(sc.duration / frame));
  bool stable = true;
  const auto t0 = std::chrono::steady_clock::now();
  int used_substeps = c.substeps;
  for (int f = 0; f < frames; ++f) {
    StepStats st = (*s)->step(sc.cloth, sc.objects, frame);
    if (st.diverged) stable = false;
    if (f == 0) used_substeps = std::max(1, st.substeps);
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!cloth_finite(sc.cloth)) stable = false;
  double rms = 0, mx = 0;
  position_error(sc.cloth.state.x, ref, rms, mx);
  return {scene,     c.solver, res,   frame / used_substeps, c.iterations, ms / frames,
          rms * 1e3, mx * 1e3, stable};
}

std::vector<Vec3> reference(const std::string& scene, int res) {
  StudyScene sc = make_scene(scene, res);
  StaticOptions so;
  so.tolerance = 1e-8;
  so.max_iterations = 200;
  if (sc.springs_model) so.energy.model = EnergyOptions::Model::kSprings;
  StaticResult r = relax_static(sc.cloth, sc.objects, so);
  std::printf("reference %s %d: %d Newton iterations, residual %.1e, %.0f ms\n", scene.c_str(), res,
              r.iterations, r.residual, r.ms);
  return sc.cloth.state.x;
}

void write_svg(const std::vector<Row>& rows, const std::string& scene, int res,
               const std::string& path) {
  const double W = 720, H = 480, L = 70, R = 150, T = 30, B = 50;
  double tmin = 1e9, tmax = 0, emin = 1e9, emax = 0;
  std::map<std::string, std::vector<const Row*>> by;
  for (const auto& r : rows) {
    if (r.scene != scene || r.resolution != res || !r.stable) continue;
    by[r.solver].push_back(&r);
    tmin = std::min(tmin, r.ms_per_frame);
    tmax = std::max(tmax, r.ms_per_frame);
    emin = std::min(emin, std::max(r.rms_mm, 1e-3));
    emax = std::max(emax, std::max(r.rms_mm, 1e-3));
  }
  if (by.empty()) return;
  const double lt0 = std::floor(std::log10(tmin)), lt1 = std::ceil(std::log10(tmax) + 1e-9);
  const double le0 = std::floor(std::log10(emin)), le1 = std::ceil(std::log10(emax) + 1e-9);
  auto X = [&](double t) { return L + (std::log10(t) - lt0) / (lt1 - lt0) * (W - L - R); };
  auto Y = [&](double e) {
    return H - B - (std::log10(std::max(e, 1e-3)) - le0) / (le1 - le0) * (H - T - B);
  };
  std::ofstream o(path);
  o << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H
    << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' "
       "fill='white'/>\n";
  o << "<text x='" << L << "' y='18'>" << scene << " " << res << "x" << res
    << ": RMS error vs compute per 1/90 s frame (log-log)</text>\n";
  for (double d = lt0; d <= lt1; d += 1)
    o << "<line x1='" << X(std::pow(10, d)) << "' y1='" << T << "' x2='" << X(std::pow(10, d))
      << "' y2='" << H - B << "' stroke='#ddd'/><text x='" << X(std::pow(10, d)) - 10 << "' y='"
      << H - B + 16 << "'>" << std::pow(10, d) << "</text>\n";
  for (double d = le0; d <= le1; d += 1)
    o << "<line x1='" << L << "' y1='" << Y(std::pow(10, d)) << "' x2='" << W - R << "' y2='"
      << Y(std::pow(10, d)) << "' stroke='#ddd'/><text x='10' y='" << Y(std::pow(10, d)) + 4 << "'>"
      << std::pow(10, d) << "</text>\n";
  o << "<text x='" << (W - R) / 2 << "' y='" << H - 10 << "'>ms per frame</text>\n";
  o << "<text x='10' y='" << T - 5 << "'>RMS mm</text>\n";
  const char* colours[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"};
  int ci = 0;
  for (auto& [name, v] : by) {
    std::sort(v.begin(), v.end(),
              [](const Row* a, const Row* b) { return a->ms_per_frame < b->ms_per_frame; });
    const char* col = colours[ci % 6];
    o << "<polyline fill='none' stroke='" << col << "' stroke-width='2' points='";
    for (const Row* r : v) o << X(r->ms_per_frame) << "," << Y(r->rms_mm) << " ";
    o << "'/>\n";
    for (const Row* r : v)
      o << "<circle cx='" << X(r->ms_per_frame) << "' cy='" << Y(r->rms_mm) << "' r='3' fill='"
        << col << "'/>\n";
    o << "<text x='" << W - R + 10 << "' y='" << T + 20 + 18 * ci << "' fill='" << col << "'>"
      << name << "</text>\n";
    ++ci;
  }
  o << "</svg>\n";
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int max_res = 64;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    if (!std::strcmp(argv[i], "--max-res") && i + 1 < argc) max_res = std::atoi(argv[++i]);
  }
  std::filesystem::create_directories("out/bench");
  std::vector<Row> rows;
  struct Job {
    std::string scene;
    int res;
    std::vector<Config> configs;
  };
  std::vector<Config> full{{"vbd", 1, 5},   {"vbd", 1, 10},  {"vbd", 2, 5},     {"vbd", 2, 10},
                           {"vbd", 4, 10},  {"vbd", 4, 20},  {"xpbd", 5, 1},    {"xpbd", 10, 1},
                           {"xpbd", 20, 1}, {"xpbd", 40, 1}, {"newton", 1, 20}, {"newton", 2, 20},
                           {"verlet", 0, 1}};
  // Quick mode (the default of ./drape bench solvers): a few minutes on the loaded 2-core
  // machine. VBD's iteration count is a maximum: it stops early on the 1 um residual.
  std::vector<Config> quick_cfg{{"vbd", 1, 10},    {"vbd", 2, 20},  {"vbd", 4, 50},
                                {"vbd", 8, 100},   {"xpbd", 10, 1}, {"xpbd", 40, 1},
                                {"newton", 1, 20}, {"verlet", 0, 1}};
  std::vector<Job> jobs;
  if (quick) {
    // The form scene's static reference and the slow VBD settings dominate: 16^2 and the
    // cheaper configurations only.
    jobs = {{"chain", 20, quick_cfg},
            {"sheet", 16, quick_cfg},
            {"form",
             16,
             {{"vbd", 1, 10}, {"vbd", 2, 20}, {"xpbd", 10, 1}, {"xpbd", 40, 1}, {"verlet", 0, 1}}}};
  } else {
    jobs = {{"chain", 20, full}, {"sheet", 16, full}, {"form", 32, full}};
    jobs.push_back({"sheet", 32, full});
    jobs.push_back({"sphere", 32, full});
    jobs.push_back({"form", 64, full});
    if (max_res >= 128)
      jobs.push_back({"form",
                      128,
                      {{"vbd", 1, 5},
                       {"vbd", 1, 10},
                       {"vbd", 2, 5},
                       {"vbd", 2, 10},
                       {"vbd", 4, 10},
                       {"xpbd", 10, 1},
                       {"xpbd", 20, 1},
                       {"verlet", 0, 1}}});
    if (max_res >= 256) jobs.push_back({"form", 256, {{"vbd", 1, 5}, {"vbd", 2, 10}}});
  }
  std::ofstream csv("out/bench/solvers.csv");
  csv << "scene,solver,resolution,dt,iterations,ms_per_frame,rms_error_mm,max_error_mm,stable\n";
  for (const auto& j : jobs) {
    const std::vector<Vec3> ref = reference(j.scene, j.res);
    for (const auto& c : j.configs) {
      Row r = run(j.scene, j.res, c, ref);
      std::printf("%-8s %4d %-7s dt %.5f it %2d: %8.3f ms/frame  rms %8.3f mm  max %8.3f mm %s\n",
                  r.scene.c_str(), r.resolution, r.solver.c_str(), r.dt, r.iterations,
                  r.ms_per_frame, r.rms_mm, r.max_mm, r.stable ? "" : "UNSTABLE");
      std::fflush(stdout);
      rows.push_back(r);
      // Written row by row so a partial run still leaves a valid CSV.
      csv << r.scene << "," << r.solver << "," << r.resolution << "," << r.dt << "," << r.iterations
          << "," << r.ms_per_frame << "," << r.rms_mm << "," << r.max_mm << ","
          << (r.stable ? 1 : 0) << std::endl;
    }
  }
  int top = 0;
  for (const auto& j : jobs)
    if (j.scene == "form") top = std::max(top, j.res);
  write_svg(rows, "form", top, "out/bench/solvers.svg");
  write_svg(rows, "sheet", quick ? 16 : 32, "out/bench/solvers_sheet.svg");
  // Summary: fastest stable configuration at <= 1 mm RMS per solver, with ratios to VBD.
  std::printf("\nSummary: fastest configuration at <= 1 mm RMS (ms per 1/90 s frame)\n");
  for (const auto& j : jobs) {
    std::map<std::string, const Row*> best;
    for (const auto& r : rows)
      if (r.scene == j.scene && r.resolution == j.res && r.stable && r.rms_mm <= 1.0 &&
          (!best[r.solver] || r.ms_per_frame < best[r.solver]->ms_per_frame))
        best[r.solver] = &r;
    std::printf("%-7s %4d:", j.scene.c_str(), j.res);
    const Row* v = best["vbd"];
    for (const auto& [name, r] : best) {
      if (!r) {
        std::printf("  %s -", name.c_str());
        continue;
      }
      std::printf("  %s %.2f ms", name.c_str(), r->ms_per_frame);
      if (v && name != "vbd") std::printf(" (%.1fx vbd)", r->ms_per_frame / v->ms_per_frame);
    }
    std::printf("\n");
  }
  std::printf("wrote out/bench/solvers.csv, out/bench/solvers.svg\n");
  return 0;
}
