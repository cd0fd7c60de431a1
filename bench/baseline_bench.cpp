// Baseline benchmark: the explicit mass-spring + damped Verlet with dress-form collision at
// 21^2, 42^2, 81^2 and 128^2. Measures ms of compute per 1/90 s frame,
// the largest stable dt at muslin stiffness (bisection) and the substeps per frame it implies,
// and the section-lookup collision cost per vertex. Writes out/bench/baseline.csv.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include "sim/form/dress_form.hpp"
#include "sim/solvers/verlet_solver.hpp"
#include "sim/testbeds/drop_testbed.hpp"

namespace {

using namespace drape::sim;
using Clock = std::chrono::steady_clock;

// CPU time of the calling thread (ms): the compute a frame costs, independent of how many other
// processes share the machine (wall time is reported beside it).
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

constexpr int kSizes[] = {21, 42, 81, 128};
constexpr double kFrame = 1.0 / 90;
constexpr double kPanel = 0.4;  // m: a 0.4 m x 0.4 m muslin panel at every resolution

struct Row {
  double ms_per_frame = NAN, wall_ms_per_frame = NAN, max_stable_dt = NAN, collision_ns = NAN;
  int auto_substeps = 0;
};
std::map<int, Row> g_rows;

std::shared_ptr<const DressForm> form_9ar() {
  static std::shared_ptr<const DressForm> f = [] {
    auto r = DressForm::from_measurements(FormMeasurements{});
    if (!r) {
      std::fprintf(stderr, "baseline_bench: %s\n", r.error().c_str());
      std::exit(1);
    }
    return std::make_shared<const DressForm>(std::move(r.value()));
  }();
  return f;
}

// The standard drop scene (sim/testbeds/drop_testbed.hpp, the same as
// tests/sim/testbeds/drop_testbed_test.cpp): the panel held at its top edge above the bust,
// released horizontal, swinging down against the form.
Cloth front_panel(int n) {
  return make_front_drop(form_9ar(), n, kPanel).cloth;
}

SceneObjects form_scene() {
  return make_front_drop(form_9ar(), 2, kPanel).scene;
}

// ms of compute per 1/90 s of simulated time, substeps chosen automatically (Gershgorin bound,
// safety 0.9), after 30 frames (1/3 s) of the drop, when the panel has swung against the form.
// At 81^2 and 128^2 (seconds per frame) only 3 frames are run first: the cost per frame does not
// depend on the contacts (every vertex is looked up in every substep either way).
void BM_BaselineFrame(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  Cloth c = front_panel(n);
  SceneObjects scene = form_scene();
  VerletSolver solver{VerletParams{}};
  const int warm = n <= 42 ? 30 : 3;
  for (int k = 0; k < warm; ++k) solver.step(c, scene, kFrame);
  double total_ms = 0, wall_ms = 0, coll_ms = 0;
  int frames = 0, substeps = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    const double c0 = thread_cpu_ms();
    StepStats st = solver.step(c, scene, kFrame);
    total_ms += thread_cpu_ms() - c0;
    wall_ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    coll_ms += st.collision_ms;
    substeps = st.substeps;
    ++frames;
    benchmark::DoNotOptimize(c.state.x.data());
  }
  state.counters["substeps"] = substeps;
  state.counters["collision_ms"] = coll_ms / frames;
  state.SetItemsProcessed(static_cast<int64_t>(frames) * substeps * c.num_vertices());
  g_rows[n].ms_per_frame = total_ms / frames;
  g_rows[n].wall_ms_per_frame = wall_ms / frames;
  g_rows[n].auto_substeps = substeps;
}

// Section-lookup collision (DressForm::push_outside through the Collider) per vertex, on a cloth
// in the drop scene's panel, laid around the front of the form (half the vertices in contact).
void BM_FormCollision(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  Cloth c = front_panel(n);
  SceneObjects scene = form_scene();
  scene.floor = false;
  // The panel laid around the front of the form (about +-75 degrees, from the hinge height
  // down), alternate vertices 2 mm inside and 2 mm outside the offset shell: half in contact.
  const DressForm& f = *scene.form;
  DropTestbed d = make_front_drop(form_9ar(), n, kPanel);
  for (int i = 0; i < c.num_vertices(); ++i) {
    const Vec2& m = c.topo.material[i];
    const double y = d.hinge_y - 0.9 * (kPanel - m.y());
    const double th = (m.x() - kPanel / 2) / 0.15;
    const Vec2 ctr = f.centre_at(y);
    const double r = f.radius_at(y, th) + scene.offset + (i % 2 ? 0.002 : -0.002);
    c.state.x[i] = Vec3(ctr.x() + r * std::sin(th), y, ctr.y() + r * std::cos(th));
  }
  Collider col;
  ClothState work = c.state;
  double ns = 0;
  int64_t verts = 0;
  for (auto _ : state) {
    state.PauseTiming();
    std::copy(c.state.x.begin(), c.state.x.end(), work.x.begin());
    state.ResumeTiming();
    const double c0 = thread_cpu_ms();
    CollisionStats cs = col.project(work, scene);
    ns += 1e6 * (thread_cpu_ms() - c0);
    verts += c.num_vertices();
    benchmark::DoNotOptimize(cs);
  }
  state.SetItemsProcessed(verts);
  g_rows[n].collision_ns = ns / static_cast<double>(verts);
}

