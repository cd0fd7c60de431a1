// The solver benchmark: solver x substeps (dt) x iterations x resolution on the shared scenes;
// CPU time per 1/90 s frame and error against the converged reference (the static minimum of
// the same scene), plus the Bullet peer (bench/bullet_peer.hpp) on the
// sheet. Writes out/bench/solvers.csv and Pareto charts out/bench/solvers.svg (form) and
// solvers_sheet.svg (error vs time, log axes, one curve per solver), prints time-at-equal-
// error ratios of the default solver against the explicit baseline, Bullet and XPBD.
// Usage: solvers_bench [--quick] [--max-res N] [--sleep-only] [--threads-only] [FLAGS]
//        solvers_bench --probe SCENE RES SOLVER SUBSTEPS ITERATIONS [FLAGS]
// `solvers_bench --help` lists every flag with its default and range. They replace environment
// variables (NAME=v before the command; a 0/1 switch became --x / --no-x, both exist):
//   SOLVERS_THREADS         --threads                 REF_ITERS               --ref-iters
//   REF_SETTLE_FRAMES       --ref-settle-frames       SLEEP_REF_ITERS         --sleep-ref-iters
//   PROBE_POLISH_FRICTION=0 --no-polish-friction      POLISH_REUSE=0          --no-polish-reuse
//   POLISH_CG_MAX           --polish-cg-max           POLISH_CG_TOL           --polish-cg-tol
//   PROBE_FRAMES            --frames                  PROBE_REF=0             --no-ref
//   PROBE_POLISH=0          --no-polish               PROBE_FRICTION          --friction
//   PROBE_LOAD              --load                    PROBE_SAVE              --save
//   PROBE_SAVE_POLISHED     --save-polished           PROBE_DRIFT=1           --drift
//   PROBE_POLISH_STEPS      --polish-steps            PROBE_SMOOTH            --smooth
//   PROBE_COARSE_ONLY       --coarse-only             PROBE_COARSE_K          --coarse-k
//   PROBE_COARSE_FACTOR     --coarse-factor           PROBE_COARSE_ROT=0|1    --[no-]coarse-rot
//   PROBE_COARSE_MU=0       --no-coarse-mu            PROBE_MG_AA             --mg-aa
//   PROBE_MG_SWEEPS         --mg-sweeps               PROBE_MG_TAU            --mg-tau
//   PROBE_MG_NOCOARSE=1     --mg-nocoarse             PROBE_MG_REFRESH        --mg-refresh
//   PROBE_FINISH            --finish                  PROBE_FINISH_SWEEPS     --finish-sweeps
//   PROBE_FINISH_EXTRA      --finish-extra            VBD_INIT                --vbd-init
//   VBD_RHO                 --vbd-rho                 VBD_DAMP                --vbd-damp
//   VBD_AIR                 --vbd-air                 VBD_FREEZE=1            --vbd-freeze
//   VBD_TOL                 --vbd-tol                 VBD_FTOL                --vbd-ftol
//   VBD_THREADS             --vbd-threads             XPBD_WARM               --xpbd-warm
//   XPBD_WARM_FRAME         --xpbd-warm-frame         XPBD_WARM_LATE          --xpbd-warm-late
//   XPBD_REUSE=0            --no-xpbd-reuse           XPBD_BEND_EVERY         --xpbd-bend-every
//   XPBD_RETEST=0           --no-xpbd-retest          XPBD_SETTLE=0           --no-xpbd-settle
//   XPBD_FREEZE=1           --xpbd-freeze             XPBD_SETTLE_SCALE       --xpbd-settle-scale
//   XPBD_SETTLE_DAMP        --xpbd-settle-damp        XPBD_SNAP               --xpbd-snap
//   XPBD_SLEEP_STEPS        --xpbd-sleep-steps        XPBD_SETTLE_SPEED       --xpbd-settle-speed
//   XPBD_SETTLE_GROWTH      --xpbd-settle-growth      XPBD_COARSE             --xpbd-coarse
//   XPBD_COARSE_FRAMES      --xpbd-coarse-frames      XPBD_COARSE_ROT=1       --xpbd-coarse-rot
//   XPBD_FINISH=0           --no-xpbd-finish          XPBD_FINISH_CYCLES      --xpbd-finish-cycles
//   XPBD_FINISH_THREAD=0    --no-xpbd-finish-thread   XPBD_F32=0              --no-xpbd-f32
//   XPBD_KERNELS            --xpbd-kernels
//   DRAPE_XPBD_SIMD (a library knob before) --simd none|avx2|widest (0: none, avx512: widest)
// e.g. PROBE_FRAMES=270 SOLVERS_THREADS=2 solvers_bench --probe form 128 xpbd 10 1 is now
// solvers_bench --probe form 128 xpbd 10 1 --frames 270 --threads 2.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "bench/bullet_peer.hpp"
#include "sim/core/stopwatch.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/rest/coarse_correction.hpp"
#include "sim/rest/equilibrium_finisher.hpp"
#include "sim/solvers/solver_factory.hpp"
#include "sim/solvers/solver_newton.hpp"
#include "sim/solvers/solver_vbd.hpp"
#include "sim/solvers/watchdog.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"
#include "sim/solvers/xpbd/xpbd_kernels.hpp"
#include "sim/testbeds/testbed.hpp"

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

double cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

// The thread rows' settings (flags --thread-counts, --thread-res, --thread-rounds,
// --threads-default-only).
struct ThreadRowsConfig {
  std::vector<int> counts{1, 2, 4, 8, 16};  // threads of the default configuration
  std::vector<int> res{128, 256};
  std::optional<int> rounds;  // default: 3 up to 128^2, 1 above
  bool default_only = false;  // no double-precision or AVX2 rows
};

// The benchmark grid's and the probe's knobs (command-line flags; `solvers_bench --help` lists
// them). Unset optionals take the default named in their help: the solver's own or the scene's
// value, or one that depends on where the knob is used.
struct Knobs {
  // The benchmark grid (and the probe, where they apply).
  bool quick = false, sleep_only = false, threads_only = false, self_only = false,
       sweep_model = false;
  ThreadRowsConfig thread_rows;
  int max_res = 64;
  std::optional<int> threads;    // solver threads: grid 1, probe 2, the probe's --finish pool 1
  std::optional<int> ref_iters;  // Newton iterations: polish 300, contact scenes' reference 150
  int ref_settle_frames = 360;
  int sleep_ref_iters = 100;
  bool polish_friction = true;
  bool polish_reuse = true;
  int polish_cg_max = StaticOptions{}.reuse_max_cg;
  double polish_cg_tol = StaticOptions{}.reuse_cg_tolerance;
  // The probe (--probe SCENE RES SOLVER SUBSTEPS ITERATIONS).
  std::tuple<std::string, int, std::string, int, int> probe{"", 0, "", 0, 0};
  std::optional<int> frames;       // the scene's duration
  std::optional<double> friction;  // the scene's objects'
  bool ref = true, polish = true, drift = false;
  std::string load, save, save_polished;
  std::vector<int> polish_steps;
  int smooth = 0;
  int coarse_only = 0;
  double coarse_k = 1e4;
  std::optional<int> coarse_factor;  // --coarse-only 4, --finish 0
  std::optional<bool> coarse_rot;    // --coarse-only off, --finish on
  bool coarse_mu = true;
  int mg_aa = 0, mg_sweeps = 0, mg_refresh = 1;
  double mg_tau = 0.05;
  bool mg_nocoarse = false;
  int finish = 0;
  int finish_sweeps = FinisherOptions{}.sweeps;
  double finish_extra = FinisherOptions{}.extrapolate;
  // The probe's VBD solver.
  int vbd_init = 2;
  double vbd_rho = 0, vbd_damp = 0;
  std::optional<double> vbd_air;  // the scene's air damping (1 where it has none)
  bool vbd_freeze = false;
  double vbd_tol = 1e-6, vbd_ftol = 1e-2;
  int vbd_threads = 2;
  // The probe's XPBD solver (unset optionals: the solver's own value).
  std::optional<double> xpbd_warm, xpbd_settle_damp, xpbd_snap, xpbd_settle_speed,
      xpbd_settle_growth;
  std::optional<int> xpbd_sleep_steps, xpbd_coarse, xpbd_coarse_frames, xpbd_finish_cycles;
  std::optional<std::string> xpbd_kernels;
  bool xpbd_reuse = true, xpbd_retest = true, xpbd_settle = true, xpbd_freeze = false;
  bool xpbd_coarse_rot = false, xpbd_finish = true, xpbd_finish_thread = true, xpbd_f32 = true;
  int xpbd_bend_every = 1;
  double xpbd_settle_scale = 64;
  int xpbd_warm_frame = -1;
  double xpbd_warm_late = 1.0;
};

// Probe state files (--save / --load): a header (magic, vertex count) then x and v as
// doubles, in the machine's byte order (scratch files of one build, not an exchange format).
constexpr std::uint32_t kStateMagic = 0x44525354;  // "DRST"

bool save_state(const std::string& path, const Cloth& cloth) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) {
    std::fprintf(stderr, "save: cannot write %s\n", path.c_str());
    return false;
  }
  const std::uint32_t head[2] = {kStateMagic, static_cast<std::uint32_t>(cloth.num_vertices())};
  bool ok = std::fwrite(head, sizeof head, 1, f) == 1;
  for (const auto* vec : {&cloth.state.x, &cloth.state.v})
    ok = ok && std::fwrite(vec->data(), sizeof(Vec3), vec->size(), f) == vec->size();
  ok = std::fclose(f) == 0 && ok;
  if (!ok) std::fprintf(stderr, "save: writing %s failed\n", path.c_str());
  return ok;
}

bool load_state(const std::string& path, Cloth& cloth) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) {
    std::fprintf(stderr, "--load: cannot open %s\n", path.c_str());
    return false;
  }
  std::uint32_t head[2] = {0, 0};
  bool ok = std::fread(head, sizeof head, 1, f) == 1 && head[0] == kStateMagic &&
            head[1] == static_cast<std::uint32_t>(cloth.num_vertices());
  // Read into copies: a short or foreign file leaves the cloth as it was.
  std::vector<Vec3> x(cloth.state.x.size()), v(cloth.state.v.size());
  for (auto* vec : {&x, &v})
    ok = ok && std::fread(vec->data(), sizeof(Vec3), vec->size(), f) == vec->size();
  std::fclose(f);
  if (!ok) {
    std::fprintf(stderr, "--load: %s is not a state of this scene (%u vertices; expected %d)\n",
                 path.c_str(), head[1], cloth.num_vertices());
    return false;
  }
  cloth.state.x = x;
  cloth.state.x_prev = std::move(x);
  cloth.state.v = std::move(v);
  return true;
}

