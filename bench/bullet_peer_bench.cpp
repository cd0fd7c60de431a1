// Standalone driver of the Bullet peer (bench/bullet_peer.hpp): runs Bullet's soft body on the
// hanging sheet for a few substep x iteration settings and prints ms per 1/90 s frame and the
// error against the static Newton minimum of the same scene (the solver benchmark's
// reference). The solver benchmark itself (solvers_bench) writes the solver=bullet rows; this
// driver is for the matching.
// Usage: bullet_peer_bench [--res N] [--check-rms MM] [--scale S] [--fixed K] [--bending] [--kdp D]
//                          [--runs SUBSTEPSxITER,...] [--ours SOLVER:SUBSTEPSxITER,...]
// --ours runs our solvers (sim/solvers/solver_factory.hpp) on the same scene in the same process,
// timed the same way, for a side-by-side at equal error (CPU time = process CPU, both threads).
// Exit code 1 when a run is unstable or a position is not finite (the peer's check).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "bench/bullet_peer.hpp"
#include "sim/solvers/solver_factory.hpp"
#include "sim/solvers/solver_newton.hpp"
#include "sim/testbeds/testbed.hpp"

using namespace drape;

int main(int argc, char** argv) {
  int res = 16;
  bench::PeerOptions opt;
  std::string runs = "1x1,1x4,1x16,4x4,10x1,10x4,40x1,40x4,100x2";
  std::string ours;
  double check_rms = -1;  // mm; > 0: exit 1 when a Bullet run's RMS error exceeds it
  CLI::App app{
      "Bullet's soft body (and, with --ours, our solvers) on the hanging sheet: ms per 1/90 s "
      "frame and the error against the static Newton minimum."};
  app.option_defaults()->always_capture_default();
  app.add_option("--res", res, "sheet resolution")->check(CLI::Range(2, 1024));
  app.add_option("--scale", opt.klst_scale, "multiplies the derived per-link kLST")
      ->check(CLI::Range(0.0, 1e9));
  app.add_option("--fixed", opt.klst_fixed, "> 0: every link gets this kLST")
      ->check(CLI::Range(0.0, 1.0));
  app.add_flag("--bending", opt.bending, "Bullet's bending links (distance-2 links)");
  app.add_option("--kdp", opt.kdp, "Bullet's velocity damping coefficient kDP")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--check-rms", check_rms,
                 "> 0: exit 1 when a Bullet run's RMS error (mm) exceeds it");
  app.add_option("--runs", runs, "Bullet's runs, SUBSTEPSxITERATIONS,...");
  app.add_option("--ours", ours, "our solvers on the same scene, SOLVER:SUBSTEPSxITERATIONS,...");
  CLI11_PARSE(app, argc, argv);
  sim::Testbed sc = sim::make_hanging_sheet(res);
  sim::StaticOptions so;
  so.tolerance = 1e-8;
  so.max_iterations = 200;
  sim::StaticResult r = sim::relax_static(sc.cloth, sc.objects, so);
  std::printf("reference: static Newton %dx%d, %d iterations, residual %.1e\n", res, res,
              r.iterations, r.residual);
  // Without bending, for the size of bending's contribution to the reference.
  sim::Testbed nb = sim::make_hanging_sheet(res);
  so.energy.bending = false;
  sim::relax_static(nb.cloth, nb.objects, so);
  double brms = 0, bmax = 0;
  sim::position_error(nb.cloth.state.x, sc.cloth.state.x, brms, bmax);
  std::printf("reference without bending differs by RMS %.3f mm, max %.3f mm\n", brms * 1e3,
              bmax * 1e3);
  std::printf("%-6s %-9s %-5s %-12s %-12s %-10s %-10s %s\n", "res", "dt", "iter", "ms/frame",
              "cpu ms/frame", "RMS mm", "max mm", "stable");
  bool all_ok = true;
  size_t pos = 0;
  while (pos < runs.size()) {
    size_t end = runs.find(',', pos);
    if (end == std::string::npos) end = runs.size();
    const std::string item = runs.substr(pos, end - pos);
    pos = end + 1;
    int sub = 0, it = 0;
    if (std::sscanf(item.c_str(), "%dx%d", &sub, &it) != 2 || sub < 1 || it < 1) {
      std::fprintf(stderr, "bad run '%s' (want SUBSTEPSxITERATIONS)\n", item.c_str());
      return 2;
    }
    const std::clock_t c0 = std::clock();
    bench::PeerRow row = bench::run_bullet_sheet(res, sub, it, opt);
    const double cpu = 1e3 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    const int frames = static_cast<int>(std::lround(sc.duration * 90));
    bool finite = row.positions.size() == sc.cloth.state.x.size();
    for (const auto& p : row.positions) finite = finite && p.allFinite();
    double rms = NAN, mx = NAN;
    if (finite) sim::position_error(row.positions, sc.cloth.state.x, rms, mx);
    std::printf("%-6d %-9.3g %-5d %-12.4g %-12.4g %-10.4g %-10.4g %s\n", res, row.dt,
                row.iterations, row.ms_per_frame, cpu / frames, rms * 1e3, mx * 1e3,
                row.stable && finite ? "yes" : "no");
    if (!row.stable || !finite) all_ok = false;
    if (check_rms > 0 && !(rms * 1e3 <= check_rms)) {
      std::printf("FAIL: RMS %.4g mm above the bound %.4g mm\n", rms * 1e3, check_rms);
      all_ok = false;
    }
  }
  // Our solvers on the same scene, same frame loop and clocks.
  pos = 0;
  while (pos < ours.size()) {
    size_t end = ours.find(',', pos);
    if (end == std::string::npos) end = ours.size();
    const std::string item = ours.substr(pos, end - pos);
    pos = end + 1;
    char name[32] = {0};
    int sub = 0, it = 0;
    if (std::sscanf(item.c_str(), "%31[a-z]:%dx%d", name, &sub, &it) != 3) {
      std::fprintf(stderr, "bad --ours item '%s' (want SOLVER:SUBSTEPSxITERATIONS)\n",
                   item.c_str());
      return 2;
    }
    sim::Testbed s2 = sim::make_hanging_sheet(res);
    sim::SolverConfig cfg;
    cfg.substeps = sub;
    cfg.iterations = it;
    auto solver = sim::make_solver(name, cfg);
    if (!solver) {
      std::fprintf(stderr, "%s\n", solver.error().c_str());
      return 2;
    }
    const int frames = static_cast<int>(std::lround(s2.duration * 90));
    const std::clock_t c0 = std::clock();
    const auto t0 = std::chrono::steady_clock::now();
    bool stable = true;
    int used = sub;
    for (int f = 0; f < frames; ++f) {
      sim::StepStats st = (*solver)->step(s2.cloth, s2.objects, 1.0 / 90);
      if (st.diverged) stable = false;
      if (f == 0) used = std::max(1, st.substeps);
    }
    const double wall =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = 1e3 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    double rms = 0, mx = 0;
    sim::position_error(s2.cloth.state.x, sc.cloth.state.x, rms, mx);
    std::printf("%-6d %-9.3g %-5d %-12.4g %-12.4g %-10.4g %-10.4g %s (%s)\n", res, 1.0 / 90 / used,
                it, wall / frames, cpu / frames, rms * 1e3, mx * 1e3, stable ? "yes" : "no", name);
  }
  return all_ok ? 0 : 1;
}