// Stability at a fixed substep h: the panel hanging from its top edge, released flat with a
// random perturbation of 0.2 % of the grid spacing (exciting every mode with the same strain at
// every resolution), 1500 substeps without collision. Stable when the state stays finite, no
// spring stretches beyond 50 % and the kinetic energy stays below the potential energy the cloth
// could release by falling 1 m plus twice the elastic energy of the initial perturbation.
bool stable_at(int n, double h) {
  PanelSpec spec;
  spec.width = spec.height = kPanel;
  spec.nx = spec.ny = n;
  Cloth c = make_panel(spec, FabricParams{});
  place_spread(c, Vec3(0, 1.5, 0), Vec3::UnitX(), Vec3::UnitZ());
  std::mt19937 rng(7);
  const double amp = 2e-3 * kPanel / (n - 1);
  std::uniform_real_distribution<double> u(-amp, amp);
  for (auto& p : c.state.x) p += Vec3(u(rng), u(rng), u(rng));
  c.state.x_prev = c.state.x;
  const int nx = c.topo.grid_nx;
  for (int i = 0; i < nx; ++i) c.state.flags[(c.topo.grid_ny - 1) * nx + i] |= kFlagPinned;
  c.relump_masses();
  VerletParams p;
  p.substeps = 1;
  p.collide = false;
  p.rollback_on_divergence = false;
  VerletSolver s(p);
  SceneObjects none;
  none.floor = false;
  double mass = 0;
  for (double m : c.state.mass) mass += m;
  s.cook(c);
  double e0 = 0;
  {
    const Springs& sp = s.springs();
    for (int q = 0; q < sp.size(); ++q) {
      const double dl = (c.state.x[sp.b[q]] - c.state.x[sp.a[q]]).norm() - sp.rest[q];
      e0 += 0.5 * sp.k[q] * dl * dl;
    }
  }
  const double e_max = mass * kGravity * 1.0 + 2.0 * e0;
  for (int k = 0; k < 1500; ++k) {
    s.step(c, none, h);
    if (k % 100 == 99 || k == 1499) {
      double ke = 0;
      for (int i = 0; i < c.num_vertices(); ++i) {
        if (!c.state.x[i].allFinite()) return false;
        ke += 0.5 * c.state.mass[i] * c.state.v[i].squaredNorm();
      }
      if (!(ke < e_max)) return false;
      const Springs& sp = s.springs();
      for (int q = 0; q < sp.size(); ++q) {
        if ((c.state.x[sp.b[q]] - c.state.x[sp.a[q]]).norm() > 1.5 * sp.rest[q]) return false;
      }
    }
  }
  return true;
}

double max_stable_dt(int n) {
  double lo = 1e-7, hi = 1e-3;  // stable, unstable
  if (!stable_at(n, lo)) return NAN;
  while (hi / lo > 1.01) {  // bisection in log space to 1 %
    const double mid = std::sqrt(lo * hi);
    (stable_at(n, mid) ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace

BENCHMARK(BM_BaselineFrame)
    ->Arg(21)
    ->Arg(42)
    ->Arg(81)
    ->Arg(128)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);
BENCHMARK(BM_FormCollision)->Arg(21)->Arg(42)->Arg(81)->Arg(128)->Unit(benchmark::kMicrosecond);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  std::printf("\nbisection of the largest stable dt (muslin, %.1f m panel)...\n", kPanel);
  for (int n : kSizes) {
    g_rows[n].max_stable_dt = max_stable_dt(n);
    std::printf("  %3d^2: %.3e s\n", n, g_rows[n].max_stable_dt);
  }
  std::filesystem::create_directories("out/bench");
  std::ofstream csv("out/bench/baseline.csv");
  csv << "resolution,ms_per_frame,max_stable_dt,substeps_per_frame,collision_ns_per_vertex\n";
  std::printf(
      "\nbaseline (explicit mass-spring + damped Verlet, 9AR form collision), 1/90 s frames\n"
      "(ms/frame and collision: CPU time of the thread; wall ms under the machine's load beside)\n"
      "%-10s %12s %12s %10s %14s %10s %12s %14s %10s\n",
      "resolution", "ms/frame", "wall ms", "x 21^2", "max stable dt", "substeps", "auto substeps",
      "coll ns/vert", "real time?");
  const double base = g_rows[21].ms_per_frame;
  for (int n : kSizes) {
    const Row& r = g_rows[n];
    const int sub =
        std::isfinite(r.max_stable_dt) ? static_cast<int>(std::ceil(kFrame / r.max_stable_dt)) : -1;
    csv << n << "," << r.ms_per_frame << "," << r.max_stable_dt << "," << sub << ","
        << r.collision_ns << "\n";
    std::printf("%-10s %12.3f %12.3f %10.1f %14.3e %10d %12d %14.2f %10s\n",
                (std::to_string(n) + "^2").c_str(), r.ms_per_frame, r.wall_ms_per_frame,
                r.ms_per_frame / base, r.max_stable_dt, sub, r.auto_substeps, r.collision_ns,
                r.ms_per_frame <= 1000.0 * kFrame ? "yes" : "no");
  }
  std::printf("wrote out/bench/baseline.csv\n");
  return 0;
}