// Converged reference. Sheet and chain: the static minimum of the scene's energy (see
// reference() below). Form and sphere: the cloth falls onto an object and the drape it settles
// into depends on the path (where the folds form: explicit, XPBD and a VBD-settled reference
// end 8-10 mm apart, all at rest), so one fixed state is not "the" answer. Their reference is
// the equilibrium of the same energy nearest to the solver's own end state: the static Newton
// solver (contacts redetected, tolerance 1e-8) run from it. A solver that stopped short of
// equilibrium (still creeping, biased by too few iterations) is as far from it as it is wrong.
bool path_dependent(const std::string& scene) {
  return scene == "form" || scene == "sphere";
}

std::vector<Vec3> polished(const Knobs& kn, const Testbed& end, double& residual,
                           int max_iterations = 0, StaticResult* result = nullptr) {
  Testbed sc = end;
  StaticOptions so;
  so.tolerance = 1e-8;
  // The frictional equilibrium nearest to it (the scene's objects' mu); --no-polish-friction:
  // the frictionless one (for probing).
  so.friction = kn.polish_friction;
  so.reuse_factorisation = kn.polish_reuse;
  so.reuse_max_cg = kn.polish_cg_max;
  so.reuse_cg_tolerance = kn.polish_cg_tol;
  // 300: a less-settled 64^2 state needed 282 iterations (docs/solvers.md "Static solver speed").
  so.max_iterations = max_iterations > 0 ? max_iterations : kn.ref_iters.value_or(300);
  StaticResult r = relax_static(sc.cloth, sc.objects, so);
  residual = r.residual;
  if (result) *result = r;
  return sc.cloth.state.x;
}

Row run(const Knobs& kn, const std::string& scene, int res, const Config& c,
        const std::vector<Vec3>& ref, bool measure_error = true) {
  Testbed sc = make_scene(scene, res);
  SolverConfig cfg;
  cfg.substeps = c.substeps;
  cfg.iterations = c.iterations;
  cfg.springs_model = sc.springs_model;
  cfg.threads = kn.threads.value_or(1);
  cfg.air_drag = sc.air_drag;
  // "xpbd-nosettle": XPBD without settling pieces at rest (XpbdOptions::settle, on in "xpbd").
  cfg.settle = c.solver != "xpbd-nosettle";
  auto s = make_solver(c.solver == "xpbd-nosettle" ? "xpbd" : c.solver, cfg);
  const double frame = 1.0 / 90;
  const int frames = static_cast<int>(std::lround(sc.duration / frame));
  bool stable = true;
  const double c0 = cpu_ms();
  int used_substeps = c.substeps;
  for (int f = 0; f < frames; ++f) {
    StepStats st = (*s)->step(sc.cloth, sc.objects, frame);
    if (st.diverged) stable = false;
    if (f == 0) used_substeps = std::max(1, st.substeps);
  }
  const double ms = cpu_ms() - c0;  // process CPU time: the machine is shared
  if (!cloth_finite(sc.cloth)) stable = false;
  double rms = 0, mx = 0;
  if (!measure_error) {
    rms = mx = std::numeric_limits<double>::quiet_NaN();
  } else if (path_dependent(scene) && stable) {
    double res_polish = 0;
    position_error(sc.cloth.state.x, polished(kn, sc, res_polish), rms, mx);
    if (!(res_polish < 1e-2))
      std::printf("  (static polish of the end state stopped at residual %.1e)\n", res_polish);
  } else {
    position_error(sc.cloth.state.x, ref, rms, mx);
  }
  return {scene,     c.solver, res,   frame / used_substeps, c.iterations, ms / frames,
          rms * 1e3, mx * 1e3, stable};
}

std::vector<Vec3> reference(const Knobs& kn, const std::string& scene, int res) {
  Testbed sc = make_scene(scene, res);
  StaticOptions so;
  so.tolerance = 1e-8;
  so.max_iterations = 200;
  if (sc.springs_model) so.energy.model = EnergyOptions::Model::kSprings;
  const bool contact = scene == "form" || scene == "sphere";
  if (contact) {
    VbdOptions o;
    o.substeps = 2;
    o.iterations = res > 32 ? 40 : 60;
    o.air_drag = 3.0;  // settles faster; the static minimum does not depend on it
    o.threads = 1;
    o.tolerance = 1e-9;
    o.force_tolerance = 1e-4;
    VbdSolver v(o);
    for (int f = 0; f < kn.ref_settle_frames; ++f) v.step(sc.cloth, sc.objects, 1.0 / 90);
    so.max_iterations = kn.ref_iters.value_or(150);
  }
  const std::vector<Vec3> settled = sc.cloth.state.x;
  StaticResult r = relax_static(sc.cloth, sc.objects, so);
  std::printf("reference %s %d: %s%d Newton iterations, residual %.1e, %.0f ms\n", scene.c_str(),
              res, contact ? "settled 4 s, then " : "", r.iterations, r.residual, r.ms);
  if (contact && !(r.residual < 1e-2)) {
    double rms = 0, mx = 0;
    position_error(settled, sc.cloth.state.x, rms, mx);
    std::printf("  Newton polish did not converge (moved rms %.3f mm): the settled state is used\n",
                rms * 1e3);
    return settled;
  }
  return sc.cloth.state.x;
}

void write_svg(const std::vector<Row>& rows, const std::string& scene, int res,
               const std::string& path) {
  const double W = 720, H = 480, L = 70, R = 150, T = 30, B = 50;
  double tmin = 1e9, tmax = 0, emin = 1e9, emax = 0;
  std::map<std::string, std::vector<const Row*>> by;
  for (const auto& r : rows) {
    if (r.scene != scene || r.resolution != res || !r.stable || !(r.rms_mm >= 0)) continue;
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

// The XPBD solver inside s (make_solver wraps it in the watchdog), or null.
XpbdSolver* xpbd_of(Solver* s) {
  if (auto* wd = dynamic_cast<WatchdogSolver*>(s)) s = &wd->inner();
  return dynamic_cast<XpbdSolver*>(s);
}

// A finish on its own thread (XpbdOptions::finish_thread) lands in the frame after its job
// ends: steps on at the app's pace (1/90 s of wall time per frame; a sleeping frame costs one
// contact check) until it has. Returns the frames stepped (0: nothing was finishing) and their
// wall time in `ms`.
int land_finish(Solver& s, Testbed& sc, double& ms) {
  ms = 0;
  XpbdSolver* xp = xpbd_of(&s);
  if (!xp || !xp->finishing()) return 0;
  const auto t0 = std::chrono::steady_clock::now();
  int frames = 0;
  for (; frames < 90 * 600 && xp->finishing(); ++frames) {
    std::this_thread::sleep_for(std::chrono::microseconds(11111));
    s.step(sc.cloth, sc.objects, 1.0 / 90);
  }
  ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return frames;
}

// --probe SCENE RES SOLVER SUBSTEPS ITERATIONS: one configuration with the options of the
// "probe" groups of --help (the VBD and XPBD solvers' options, --frames, --ref-iters, --no-polish
// skips the final scoring, --friction the objects' friction coefficient, --xpbd-warm-frame +
// --xpbd-warm-late: warm start from a frame on), printing wall and CPU time per frame and the
// error per 0.1 s.
int probe(const Knobs& kn) {
  const auto& [scene, res, solver, ns, it] = kn.probe;
  if (res < 2 || ns < 0 || it < 0) {
    std::fprintf(stderr, "--probe: RES must be >= 2, SUBSTEPS and ITERATIONS >= 0\n");
    return 2;
  }
  // Path-dependent scenes are scored against the equilibrium nearest to the end state (at the
  // end); --no-ref skips the static reference the progress lines compare with.
  const std::vector<Vec3> refx =
      kn.ref ? reference(kn, scene, res) : make_scene(scene, res).cloth.state.x;
  {
    Vec3 lo = refx[0], hi = lo;
    for (const auto& p : refx) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    std::printf("reference box (%.3f %.3f %.3f)-(%.3f %.3f %.3f)\n", lo.x(), lo.y(), lo.z(), hi.x(),
                hi.y(), hi.z());
  }
  Testbed sc = make_scene(scene, res);
  std::unique_ptr<Solver> s;
  VbdSolver* vbd = nullptr;
  if (solver == "vbd") {
    VbdOptions o;
    o.substeps = ns;
    o.iterations = it;
    o.init = static_cast<VbdOptions::Init>(kn.vbd_init);
    o.chebyshev_rho = kn.vbd_rho;
    o.chebyshev = o.chebyshev_rho > 0;
    o.rayleigh_damping = kn.vbd_damp;
    o.air_drag = kn.vbd_air.value_or(sc.air_drag >= 0 ? sc.air_drag : 1.0);
    o.freeze = kn.vbd_freeze;
    o.tolerance = kn.vbd_tol;
    o.force_tolerance = kn.vbd_ftol;
    o.threads = kn.vbd_threads;
    auto v = std::make_unique<VbdSolver>(o);
    vbd = v.get();
    s = std::move(v);
  } else {
    SolverConfig cfg;
    cfg.substeps = ns;
    cfg.iterations = it;
    cfg.springs_model = sc.springs_model;
    cfg.threads = kn.threads.value_or(2);
    cfg.air_drag = sc.air_drag;
    auto made = make_solver(solver, cfg);
    if (!made) {
      std::fprintf(stderr, "--probe: %s\n", made.error().c_str());
      return 2;
    }
    s = std::move(made.value());
    if (auto* xp = xpbd_of(s.get())) {
      XpbdOptions& o = xp->options();
      o.warm_start = kn.xpbd_warm.value_or(o.warm_start);
      o.reuse_contacts = kn.xpbd_reuse;
      o.bending_every = kn.xpbd_bend_every;
      o.retest_contacts = kn.xpbd_retest;
      o.settle = kn.xpbd_settle;
      o.freeze = kn.xpbd_freeze;
      o.settle_mass_scale = kn.xpbd_settle_scale;
      o.settle_air_drag = kn.xpbd_settle_damp.value_or(o.settle_air_drag);
      o.contact_snap_depth = kn.xpbd_snap.value_or(o.contact_snap_depth);
      o.settle_sleep_steps = kn.xpbd_sleep_steps.value_or(o.settle_sleep_steps);
      o.settle_speed = kn.xpbd_settle_speed.value_or(o.settle_speed);
      o.settle_growth = kn.xpbd_settle_growth.value_or(o.settle_growth);
      o.coarse_factor = kn.xpbd_coarse.value_or(o.coarse_factor);
      o.coarse_frames = kn.xpbd_coarse_frames.value_or(o.coarse_frames);
      o.coarse.rotations = kn.xpbd_coarse_rot;
      o.finish = kn.xpbd_finish;
      o.finisher.cycles = kn.xpbd_finish_cycles.value_or(o.finisher.cycles);
      o.finish_thread = kn.xpbd_finish_thread;
      o.single_precision = kn.xpbd_f32;
      o.kernels = kn.xpbd_kernels.value_or(o.kernels);
    }
  }
  sc.objects.friction = kn.friction.value_or(sc.objects.friction);
  const double frame = 1.0 / 90;
  const int frames = kn.frames.value_or(static_cast<int>(std::lround(sc.duration / frame)));
  double wall = 0, cpu = 0, max_wall = 0, first_wall = 0;
  int max_frame = -1;
  long iters = 0;
  // --load FILE: start from a state --save FILE wrote (positions and velocities of the same
  // scene and resolution), e.g. to examine the polish of one end state without re-running the
  // drape (--frames 0).
  if (!kn.load.empty() && !load_state(kn.load, sc.cloth)) return 1;
  const std::vector<Vec3> start_x = sc.cloth.state.x;
  for (int f = 0; f < frames; ++f) {
    if (f == kn.xpbd_warm_frame) {
      if (auto* xp = xpbd_of(s.get())) xp->options().warm_start = kn.xpbd_warm_late;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_ms();
    StepStats st = s->step(sc.cloth, sc.objects, frame);
    cpu += cpu_ms() - c0;
    const double w =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    wall += w;
    if (f == 0) first_wall = w;
    if (w > max_wall) max_wall = w, max_frame = f;
    iters += st.iterations;
    if ((f + 1) % 9 == 0 || f + 1 == frames) {
      double rms = 0, mx = 0;
      position_error(sc.cloth.state.x, refx, rms, mx);
      Vec3 lo = sc.cloth.state.x[0], hi = lo;
      double ke = 0, sd = 1;
      for (size_t i = 0; i < sc.cloth.state.x.size(); ++i) {
        lo = lo.cwiseMin(sc.cloth.state.x[i]);
        hi = hi.cwiseMax(sc.cloth.state.x[i]);
        ke += 0.5 * sc.cloth.state.mass[i] * sc.cloth.state.v[i].squaredNorm();
        if (sc.objects.form)
          sd = std::min(sd, sc.objects.form->signed_distance(sc.cloth.state.x[i]));
      }
      std::printf(
          "t %.2f s: rms %.3f mm max %.3f mm  iters/frame %.1f frozen %d settle x%.0f  KE %.2e J  "
          "min sd %.1f mm  box (%.3f %.3f %.3f)-(%.3f %.3f %.3f)\n",
          (f + 1) * frame, rms * 1e3, mx * 1e3, double(iters) / (f + 1),
          vbd ? vbd->frozen_count() : 0, xpbd_of(s.get()) ? xpbd_of(s.get())->settle_scale() : 1.0,
          ke, sd * 1e3, lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z());
    }
  }
  if (kn.drift) {
    double rms = 0, mx = 0;
    position_error(sc.cloth.state.x, start_x, rms, mx);
    std::printf("drift from the start state: rms %.3f mm, max %.3f mm\n", rms * 1e3, mx * 1e3);
  }
  std::printf(
      "%s %d %s %dx%d: wall %.3f ms/frame, cpu %.3f ms/frame (this thread), longest frame %.1f "
      "ms (frame %d); steady %.3f ms/frame (the frames after the first, whose %.1f ms include "
      "the solver's setup)\n",
      scene.c_str(), res, solver.c_str(), ns, it, frames ? wall / frames : 0.0,
      frames ? cpu / frames : 0.0, max_wall, max_frame,
      frames > 1 ? (wall - first_wall) / (frames - 1) : 0.0, first_wall);
  double land_ms = 0;
  if (const int extra = land_finish(*s, sc, land_ms); extra > 0)
    std::printf("finish thread: landed %d frames (%.0f ms) after the last frame\n", extra, land_ms);
  if (!kn.save.empty() && !save_state(kn.save, sc.cloth)) return 1;
  {
    // The fastest vertices at the end (a drape at rest should have none): speed, height, distance
    // from the form's surface.
    std::vector<int> idx(sc.cloth.state.x.size());
    for (size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<int>(i);
    const auto& v = sc.cloth.state.v;
    const size_t k = std::min<size_t>(5, idx.size());
    std::partial_sort(idx.begin(), idx.begin() + k, idx.end(),
                      [&](int a, int b) { return v[a].squaredNorm() > v[b].squaredNorm(); });
    std::printf("fastest vertices at the end:");
    for (size_t j = 0; j < k; ++j) {
      const int i = idx[j];
      const double sd = sc.objects.form ? sc.objects.form->signed_distance(sc.cloth.state.x[i]) : 1;
      std::printf(" [%d: %.2f mm/s, y %.3f m, sd %.2f mm]", i, v[i].norm() * 1e3,
                  sc.cloth.state.x[i].y(), sd * 1e3);
    }
    std::printf("\n");
  }
  if (auto* xp = xpbd_of(s.get())) {
    const bool f32 = xp->options().single_precision;
    std::printf(
        "xpbd: %.2f contact detections and %.0f vertices tested again per frame, %ld anchor "
        "renewals in %d frames%s; kernels %s (%d triangles, %d bending blocks per pack); "
        "element sweeps %.3f ms/frame wall, the rest of the steps %.3f\n",
        double(xp->contact_detections()) / frames, double(xp->contact_retests()) / frames,
        xp->anchor_renewals(), frames, f32 ? "" : " (double precision)", xp->kernels().name,
        f32 ? xp->kernels().tri_lanes : 4, f32 ? 8 : 4, frames ? xp->sweep_ms() / frames : 0.0,
        frames ? (wall - xp->sweep_ms()) / frames : 0.0);
    // The steps' parts (the cooks apart): on more threads, a part whose time does not fall is
    // serial.
    std::printf("xpbd step parts, wall ms/frame:");
    for (int p = 0; p < XpbdSolver::kStepParts; ++p)
      std::printf(" %s %.3f%s", XpbdSolver::part_name(p), frames ? xp->part_ms(p) / frames : 0.0,
                  p + 1 < XpbdSolver::kStepParts ? "," : "\n");
    if (xp->options().coarse_factor > 0) {
      const CoarseStats& c = xp->last_coarse();
      std::printf(
          "xpbd coarse correction: %d applied, %.1f ms in all (%.2f ms/frame); last: %d nodes, "
          "alpha %.3g, moved %.4f mm, residual %.2e N, build %.1f ms, assemble %.1f ms, factor "
          "%.1f "
          "ms, total %.1f ms\n",
          xp->coarse_count(), xp->coarse_ms(), frames ? xp->coarse_ms() / frames : 0.0, c.nodes,
          c.alpha, c.max_move * 1e3, c.residual, c.build_ms, c.assemble_ms, c.factor_ms,
          c.total_ms);
    }
    if (xp->finish_count() > 0) {
      const FinisherStats& f = xp->last_finish();
      std::printf(
          "xpbd static finish: %d pieces, %d cycles, %.0f ms in all%s; last %s: E %.9f -> %.9f "
          "J, last cycle moved %.4f mm, sweeps %.0f ms, coarse %.0f ms\n",
          xp->finish_count(), xp->finish_cycles(), xp->finish_ms(),
          xp->options().finish_thread ? " (on its own thread)" : "",
          xp->options().finish_thread ? "job" : "cycle", f.energy_before, f.energy_after,
          f.last_move * 1e3, f.sweep_ms, f.coarse_ms);
    }
  }
  // --coarse-only k: k coarse corrections (sim/rest/coarse_correction.hpp, lattice
  // --coarse-factor) of the end state alone, contacts re-detected before each (the
  // correction alone, without the solver's sweeps).
  CoarseCorrection probe_cc;
  bool probe_cc_used = false;
  if (const int kc = kn.coarse_only; kc > 0) {
    probe_cc_used = true;
    ClothEnergy e;
    EnergyOptions eo;
    e.build(sc.cloth, eo);
    e.set_form(&sc.objects);
    e.set_contact_stiffness(kn.coarse_k);
    CoarseCorrection& cc = probe_cc;
    cc.options().factor = kn.coarse_factor.value_or(4);
    cc.options().rotations = kn.coarse_rot.value_or(false);
    std::vector<int> group(sc.cloth.num_vertices());
    for (int i = 0; i < sc.cloth.num_vertices(); ++i) group[i] = sc.cloth.is_free(i) ? 0 : -1;
    const std::vector<Vec3> anchor = sc.cloth.state.x;  // friction's, as the polish's
    // --mg-aa m: Anderson acceleration (Peng et al. 2018) of the cycle x -> G(x) over the
    // last m cycles, kept only when it lowers E below G(x)'s (else the history restarts).
    const int aa_m = kn.mg_aa;
    const int nx = 3 * sc.cloth.num_vertices();
    std::vector<Eigen::VectorXd> dF, dG;
    Eigen::VectorXd f_prev, g_prev;
    int aa_taken = 0;
    auto flat = [&](const std::vector<Vec3>& v) {
      return Eigen::Map<const Eigen::VectorXd>(v[0].data(), nx);
    };
    for (int cycle = 0; cycle < kc; ++cycle) {
      const Eigen::VectorXd xin = flat(sc.cloth.state.x);
      e.detect_contacts(sc.cloth, sc.objects);
      if (sc.objects.friction > 0 && kn.coarse_mu) {
        e.set_friction(sc.objects.friction, 1e-4, anchor);
        e.lag_friction_load(sc.cloth.state.x, sc.cloth.state.mass);
      }
      // --mg-sweeps v: v Gauss-Seidel sweeps of per-vertex Newton steps on the static
      // energy before each correction (a two-level cycle's smoother; the equilibrium is its
      // fixed point).
      const int sweeps = kn.mg_sweeps;
      const double tau2 = std::pow(kn.mg_tau, 2);
      const double e0 = e.energy(sc.cloth.state.x, sc.cloth.state.mass);
      const double cs0 = cpu_ms();
      for (int sw = 0; sw < sweeps; ++sw)
        for (int i = 0; i < sc.cloth.num_vertices(); ++i) {
          if (group[i] < 0) continue;
          Vec3 fi;
          Mat3 Hi;
          const double mi = sc.cloth.state.mass[i];
          e.vertex_force_hessian(i, sc.cloth.state.x, mi, fi, Hi);
          Hi.diagonal().array() += mi / tau2;
          sc.cloth.state.x[i] += Hi.ldlt().solve(fi);
        }
      if (sweeps > 0)
        std::printf("  %d sweeps: E %.9f -> %.9f J, %.1f ms CPU\n", sweeps, e0,
                    e.energy(sc.cloth.state.x, sc.cloth.state.mass), cpu_ms() - cs0);
      // --mg-nocoarse: the sweeps alone (the cycle without its coarse step).
      const CoarseStats c = kn.mg_nocoarse ? CoarseStats{}
                                           : cc.apply(sc.cloth, e, group, sc.cloth.state.x,
                                                      cycle % kn.mg_refresh != 0);
      if (aa_m > 0) {
        const Eigen::VectorXd g = flat(sc.cloth.state.x);
        const Eigen::VectorXd fk = g - xin;
        if (f_prev.size() == nx) {
          dF.push_back(fk - f_prev);
          dG.push_back(g - g_prev);
          if (static_cast<int>(dF.size()) > aa_m) {
            dF.erase(dF.begin());
            dG.erase(dG.begin());
          }
        }
        f_prev = fk;
        g_prev = g;
        const int h = static_cast<int>(dF.size());
        if (h > 0) {
          Eigen::MatrixXd A(h, h);
          Eigen::VectorXd b(h);
          for (int a = 0; a < h; ++a) {
            b[a] = dF[a].dot(fk);
            for (int bb = 0; bb < h; ++bb) A(a, bb) = dF[a].dot(dF[bb]);
          }
          A.diagonal().array() += 1e-10 * A.diagonal().maxCoeff() + 1e-30;
          const Eigen::VectorXd gam = A.ldlt().solve(b);
          Eigen::VectorXd xa = g;
          for (int a = 0; a < h; ++a) xa -= gam[a] * dG[a];
          std::vector<Vec3> xav(sc.cloth.num_vertices());
          Eigen::Map<Eigen::VectorXd>(xav[0].data(), nx) = xa;
          const double eg = e.energy(sc.cloth.state.x, sc.cloth.state.mass);
          const double ea = e.energy(xav, sc.cloth.state.mass);
          if (ea < eg) {
            sc.cloth.state.x = xav;
            ++aa_taken;
          } else {
            dF.clear();
            dG.clear();
          }
          std::printf("  anderson (%d): E %.9f vs cycle %.9f: %s\n", h, ea, eg,
                      ea < eg ? "taken" : "restart");
        }
      }
      e.clear_friction();
      std::printf(
          "coarse %d: applied %d alpha %.3g moved %.4f mm residual %.3e N  E %.9f -> %.9f J  "
          "%.1f ms (assemble %.1f, factor %.1f), %d nodes\n",
          cycle, c.applied ? 1 : 0, c.alpha, c.max_move * 1e3, c.residual, c.energy_before,
          c.energy_after, c.total_ms, c.assemble_ms, c.factor_ms, c.nodes);
    }
    sc.cloth.state.x_prev = sc.cloth.state.x;
    if (aa_m > 0) std::printf("anderson steps taken: %d of %d\n", aa_taken, kc);
  }
  // --finish k: the static finish (sim/rest/equilibrium_finisher.hpp) of the end state, at most
  // k cycles (--finish-sweeps, --coarse-factor, --no-coarse-rot for translations).
  if (const int kf = kn.finish; kf > 0) {
    EquilibriumFinisher fin;
    fin.options().cycles = kf;
    fin.options().sweeps = kn.finish_sweeps;
    fin.options().coarse_factor = kn.coarse_factor.value_or(0);
    fin.options().rotations = kn.coarse_rot.value_or(true);
    fin.options().extrapolate = kn.finish_extra;
    std::vector<int> group(sc.cloth.num_vertices());
    for (int i = 0; i < sc.cloth.num_vertices(); ++i) group[i] = sc.cloth.is_free(i) ? 0 : -1;
    ThreadPool pool(kn.threads.value_or(1));
    const FinisherStats fs = fin.run(sc.cloth, sc.objects, group, EnergyOptions{}, &pool);
    std::printf(
        "finish: %d cycles, E %.9f -> %.9f J, moved %.3f mm (last cycle %.4f mm), sweeps %.0f ms, "
        "coarse %.0f ms, total %.0f ms\n",
        fs.cycles, fs.energy_before, fs.energy_after, fs.max_move * 1e3, fs.last_move * 1e3,
        fs.sweep_ms, fs.coarse_ms, fs.total_ms);
  }
  if (path_dependent(scene) && kn.polish) {
    double res_polish = 0, rms = 0, mx = 0;
    StaticResult pr;
    const std::vector<Vec3> pol = polished(kn, sc, res_polish, 0, &pr);
    // --save-polished FILE: the equilibrium itself (velocities zero), e.g. to start a solver at it
    // and see where the solver's own fixed point lies (--drift).
    if (!kn.save_polished.empty()) {
      Cloth eq = sc.cloth;
      eq.state.x = pol;
      eq.state.x_prev = pol;
      std::fill(eq.state.v.begin(), eq.state.v.end(), Vec3::Zero());
      if (!save_state(kn.save_polished, eq)) return 1;
    }
    position_error(sc.cloth.state.x, pol, rms, mx);
    std::printf(
        "static polish: %d Newton iterations (%d exact), %d rounds, %.0f ms wall, %d "
        "factorisations (%.0f ms), %d systems by CG on a stale factorisation (%d CG "
        "iterations, %.0f ms)\n",
        pr.iterations, pr.exact_steps, pr.rounds, pr.ms, pr.factorisations, pr.factor_ms,
        pr.cg_solves, pr.cg_iterations, pr.cg_ms);
    std::printf(
        "error against the equilibrium nearest to the end state: rms %.3f mm, max %.3f mm "
        "(static polish residual %.1e, energy there %.9f J)\n",
        rms * 1e3, mx * 1e3, res_polish, pr.energy);
    // --polish-steps 1,2,4: how close a static solve of n Newton iterations from the end state
    // gets to that equilibrium, and what it costs (a polish of a piece falling asleep).
    for (const int n : kn.polish_steps) {
      double rk = 0, e_rms = 0, e_max = 0;
      const double c0 = cpu_ms();
      const std::vector<Vec3> xk = polished(kn, sc, rk, n);
      const double ms = cpu_ms() - c0;
      position_error(xk, pol, e_rms, e_max);
      std::printf(
          "  polish of %d Newton iterations: %.0f ms CPU, residual %.1e, rms %.3f mm, "
          "max %.3f mm from the equilibrium\n",
          n, ms, rk, e_rms * 1e3, e_max * 1e3);
    }
    // --smooth k: how smooth the error field is: k Jacobi passes of neighbour averaging (over
    // the triangles' edges) keep its long wavelengths; printed: rms of the smoothed field and of
    // what the smoothing removed.
    if (const int ks = kn.smooth; ks > 0) {
      const int nv = sc.cloth.num_vertices();
      std::vector<Vec3> e(nv), acc(nv);
      std::vector<int> cnt(nv);
      for (int i = 0; i < nv; ++i) e[i] = pol[i] - sc.cloth.state.x[i];
      const std::vector<Vec3> e0 = e;
      for (int pass = 0; pass < ks; ++pass) {
        std::fill(acc.begin(), acc.end(), Vec3::Zero());
        std::fill(cnt.begin(), cnt.end(), 0);
        for (const auto& t : sc.cloth.topo.triangles)
          for (int a = 0; a < 3; ++a) {
            acc[t[a]] += e[t[(a + 1) % 3]] + e[t[(a + 2) % 3]];
            cnt[t[a]] += 2;
          }
        for (int i = 0; i < nv; ++i)
          if (cnt[i]) e[i] = 0.5 * e[i] + 0.5 * acc[i] / cnt[i];
      }
      double s2 = 0, r2 = 0;
      for (int i = 0; i < nv; ++i) {
        s2 += e[i].squaredNorm();
        r2 += (e0[i] - e[i]).squaredNorm();
      }
      std::printf(
          "  error field after %d smoothing passes: smooth part rms %.3f mm, rest %.3f mm\n", ks,
          std::sqrt(s2 / nv) * 1e3, std::sqrt(r2 / nv) * 1e3);
    }
    if (probe_cc_used) {
      std::vector<Vec3> e(pol.size()), fe;
      for (size_t i = 0; i < pol.size(); ++i) e[i] = pol[i] - sc.cloth.state.x[i];
      if (probe_cc.fit(e, fe)) {
        double f2 = 0, r2 = 0;
        for (size_t i = 0; i < e.size(); ++i) {
          f2 += fe[i].squaredNorm();
          r2 += (e[i] - fe[i]).squaredNorm();
        }
        std::printf("  error field fitted by the coarse space: fit rms %.3f mm, rest %.3f mm\n",
                    std::sqrt(f2 / e.size()) * 1e3, std::sqrt(r2 / e.size()) * 1e3);
      }
    }
    // Where the error is: vertices touching the form (within 0.5 mm of the kept-out shell)
    // and free ones, and the worst vertex's height and displacement.
    double e_touch = 0, e_free = 0, worst = -1;
    int n_touch = 0, n_free = 0, iw = 0;
    for (size_t i = 0; i < pol.size(); ++i) {
      const double e2 = (sc.cloth.state.x[i] - pol[i]).squaredNorm();
      const double sd =
          sc.objects.form ? sc.objects.form->signed_distance(sc.cloth.state.x[i]) : 1.0;
      if (sd < sc.objects.offset + 5e-4) {
        e_touch += e2;
        ++n_touch;
      } else {
        e_free += e2;
        ++n_free;
      }
      if (e2 > worst) {
        worst = e2;
        iw = static_cast<int>(i);
      }
    }
    const Vec3 d = pol[iw] - sc.cloth.state.x[iw];
    std::printf(
        "  touching the form: %d vertices, rms %.3f mm; free: %d, rms %.3f mm; worst vertex %d at "
        "y %.3f m moves (%.2f %.2f %.2f) mm\n",
        n_touch, n_touch ? std::sqrt(e_touch / n_touch) * 1e3 : 0.0, n_free,
        n_free ? std::sqrt(e_free / n_free) * 1e3 : 0.0, iw, sc.cloth.state.x[iw].y(), d.x() * 1e3,
        d.y() * 1e3, d.z() * 1e3);
  }
  return 0;
}

// Sleeping ("skip what a scene doesn't need"): the default solver on the form scene with and
// without freezing for 8 s, CPU ms per frame while the panel drapes (0-3 s), while it settles
// (3-6 s; at 128^2 its last wrinkles stop at ~4.5 s) and at rest (6-8 s), the fraction of
// vertices asleep at the end and when the whole panel first slept. With freezing, the static
// finish of the sleeping drape runs on its own thread (the app's default): its CPU time is not in
// the rows' (this thread's) and is reported beside them, with how long after 8 s it landed.
void sleep_rows(const Knobs& kn, int sres) {
  std::ofstream sl("out/bench/solvers_sleep.csv");
  sl << "scene,solver,resolution,freeze,ms_per_frame_drape,ms_per_frame_settling,"
        "ms_per_frame_rest,ms_per_frame_mean,frozen_fraction,all_asleep_s,rms_error_mm,"
        "max_error_mm,finish_thread_ms,finish_landed_ms\n";
  double rest[2] = {0, 0};
  for (int fr = 0; fr < 2; ++fr) {
    Testbed sc = make_scene("form", sres);
    SolverConfig cfg;
    cfg.freeze = fr == 1;
    cfg.threads = 1;
    cfg.air_drag = sc.air_drag;
    auto s = make_solver("default", cfg);
    const int marks[4] = {0, 270, 540, 720};
    double ms[3] = {0, 0, 0}, asleep_at = -1;
    int frozen = 0;
    for (int k = 0; k < 3; ++k) {
      const double c0 = cpu_ms();
      for (int f = marks[k]; f < marks[k + 1]; ++f) {
        (*s)->step(sc.cloth, sc.objects, 1.0 / 90);
        if (asleep_at < 0 && fr == 1) {
          bool all = true;
          for (int i = 0; i < sc.cloth.num_vertices() && all; ++i)
            all = !sc.cloth.is_free(i) || (sc.cloth.state.flags[i] & kFlagFrozen);
          if (all) asleep_at = (f + 1) / 90.0;
        }
      }
      ms[k] = (cpu_ms() - c0) / (marks[k + 1] - marks[k]);
    }
    // The static finish runs on its own thread (not in this thread's CPU time): its cycles'
    // time, and how long after the 8 s its result landed.
    double land_ms = 0, finish_ms = 0;
    land_finish(**s, sc, land_ms);
    if (XpbdSolver* xp = xpbd_of(s->get())) finish_ms = xp->finish_ms();
    for (uint8_t fl : sc.cloth.state.flags) frozen += (fl & kFlagFrozen) ? 1 : 0;
    const double frac = double(frozen) / sc.cloth.num_vertices();
    rest[fr] = ms[2];
    const double mean = (ms[0] * 270 + ms[1] * 270 + ms[2] * 180) / 720;
    // The settled drape (freezing run) scored against the equilibrium nearest to it.
    double rms = std::numeric_limits<double>::quiet_NaN(), mx = rms;
    if (fr == 1) {
      double res_polish = 0;
      position_error(sc.cloth.state.x, polished(kn, sc, res_polish, kn.sleep_ref_iters), rms, mx);
      rms *= 1e3;
      mx *= 1e3;
      std::printf(
          "    settled %d^2 drape: %.3f mm rms, %.3f mm max from the nearest equilibrium "
          "(polish residual %.1e)\n",
          sres, rms, mx, res_polish);
    }
    std::printf(
        "sleep    %4d %s freeze %d: %8.3f ms/frame draping (0-3 s), %8.3f settling (3-6 s), "
        "%8.3f at rest (6-8 s), %.0f %% asleep, all asleep at %.2f s; static finish %.0f ms on "
        "its thread, landed %.0f ms after 8 s\n",
        sres, kDefaultSolver, fr, ms[0], ms[1], ms[2], 100 * frac, asleep_at, finish_ms, land_ms);
    sl << "form," << kDefaultSolver << "," << sres << "," << fr << "," << ms[0] << "," << ms[1]
       << "," << ms[2] << "," << mean << "," << frac << "," << asleep_at << "," << rms << "," << mx
       << "," << finish_ms << "," << land_ms << std::endl;
  }
  if (rest[1] > 0)
    std::printf("    cost at rest without / with freezing = %.1fx\n", rest[0] / rest[1]);
}

// The machine's CPU model (Linux: /proc/cpuinfo's first "model name"; empty elsewhere).
std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      std::string m = line.substr(line.find(':') + 1);
      m.erase(0, m.find_first_not_of(' '));
      return m;
    }
  return "";
}

// One timed drape for the thread rows: wall ms for all frames, CPU ms, the first frame's ms.
struct ThreadRun {
  double wall = 0, cpu = 0, steady = 0, first = 0;
  std::string kernels;
  std::array<double, XpbdSolver::kStepParts> parts{};  // XPBD: wall ms/frame of each step part
};
ThreadRun timed_drape(int res, int threads, bool dbl, const std::string& kernels,
                      std::optional<int> frames_cap) {
  Testbed sc = make_scene("form", res);
  SolverConfig cfg;
  cfg.substeps = 10;
  cfg.threads = threads;
  cfg.air_drag = sc.air_drag;
  auto s = make_solver("default", cfg);
  if (auto* xp = xpbd_of(s->get())) {
    xp->options().single_precision = !dbl;
    xp->options().kernels = kernels;
  }
  const int frames =
      std::max(2, frames_cap.value_or(static_cast<int>(std::lround(sc.duration * 90))));
  const double c0 = cpu_ms();
  const auto w0 = std::chrono::steady_clock::now();
  (*s)->step(sc.cloth, sc.objects, 1.0 / 90);  // the first frame cooks the solver
  const auto w1 = std::chrono::steady_clock::now();
  for (int f = 1; f < frames; ++f) (*s)->step(sc.cloth, sc.objects, 1.0 / 90);
  const auto w2 = std::chrono::steady_clock::now();
  auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  ThreadRun r{ms(w2 - w0) / frames, (cpu_ms() - c0) / frames, ms(w2 - w1) / (frames - 1),
              ms(w1 - w0), ""};
  if (auto* xp = xpbd_of(s->get())) {
    r.kernels = xp->kernels().name;
    for (int p = 0; p < XpbdSolver::kStepParts; ++p) r.parts[p] = xp->part_ms(p) / frames;
  }
  return r;
}

void thread_rows(int max_res, const ThreadRowsConfig& tr, std::optional<int> frames_cap) {
  // Threads and precision: the default solver 10x1 on the form scene (the 3-s drape) with 1, 2,
  // 4, 8 and 16 threads (the element sweep in one share per thread, the same result), wall and
  // CPU ms per frame at 128^2 and 256^2, with XPBD's kernels in single precision (the default);
  // at 1 and 2 threads also the double kernels and, on a CPU with AVX-512, the single precision
  // kernels of the AVX2 build (what a CPU without AVX-512 runs). The wall time is what one frame
  // takes; threads beyond the machine's cores (the file's `cores`) take turns on them. A shared
  // host's speed drifts by tens of % within minutes, so the configurations run interleaved in
  // rounds (3 up to 128^2, 1 above, unless --thread-rounds) and each row is the median of its
  // rounds. Speed-up and parallel efficiency are against the same configuration on one thread.
  const unsigned cores = std::thread::hardware_concurrency();
  const std::string cpu = cpu_model();
  std::ofstream tc("out/bench/solvers_threads.csv");
  tc << "scene,solver,resolution,substeps,threads,cores,precision,kernels,runs,ms_per_frame,"
        "cpu_ms_per_frame,steady_ms_per_frame,first_frame_ms,speedup,efficiency,cpu";
  // Then each step part's wall ms per frame (XpbdSolver::StepPart; the first frame's cook is
  // in first_frame_ms, not in a part).
  for (int p = 0; p < XpbdSolver::kStepParts; ++p) {
    std::string name = XpbdSolver::part_name(p);
    std::replace_if(
        name.begin(), name.end(), [](char ch) { return !std::isalnum(ch); }, '_');
    tc << ",part_" << name << "_ms";
  }
  tc << "\n";
  std::printf("threads  machine: %u cores, %s\n", cores, cpu.c_str());
  struct Config {
    bool dbl;
    std::string kernels;  // XpbdOptions::kernels ("": the fastest build)
    std::vector<int> threads;
  };
  std::vector<Config> configs{{false, "", tr.counts}};
  if (!tr.default_only) {
    if (std::string(xpbd::kernels().name) == "avx512") configs.push_back({false, "avx2", {1, 2}});
    configs.push_back({true, "", {1, 2}});
  }
  for (int res : tr.res) {
    if (res > max_res) continue;
    const int rounds = tr.rounds.value_or(res <= 128 ? 3 : 1);
    std::map<std::pair<int, int>, std::vector<ThreadRun>> runs;  // (config, threads)
    for (int round = 0; round < rounds; ++round)
      for (size_t c = 0; c < configs.size(); ++c)
        for (int threads : configs[c].threads)
          runs[{static_cast<int>(c), threads}].push_back(
              timed_drape(res, threads, configs[c].dbl, configs[c].kernels, frames_cap));
    auto median = [](const std::vector<ThreadRun>& v, double ThreadRun::*f) {
      std::vector<double> x;
      for (const ThreadRun& r : v) x.push_back(r.*f);
      std::sort(x.begin(), x.end());
      return x[x.size() / 2];
    };
    auto median_part = [](const std::vector<ThreadRun>& v, int p) {
      std::vector<double> x;
      for (const ThreadRun& r : v) x.push_back(r.parts[p]);
      std::sort(x.begin(), x.end());
      return x[x.size() / 2];
    };
    std::printf("threads  %4d^2 %s 10x1: %-7s %-6s %7s %10s %10s %10s %10s %8s %6s\n", res,
                kDefaultSolver, "prec", "simd", "threads", "ms/frame", "CPU ms", "steady",
                "first ms", "speedup", "eff");
    for (size_t c = 0; c < configs.size(); ++c) {
      const double one = runs.count({static_cast<int>(c), 1})
                             ? median(runs[{static_cast<int>(c), 1}], &ThreadRun::wall)
                             : 0.0;
      for (int threads : configs[c].threads) {
        const auto& v = runs[{static_cast<int>(c), threads}];
        const double wall = median(v, &ThreadRun::wall);
        const double speedup = one > 0 ? one / wall : 0.0, eff = speedup / threads;
        const char* prec = configs[c].dbl ? "double" : "single";
        std::printf(
            "threads  %4d^2 %s 10x1: %-7s %-6s %7d %10.3f %10.3f %10.3f %10.1f %7.2fx %5.0f%%\n",
            res, kDefaultSolver, prec, v[0].kernels.c_str(), threads, wall,
            median(v, &ThreadRun::cpu), median(v, &ThreadRun::steady), median(v, &ThreadRun::first),
            speedup, 100 * eff);
        tc << "form," << kDefaultSolver << "," << res << ",10," << threads << "," << cores << ","
           << prec << "," << v[0].kernels << "," << rounds << "," << wall << ","
           << median(v, &ThreadRun::cpu) << "," << median(v, &ThreadRun::steady) << ","
           << median(v, &ThreadRun::first) << "," << speedup << "," << eff << ",\"" << cpu << "\"";
        for (int p = 0; p < XpbdSolver::kStepParts; ++p) tc << "," << median_part(v, p);
        tc << std::endl;
      }
    }
    // The step's parts of the default configuration, each against its own time on one thread:
    // a part that does not speed up is serial (what limits the frame on many cores).
    std::printf("threads  %4d^2 step parts, wall ms/frame (speed-up against one thread):\n", res);
    const auto& one = runs[{0, 1}];
    for (int threads : configs[0].threads) {
      const auto& v = runs[{0, threads}];
      std::printf("threads  %4d^2 %3d:", res, threads);
      const char* sep = " ";
      for (int p = 0; p < XpbdSolver::kStepParts; ++p) {
        const double ms = median_part(v, p), base = one.empty() ? 0.0 : median_part(one, p);
        if (base < 0.005 && ms < 0.005) continue;  // (a part this scene does not run)
        std::printf("%s%s %.3f", sep, XpbdSolver::part_name(p), ms);
        if (base > 0 && ms > 0 && threads > 1) std::printf(" (%.2fx)", base / ms);
        sep = ", ";
      }
      std::printf("\n");
    }
  }
}

// The element sweep's plan on many threads, measured on one: the default solver on the form drape
// (the thread rows' scene) on a pool of one thread, its sweep planned for S slots
// (XpbdOptions::sweep_slots: the same results), each sweep's runs timed and replayed as S
// threads would run them (XpbdSolver::sweep_profile, xpbd::SweepPlan::schedule): the sweep's
// span on S threads that never wait for a time slice nor share caches or memory bandwidth, and
// what the slots spend idle (waiting for another slot before a run, after their last phase),
// beside the same runs replayed with a phase gate (gated_efficiency: no slot two phases ahead of
// another, what a plan whose waits name only the phase before needs). With
// the step's time outside the sweeps on one thread (the frame's and substeps' other work) it
// brackets the frame on S cores: that work serial, or divided by S. The MB of the arrays a sweep
// streams (XpbdSolver::sweep_megabytes) give the memory traffic a measured frame implies. CSV
// out/bench/solvers_sweep_model.csv. False (with the reason on stderr) when the default solver is
// not XPBD: it has no sweep plan to model.
bool sweep_model_rows(const ThreadRowsConfig& tr, std::optional<int> frames_cap) {
  std::ofstream mc("out/bench/solvers_sweep_model.csv");
  mc << "scene,solver,resolution,slots,frames,frame_ms,sweep_ms,other_ms,work_ms,span_ms,"
        "span_handover_ms,sweep_speedup,sweep_efficiency,wait_pct,tail_pct,"
        "handover_efficiency,gated_efficiency,frame_ms_other_serial,frame_ms_other_divided,"
        "sweep_mb\n";
  std::printf("model    %5s %5s %9s %9s %9s %9s %9s %8s %6s %6s %6s %7s %7s %10s %10s\n", "res",
              "slots", "frame ms", "sweep ms", "other ms", "work ms", "span ms", "speedup", "eff",
              "wait", "tail", "eff+ho", "gated", "fr serial", "fr divided");
  for (int res : tr.res)
    for (int slots : tr.counts) {
      if (slots < 2) continue;
      Testbed sc = make_scene("form", res);
      SolverConfig cfg;
      cfg.substeps = 10;
      cfg.threads = 1;
      cfg.air_drag = sc.air_drag;
      auto made = make_solver("default", cfg);
      XpbdSolver* xp = xpbd_of(made->get());
      if (!xp) {
        std::fprintf(stderr, "sweep model: the default solver (%s) is not XPBD: no sweep plan\n",
                     kDefaultSolver);
        return false;
      }
      xp->options().sweep_slots = slots;
      xp->options().sweep_profile = true;
      const int frames =
          std::max(2, frames_cap.value_or(static_cast<int>(std::lround(sc.duration * 90))));
      const auto w0 = std::chrono::steady_clock::now();
      for (int f = 0; f < frames; ++f) (*made)->step(sc.cloth, sc.objects, 1.0 / 90);
      const double frame = ms_since(w0) / frames, sweep = xp->sweep_ms() / frames;
      const auto& P = xp->sweep_profile();
      const double work = P.ideal.work_ns * 1e-6 / frames, span = P.ideal.span_ns * 1e-6 / frames;
      const double span_ho = P.handover.span_ns * 1e-6 / frames, other = frame - sweep;
      const double slot_ns = slots * P.ideal.span_ns;
      auto pct = [&](double ns) { return slot_ns > 0 ? 100 * ns / slot_ns : 0.0; };
      const double eff = span > 0 ? work / (slots * span) : 0.0;
      const double eff_ho = span_ho > 0 ? work / (slots * span_ho) : 0.0;
      const double span_gated = P.gated.span_ns * 1e-6 / frames;
      const double eff_gated = span_gated > 0 ? work / (slots * span_gated) : 0.0;
      std::printf(
          "model    %5d %5d %9.3f %9.3f %9.3f %9.3f %9.3f %7.2fx %5.0f%% %5.1f%% %5.1f%% %6.0f%% "
          "%6.0f%% %10.3f %10.3f\n",
          res, slots, frame, sweep, other, work, span, span > 0 ? work / span : 0.0, 100 * eff,
          pct(P.ideal.border_ns), pct(P.ideal.tail_ns), 100 * eff_ho, 100 * eff_gated, other + span,
          other / slots + span);
      const double mb = xp->sweep_megabytes(sc.cloth.num_vertices());
      std::printf("model    %5d %5d the sweep's arrays %.1f MB (%d sweeps a frame)\n", res, slots,
                  mb, static_cast<int>(std::lround(double(P.sweeps) / frames)));
      mc << "form," << kDefaultSolver << "," << res << "," << slots << "," << frames << "," << frame
         << "," << sweep << "," << other << "," << work << "," << span << "," << span_ho << ","
         << (span > 0 ? work / span : 0.0) << "," << eff << "," << pct(P.ideal.border_ns) << ","
         << pct(P.ideal.tail_ns) << "," << eff_ho << "," << eff_gated << "," << other + span << ","
         << other / slots + span << "," << mb << std::endl;
    }
  return true;
}

// Self-collision in the app's scene: the live session's solver (the default, pieces at rest
// sleeping, the static finish one cycle per tick as in a lock-step session, two threads) on the
// form drape (the muslin panel falling from the chest line, 3 s) with self-collision off and on,
// interleaved in rounds; per configuration the median over rounds of the mean and the p99 tick
// (wall ms), the self pairs at the end and the largest during the drape, and the mean share of
// the cloth's regions the detections tested (SelfCollision's region cull). CSV
// out/bench/solvers_self.csv.
void self_rows(const std::vector<int>& resolutions, int rounds, std::optional<int> frames_cap) {
  std::ofstream sc("out/bench/solvers_self.csv");
  sc << "scene,solver,resolution,threads,self_collision,rounds,ms_per_frame,p99_ms,ratio,"
        "self_pairs_end,self_pairs_max,regions_tested_pct,detections_per_frame,self_detections_per_"
        "frame,collision_ms_per_frame\n";
  std::printf("self     %6s %4s %10s %10s %8s %12s %12s %10s %8s %8s %8s\n", "res", "self",
              "ms/frame", "p99 ms", "ratio", "pairs (end)", "pairs (max)", "regions %", "det/fr",
              "self/fr", "coll ms");
  for (const int res : resolutions) {
    struct Run {
      double mean, p99;
      size_t pairs_end, pairs_max;
      double tested, detections, self_detections, collision_ms;  // per frame
    };
    std::vector<Run> runs[2];
    for (int round = 0; round < rounds; ++round)
      for (int self = 0; self < 2; ++self) {
        Testbed t = make_form_drape(res);
        t.objects.self_collision = self == 1;
        SolverConfig cfg;
        cfg.freeze = true;
        cfg.finish_thread = false;
        auto solver = make_solver(kDefaultSolver, cfg);
        Solver* inner = solver.value().get();
        if (auto* wd = dynamic_cast<WatchdogSolver*>(inner)) inner = &wd->inner();
        auto* xs = dynamic_cast<XpbdSolver*>(inner);
        const int frames = frames_cap.value_or(static_cast<int>(std::lround(t.duration * 90)));
        std::vector<double> ms;
        size_t most = 0;
        double tested = 0;  // sum over frames of the share of regions the last detection tested
        double collision_ms = 0;
        for (int f = 0; f < frames; ++f) {
          const auto t0 = std::chrono::steady_clock::now();
          collision_ms += solver.value()->step(t.cloth, t.objects, 1.0 / 90).collision_ms;
          ms.push_back(
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                  .count());
          if (xs) most = std::max(most, xs->self_collision().contacts().size());
          if (xs && xs->self_collision().regions() > 0)
            tested +=
                double(xs->self_collision().active_regions()) / xs->self_collision().regions();
        }
        double sum = 0;
        for (double m : ms) sum += m;
        std::sort(ms.begin(), ms.end());
        runs[self].push_back(
            {sum / frames, ms[std::min(ms.size() - 1, ms.size() * 99 / 100)],
             xs ? xs->self_collision().contacts().size() : 0, most, 100 * tested / frames,
             xs ? double(xs->contact_detections()) / frames : 0.0,
             xs ? double(xs->self_detections()) / frames : 0.0, collision_ms / frames});
      }
    auto median = [](std::vector<Run> v, double Run::*f) {
      std::sort(v.begin(), v.end(), [f](const Run& a, const Run& b) { return a.*f < b.*f; });
      return v[v.size() / 2].*f;
    };
    const double off = median(runs[0], &Run::mean);
    for (int self = 0; self < 2; ++self) {
      const double mean = median(runs[self], &Run::mean), p99 = median(runs[self], &Run::p99);
      const Run& last = runs[self].back();
      const double det = median(runs[self], &Run::detections),
                   self_det = median(runs[self], &Run::self_detections),
                   coll = median(runs[self], &Run::collision_ms);
      std::printf("self     %4d^2 %4s %10.3f %10.3f %7.2fx %12zu %12zu %10.1f %8.2f %8.2f %8.3f\n",
                  res, self ? "on" : "off", mean, p99, mean / off, last.pairs_end, last.pairs_max,
                  last.tested, det, self_det, coll);
      sc << "form," << kDefaultSolver << "," << res << ",2," << self << "," << rounds << "," << mean
         << "," << p99 << "," << mean / off << "," << last.pairs_end << "," << last.pairs_max << ","
         << last.tested << "," << det << "," << self_det << "," << coll << std::endl;
    }
  }
}

// A flag --name with its negation --no-name (--name=0 works too).
CLI::Option* switch_flag(CLI::App& app, const std::string& name, bool& value,
                         const std::string& help) {
  return app.add_flag("--" + name + ",!--no-" + name, value,
                      help + (value ? " (default: on)" : " (default: off)"));
}

// Every knob of the benchmark grid and the probe as a flag; the environment variables they replace
// are in the table at the top of this file.
void add_knobs(CLI::App& app, Knobs& kn, std::string& simd) {
  const auto count = CLI::Range(0, 1000000);
  const auto positive = CLI::Range(1, 1000000);
  const auto non_negative = CLI::Range(0.0, 1e9);
  app.option_defaults()->always_capture_default();
  // The benchmark grid.
  app.option_defaults()->group("Benchmark grid");
  app.add_flag("--quick", kn.quick,
               "the quick grid (./drape bench solvers' default; a few minutes)");
  app.add_option("--max-res", kn.max_res,
                 "the full grid's largest form resolution (64: 64^2 scored; 128: and 128^2 timed, "
                 "the thread rows; 256: and 256^2 timed)")
      ->check(CLI::Range(16, 4096));
  app.add_flag("--sleep-only", kn.sleep_only,
               "only the sleeping rows (out/bench/solvers_sleep.csv)");
  app.add_flag("--threads-only", kn.threads_only,
               "only the thread and precision rows (out/bench/solvers_threads.csv)");
  app.add_flag("--self-only", kn.self_only,
               "only the self-collision rows: the app's scene with it off and on, 64^2 and "
               "--max-res (out/bench/solvers_self.csv)");
  app.add_flag("--sweep-model", kn.sweep_model,
               "only the sweep model: the element sweep planned for each --thread-counts count "
               "above 1, timed on one thread and replayed on that many, at each --thread-res "
               "(out/bench/solvers_sweep_model.csv)");
  app.add_option("--thread-counts", kn.thread_rows.counts,
                 "the thread rows' thread counts (the default configuration; 1,2,4)")
      ->delimiter(',')
      ->check(CLI::Range(1, 64));
  app.add_option("--thread-res", kn.thread_rows.res, "the thread rows' form resolutions (128,256)")
      ->delimiter(',')
      ->check(CLI::Range(2, 1024));
  app.add_option("--thread-rounds", kn.thread_rows.rounds,
                 "the thread rows' rounds, each row the median (default: 3 up to 128^2, 1 above)")
      ->check(CLI::Range(1, 100));
  app.add_flag("--threads-default-only", kn.thread_rows.default_only,
               "the thread rows without the double-precision and AVX2 rows");
  app.add_option("--simd", simd,
                 "the widest SIMD build XPBD's kernels may use: none (portable), avx2, widest "
                 "(the CPU's widest: avx512 where it has it)")
      ->check(CLI::Validator(
          [](std::string& v) {
            return xpbd::parse_simd_limit(v) ? std::string() : "expected none, avx2 or widest";
          },
          "none|avx2|widest"));
  app.add_option("--threads", kn.threads,
                 "solver threads (default: 1 in the benchmark grid, 2 in --probe, 1 in the pool of "
                 "--finish)")
      ->check(CLI::Range(1, 256));
  app.add_option("--ref-iters", kn.ref_iters,
                 "at most so many Newton iterations in the static polish (default 300) and in "
                 "the contact scenes' static reference after settling (default 150)")
      ->check(positive);
  app.add_option("--ref-settle-frames", kn.ref_settle_frames,
                 "frames VBD settles a contact scene before its static reference")
      ->check(count);
  app.add_option("--sleep-ref-iters", kn.sleep_ref_iters,
                 "Newton iterations of the polish that scores the sleep rows' settled drape")
      ->check(positive);
  switch_flag(app, "polish-friction", kn.polish_friction,
              "the static polish finds the frictional equilibrium (the objects' mu); "
              "--no-polish-friction: the frictionless one");
  switch_flag(app, "polish-reuse", kn.polish_reuse,
              "the static polish reuses a stale factorisation (CG on it)");
  app.add_option("--polish-cg-max", kn.polish_cg_max,
                 "CG iterations per system on a stale factorisation in the static polish")
      ->check(count);
  app.add_option("--polish-cg-tol", kn.polish_cg_tol,
                 "relative residual of CG on a stale factorisation in the static polish")
      ->check(non_negative);
  // The probe.
  app.option_defaults()->group("Probe");
  app.add_option("--probe", kn.probe,
                 "run one configuration: SCENE (chain, sheet, form, sphere, cantilever), RES "
                 "(cloth resolution), SOLVER (vbd, xpbd, newton, verlet, default), SUBSTEPS, "
                 "ITERATIONS; prints wall and CPU time per frame and the error every 0.1 s")
      ->type_name("SCENE RES SOLVER SUBSTEPS ITERATIONS")
      ->default_str("");
  app.add_option("--frames", kn.frames, "frames to step (default: the scene's duration)")
      ->check(count);
  switch_flag(app, "ref", kn.ref,
              "compare the progress lines with the scene's static reference; --no-ref: with "
              "the start state (skips computing the reference)");
  switch_flag(app, "polish", kn.polish,
              "score the end state of a form or sphere drape against the equilibrium nearest "
              "to it (static polish); --no-polish skips it");
  app.add_option("--friction", kn.friction,
                 "the objects' friction coefficient (default: the scene's)")
      ->check(non_negative);
  app.add_option("--load", kn.load,
                 "start from a state --save wrote (same scene and resolution); with --frames 0: "
                 "only score it")
      ->check(CLI::ExistingFile);
  app.add_option("--save", kn.save, "write the end state (positions, velocities) to this file");
  app.add_option("--save-polished", kn.save_polished,
                 "write the equilibrium nearest to the end state (velocities zero) to this file");
  app.add_flag("--drift", kn.drift, "print how far the end state is from the start state");
  app.add_option("--polish-steps", kn.polish_steps,
                 "comma-separated Newton iteration counts: how close a polish of so many "
                 "iterations gets to the equilibrium, and its cost")
      ->delimiter(',')
      ->check(positive)
      ->default_str("");
  app.add_option("--smooth", kn.smooth,
                 "passes of neighbour averaging of the error field (its smooth part and the rest "
                 "are printed)")
      ->check(count);
  app.add_option("--coarse-only", kn.coarse_only,
                 "coarse corrections of the end state alone, contacts detected before each")
      ->check(count);
  app.add_option("--coarse-k", kn.coarse_k, "contact stiffness (N/m) of --coarse-only's energy")
      ->check(non_negative);
  app.add_option("--coarse-factor", kn.coarse_factor,
                 "fine edges per coarse lattice cell in --coarse-only (default 4) and --finish "
                 "(default 0)")
      ->check(count);
  app.add_flag_function(
      "--coarse-rot,!--no-coarse-rot", [&kn](std::int64_t n) { kn.coarse_rot = n > 0; },
      "rotations in the coarse space of --coarse-only (default off) and --finish (default on)");
  switch_flag(app, "coarse-mu", kn.coarse_mu,
              "friction (the objects' mu) in --coarse-only's energy");
  app.add_option("--mg-aa", kn.mg_aa,
                 "Anderson acceleration of --coarse-only's cycles over the last so many")
      ->check(count);
  app.add_option("--mg-sweeps", kn.mg_sweeps,
                 "Gauss-Seidel sweeps of per-vertex Newton steps before each coarse correction")
      ->check(count);
  app.add_option("--mg-tau", kn.mg_tau, "time step (s) of the inertia term in --mg-sweeps' steps")
      ->check(CLI::PositiveNumber);
  app.add_flag("--mg-nocoarse", kn.mg_nocoarse, "--mg-sweeps alone, without the coarse step");
  app.add_option("--mg-refresh", kn.mg_refresh,
                 "factorise the coarse matrix every so many corrections (reuse it in between)")
      ->check(positive);
  app.add_option("--finish", kn.finish,
                 "the static finish of the end state: at most so many cycles")
      ->check(count);
  app.add_option("--finish-sweeps", kn.finish_sweeps, "Gauss-Seidel sweeps per --finish cycle")
      ->check(count);
  app.add_option("--finish-extra", kn.finish_extra,
                 "largest extrapolation along a --finish cycle's displacement (cycles; 0: none)")
      ->check(non_negative);
  // The probe's VBD solver.
  app.option_defaults()->group("Probe: VBD");
  app.add_option("--vbd-init", kn.vbd_init,
                 "initial guess: 0 inertia, 1 inertia and gravity, 2 adaptive")
      ->check(CLI::Range(0, 2));
  app.add_option("--vbd-rho", kn.vbd_rho, "Chebyshev acceleration's rho (0: off)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--vbd-damp", kn.vbd_damp, "VBD's damping")->check(non_negative);
  app.add_option("--vbd-air", kn.vbd_air, "air damping (1/s; default: the scene's, else 1)")
      ->check(non_negative);
  app.add_flag("--vbd-freeze,!--no-vbd-freeze", kn.vbd_freeze, "freeze vertices at rest");
  app.add_option("--vbd-tol", kn.vbd_tol, "VBD's tolerance")->check(non_negative);
  app.add_option("--vbd-ftol", kn.vbd_ftol, "VBD's force tolerance")->check(non_negative);
  app.add_option("--vbd-threads", kn.vbd_threads, "VBD's threads")->check(CLI::Range(1, 256));
  // The probe's XPBD solver.
  app.option_defaults()->group("Probe: XPBD (unset: the solver's own value)");
  app.add_option("--xpbd-warm", kn.xpbd_warm, "warm start of the constraint multipliers (0-1)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--xpbd-warm-frame", kn.xpbd_warm_frame,
                 "from this frame on the warm start is --xpbd-warm-late (-1: never)")
      ->check(CLI::Range(-1, 1000000));
  app.add_option("--xpbd-warm-late", kn.xpbd_warm_late, "the warm start from --xpbd-warm-frame on")
      ->check(CLI::Range(0.0, 1.0));
  switch_flag(app, "xpbd-reuse", kn.xpbd_reuse,
              "reuse contacts (detect again only after half the margin of motion)");
  app.add_option("--xpbd-bend-every", kn.xpbd_bend_every, "project bending every so many substeps")
      ->check(positive);
  switch_flag(app, "xpbd-retest", kn.xpbd_retest, "test the vertices that moved again");
  switch_flag(app, "xpbd-settle", kn.xpbd_settle, "settle pieces at rest");
  switch_flag(app, "xpbd-freeze", kn.xpbd_freeze, "freeze (sleep) pieces at rest");
  app.add_option("--xpbd-settle-scale", kn.xpbd_settle_scale,
                 "the largest inertia scale of a settling piece")
      ->check(CLI::Range(1.0, 1e9));
  app.add_option("--xpbd-settle-damp", kn.xpbd_settle_damp, "damping of a settled piece (1/s)")
      ->check(non_negative);
  app.add_option("--xpbd-snap", kn.xpbd_snap, "contact snap depth (m)")->check(non_negative);
  app.add_option("--xpbd-sleep-steps", kn.xpbd_sleep_steps,
                 "substeps at full inertia scale before a settled piece sleeps")
      ->check(count);
  app.add_option("--xpbd-settle-speed", kn.xpbd_settle_speed,
                 "speed (m/s) below which a piece begins to settle")
      ->check(non_negative);
  app.add_option("--xpbd-settle-growth", kn.xpbd_settle_growth,
                 "growth of a settling piece's inertia per step")
      ->check(CLI::Range(1.0, 1e9));
  app.add_option("--xpbd-coarse", kn.xpbd_coarse,
                 "coarse correction of settled pieces: fine edges per coarse cell (0: off)")
      ->check(count);
  app.add_option("--xpbd-coarse-frames", kn.xpbd_coarse_frames,
                 "frames of coarse corrections after a piece has settled")
      ->check(count);
  switch_flag(app, "xpbd-coarse-rot", kn.xpbd_coarse_rot, "rotations in the coarse space");
  switch_flag(app, "xpbd-finish", kn.xpbd_finish, "the static finish of sleeping pieces");
  app.add_option("--xpbd-finish-cycles", kn.xpbd_finish_cycles, "at most so many finish cycles")
      ->check(count);
  switch_flag(app, "xpbd-finish-thread", kn.xpbd_finish_thread,
              "the static finish on a thread of its own");
  switch_flag(app, "xpbd-f32", kn.xpbd_f32,
              "single-precision kernels; --no-xpbd-f32: double precision");
  app.add_option("--xpbd-kernels", kn.xpbd_kernels,
                 "the kernels' build by name (default: the fastest this CPU runs)")
      ->check(CLI::IsMember({"portable", "avx2", "avx512"}));
}

}  // namespace

int main(int argc, char** argv) {
  Knobs kn;
  std::string simd;
  CLI::App app{
      "The solver benchmark: solver x substeps x iterations x resolution on the shared scenes "
      "(out/bench/solvers*.csv, .svg), or one configuration (--probe)."};
  add_knobs(app, kn, simd);
  CLI11_PARSE(app, argc, argv);
  // Before any solver is made (kernels() chooses once).
  if (!simd.empty()) xpbd::limit_simd(*xpbd::parse_simd_limit(simd));
  if (app.count("--probe") > 0) return probe(kn);
  const bool quick = kn.quick;
  const int max_res = kn.max_res;
  std::filesystem::create_directories("out/bench");
  if (kn.sleep_only) {  // the sleeping rows alone (out/bench/solvers_sleep.csv)
    sleep_rows(kn, quick ? 32 : 128);
    return 0;
  }
  if (kn.self_only) {  // the self-collision rows alone (out/bench/solvers_self.csv)
    self_rows({64, std::max(max_res, 128)}, kn.thread_rows.rounds.value_or(3), kn.frames);
    return 0;
  }
  if (kn.sweep_model) {  // the sweep's plan on many threads, measured on one
    return sweep_model_rows(kn.thread_rows, kn.frames) ? 0 : 1;
  }
  if (kn.threads_only) {  // the thread and precision rows alone (out/bench/solvers_threads.csv)
    thread_rows(std::max(max_res, 256), kn.thread_rows, kn.frames);
    return 0;
  }
  std::vector<Row> rows;
  struct Job {
    std::string scene;
    int res;
    std::vector<Config> configs;
    bool error = true;  // false: time only (256^2)
  };
  // "xpbd" settles pieces at rest (the default); "xpbd-nosettle" is the same solver without it,
  // side by side.
  std::vector<Config> full{{"vbd", 1, 5},
                           {"vbd", 1, 10},
                           {"vbd", 2, 10},
                           {"vbd", 2, 20},
                           {"vbd", 4, 20},
                           {"xpbd", 5, 1},
                           {"xpbd", 10, 1},
                           {"xpbd", 20, 1},
                           {"xpbd", 40, 1},
                           {"xpbd-nosettle", 5, 1},
                           {"xpbd-nosettle", 10, 1},
                           {"xpbd-nosettle", 20, 1},
                           {"xpbd-nosettle", 40, 1},
                           {"verlet", 0, 1}};
  // Quick mode (the default of ./drape bench solvers): a few minutes. VBD's iteration count
  // is a maximum (early stop on the residual).
  std::vector<Config> quick_cfg{{"vbd", 1, 5},     {"vbd", 1, 10},  {"vbd", 2, 20},
                                {"vbd", 4, 20},    {"xpbd", 10, 1}, {"xpbd", 40, 1},
                                {"newton", 1, 20}, {"verlet", 0, 1}};
  std::vector<Job> jobs;
  const std::vector<Config> form_cfg{{"vbd", 1, 5},   {"vbd", 2, 10},  {"vbd", 4, 20},
                                     {"xpbd", 10, 1}, {"xpbd", 20, 1}, {"xpbd", 40, 1},
                                     {"verlet", 0, 1}};
  if (quick) {
    jobs = {{"chain", 20, quick_cfg}, {"sheet", 16, quick_cfg}, {"form", 16, form_cfg}};
  } else {
    jobs = {{"chain", 20, full}, {"sheet", 16, full}, {"form", 16, full},
            {"sheet", 32, full}, {"form", 32, full},  {"sphere", 32, full}};
    // 64^2 scored (the static polish takes ~30 s per state there, docs/solvers.md "Static
    // solver speed"), with the explicit baseline (~50 s of stepping).
    const std::vector<Config> big{{"vbd", 1, 5}, {"xpbd", 10, 1}, {"xpbd", 20, 1}};
    std::vector<Config> b64 = big;
    b64.push_back({"xpbd", 5, 1});
    b64.push_back({"xpbd-nosettle", 10, 1});
    b64.push_back({"xpbd", 40, 1});
    b64.push_back({"verlet", 0, 1});
    if (max_res >= 64) jobs.push_back({"form", 64, b64, true});
    // 128^2 timed only: at 3 s its drape is still moving (its last wrinkles stop at ~4.5 s),
    // ~80 mm from any equilibrium, and the polish from there does not converge in 150
    // iterations (7.5 min). The settled 128^2 drape is scored in the sleep section below.
    if (max_res >= 128) jobs.push_back({"form", 128, big, false});
    if (max_res >= 256) jobs.push_back({"form", 256, {{"xpbd", 10, 1}}, false});
  }
  const std::string default_solver = kDefaultSolver;  // make_solver("default")
  std::ofstream csv("out/bench/solvers.csv");
  csv << "scene,solver,resolution,dt,iterations,ms_per_frame,rms_error_mm,max_error_mm,stable\n";
  for (const auto& j : jobs) {
    const std::vector<Vec3> ref =
        path_dependent(j.scene) || !j.error ? std::vector<Vec3>{} : reference(kn, j.scene, j.res);
    for (const auto& c : j.configs) {
      Row r = run(kn, j.scene, j.res, c, ref, j.error);
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
    if (j.scene == "sheet") {
      // The peer (bench/bullet_peer.*): Bullet's soft body on the same sheet, CPU-timed here.
      for (const auto& [ns, it] : std::vector<std::pair<int, int>>{{10, 1}, {40, 1}, {20, 4}}) {
        const double c0 = cpu_ms();
        drape::bench::PeerRow p = drape::bench::run_bullet_sheet(j.res, ns, it);
        const double cpu = cpu_ms() - c0;
        if (p.positions.size() != ref.size()) {
          std::printf("sheet    %4d bullet  %dx%d: not available (built without Bullet)\n", j.res,
                      ns, it);
          break;
        }
        std::vector<Vec3> px(p.positions.begin(), p.positions.end());
        double rms = 0, mx = 0;
        position_error(px, ref, rms, mx);
        const int frames = static_cast<int>(std::lround(make_scene("sheet", j.res).duration * 90));
        Row r{"sheet", "bullet", j.res, p.dt, it, cpu / frames, rms * 1e3, mx * 1e3, p.stable};
        std::printf("%-8s %4d %-7s dt %.5f it %2d: %8.3f ms/frame  rms %8.3f mm  max %8.3f mm %s\n",
                    r.scene.c_str(), r.resolution, r.solver.c_str(), r.dt, r.iterations,
                    r.ms_per_frame, r.rms_mm, r.max_mm, r.stable ? "" : "UNSTABLE");
        std::fflush(stdout);
        rows.push_back(r);
        csv << r.scene << "," << r.solver << "," << r.resolution << "," << r.dt << ","
            << r.iterations << "," << r.ms_per_frame << "," << r.rms_mm << "," << r.max_mm << ","
            << (r.stable ? 1 : 0) << std::endl;
      }
    }
  }
  sleep_rows(kn, quick ? 32 : 128);
  // Switches of "skip what a scene doesn't need", on and off: XPBD 10x1 on the form scene with
  // contact reuse (detection only after half the margin of motion) on/off, and self-collision
  // (spatial hash) off/on; CPU ms per frame, detections per frame, self pairs at the end.
  {
    const int kres = quick ? 32 : 64;
    std::ofstream kc("out/bench/solvers_skip.csv");
    kc << "scene,solver,resolution,switch,on,ms_per_frame,detections_per_frame,self_pairs\n";
    struct Sw {
      const char* name;
      bool on, reuse, self;
    };
    for (const Sw& sw :
         {Sw{"contact_reuse", true, true, false}, Sw{"contact_reuse", false, false, false},
          Sw{"self_collision", false, true, false}, Sw{"self_collision", true, true, true}}) {
      Testbed sc = make_scene("form", kres);
      sc.objects.self_collision = sw.self;
      XpbdOptions o;
      o.substeps = 10;
      o.threads = 1;
      o.air_drag = sc.air_drag;
      o.reuse_contacts = sw.reuse;
      XpbdSolver s(o);
      const int frames = static_cast<int>(std::lround(sc.duration * 90));
      const double c0 = cpu_ms();
      for (int f = 0; f < frames; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
      const double ms = (cpu_ms() - c0) / frames;
      const double det = double(s.contact_detections()) / frames;
      const int pairs = static_cast<int>(s.self_collision().contacts().size());
      std::printf(
          "skip     %4d xpbd 10x1 %-14s %-3s: %8.3f ms/frame, %.2f detections/frame, %d "
          "self pairs\n",
          kres, sw.name, sw.on ? "on" : "off", ms, det, pairs);
      kc << "form,xpbd," << kres << "," << sw.name << "," << (sw.on ? 1 : 0) << "," << ms << ","
         << det << "," << pairs << std::endl;
    }
  }
  if (!quick && max_res >= 128) thread_rows(max_res, kn.thread_rows, kn.frames);
  int top = 0;  // the chart: the finest form resolution that is scored (not time only)
  for (const auto& j : jobs)
    if (j.scene == "form" && j.error) top = std::max(top, j.res);
  write_svg(rows, "form", top, "out/bench/solvers.svg");
  write_svg(rows, "sheet", quick ? 16 : 32, "out/bench/solvers_sheet.svg");
  // Summary: time at equal error. For each scene, the fastest stable configuration of every
  // solver reaching <= 1 mm RMS, and <= the explicit baseline's (best) error; ratios of the
  // default solver's time to the others'.
  std::printf(
      "\nSummary: CPU ms per 1/90 s frame of the fastest stable configuration at equal "
      "RMS error\n");
  auto best = [&](const Job& j, const std::string& solver, double err) -> const Row* {
    const Row* b = nullptr;
    for (const auto& r : rows)
      if (r.scene == j.scene && r.resolution == j.res && r.solver == solver && r.stable &&
          r.rms_mm <= err && (!b || r.ms_per_frame < b->ms_per_frame))
        b = &r;
    return b;
  };
  for (const auto& j : jobs) {
    const Row* ex = best(j, "verlet", 1e30);
    std::vector<double> targets{1.0};
    if (ex) targets.push_back(ex->rms_mm * 1.0001);
    for (double e : targets) {
      std::printf("%-7s %4d at <= %.3g mm:", j.scene.c_str(), j.res, e);
      const Row* d = best(j, default_solver, e);
      for (const char* name : {"vbd", "xpbd", "xpbd-nosettle", "newton", "verlet", "bullet"}) {
        const Row* r = best(j, name, e);
        if (r)
          std::printf("  %s %.3g ms", name, r->ms_per_frame);
        else
          std::printf("  %s -", name);
      }
      std::printf("\n");
      for (const char* peer : {"verlet", "bullet", "xpbd-nosettle"}) {
        const Row* p = best(j, peer, e);
        if (d && p)
          std::printf("    ratio %s / %s (default) = %.2fx\n", peer, default_solver.c_str(),
                      p->ms_per_frame / d->ms_per_frame);
        else if (p)
          std::printf("    ratio %s / %s: %s does not reach this error in the grid\n", peer,
                      default_solver.c_str(), default_solver.c_str());
      }
    }
  }
  std::printf("wrote out/bench/solvers.csv, out/bench/solvers.svg\n");
  return 0;
}
