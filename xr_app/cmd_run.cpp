// `drape run`: the headless main job until the XR app exists. Builds the 9AR form, drops a
// muslin panel over its shoulders on the simulation thread (lock step, or real time), then
// writes the draped cloth and the form as glTF and prints where, with the max penetration.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>

#include "sim/dress_form.hpp"
#include "sim/mesh_io.hpp"
#include "sim/sim_thread.hpp"
#include "sim/verlet_solver.hpp"
#include "xr_app/command.hpp"

namespace {

using namespace drape::sim;

void usage() {
  std::printf(
      "usage: drape run [--seconds S] [--out DIR] [--resolution N] [--fabric NAME]\n"
      "                 [--size 9AR] [--realtime] [--stiffness-scale K]\n"
      "Drops a 0.6 m x 0.7 m panel (N vertices across, default 31: 2 cm) over the dress form's\n"
      "shoulders, its centre pinned above the neck, and simulates S seconds (default 3) with the\n"
      "baseline solver (the study's mass-spring + damped Verlet, substeps chosen for stability)\n"
      "on the 90 Hz simulation thread, in lock step (default) or real time. Writes\n"
      "DIR/drape_cloth.gltf and DIR/dress_form.gltf (default DIR: out).\n");
}

std::string fabrics_path() {
  if (std::filesystem::exists("assets/fabrics.json")) return "assets/fabrics.json";
  return std::string(DRAPE_SOURCE_DIR) + "/assets/fabrics.json";
}

int run(int argc, char** argv) {
  double seconds = 3.0, stiffness_scale = 1.0;
  std::string out = "out", fabric_name = "muslin", size = "9AR";
  int resolution = 31;
  bool realtime = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&](const char* what) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "drape run: %s needs a value\n", what);
        std::exit(2);
      }
      return argv[++i];
    };
    char* end = nullptr;
    if (a == "--help" || a == "-h") {
      usage();
      return 0;
    } else if (a == "--seconds") {
      seconds = std::strtod(next("--seconds"), &end);
      if (*end || !(seconds > 0 && seconds < 3600)) {
        std::fprintf(stderr, "drape run: --seconds must be a number in (0, 3600)\n");
        return 2;
      }
    } else if (a == "--out") {
      out = next("--out");
    } else if (a == "--resolution") {
      resolution = static_cast<int>(std::strtol(next("--resolution"), &end, 10));
      if (*end || resolution < 3 || resolution > 400) {
        std::fprintf(stderr, "drape run: --resolution must be an integer in [3, 400]\n");
        return 2;
      }
    } else if (a == "--fabric") {
      fabric_name = next("--fabric");
    } else if (a == "--size") {
      size = next("--size");
    } else if (a == "--stiffness-scale") {
      stiffness_scale = std::strtod(next("--stiffness-scale"), &end);
      if (*end || !(stiffness_scale > 0 && stiffness_scale <= 10)) {
        std::fprintf(stderr, "drape run: --stiffness-scale must be in (0, 10]\n");
        return 2;
      }
    } else if (a == "--realtime") {
      realtime = true;
    } else {
      std::fprintf(stderr, "drape run: unknown option '%s'\n", a.c_str());
      usage();
      return 2;
    }
  }

  auto fabric = load_fabric(fabrics_path(), fabric_name);
  if (!fabric) {
    std::fprintf(stderr, "drape run: %s\n", fabric.error().c_str());
    return 1;
  }
  auto meas = measurements_for_size(size);
  if (!meas) {
    std::fprintf(stderr, "drape run: %s\n", meas.error().c_str());
    return 1;
  }
  auto form = DressForm::from_measurements(*meas);
  if (!form) {
    std::fprintf(stderr, "drape run: %s\n", form.error().c_str());
    return 1;
  }

  World world;
  world.scene.form = std::make_shared<const DressForm>(std::move(form.value()));
  world.scene.offset = 0.003;
  const DressForm& f = *world.scene.form;
  const double width = 0.6, height = 0.7;
  PanelSpec spec;
  spec.width = width;
  spec.height = height;
  spec.nx = resolution;
  spec.ny = std::max(3, static_cast<int>(std::lround((resolution - 1) * height / width)) + 1);
  world.cloth = make_panel(spec, *fabric);
  // Spread horizontally 1 cm above the top of the form, weft across the shoulders (x), warp
  // front to back (z) so the grain hangs vertically at centre front and back.
  const Vec2 top = f.centre_at(f.max_y());
  place_spread(world.cloth, Vec3(top.x() - width / 2, f.max_y() + 0.01, top.y() - height / 2),
               Vec3::UnitX(), Vec3::UnitZ());
  int pinned = 0;
  for (int i = 0; i < world.cloth.num_vertices(); ++i) {
    const Vec3& p = world.cloth.state.x[i];
    if (std::hypot(p.x() - top.x(), p.z() - top.y()) < 0.035) {
      world.cloth.state.flags[i] |= kFlagPinned;
      ++pinned;
    }
  }
  if (pinned == 0) world.cloth.state.flags[world.cloth.num_vertices() / 2] |= kFlagPinned;
  world.cloth.relump_masses();
  VerletParams vp;
  vp.stiffness_scale = stiffness_scale;
  vp.damping_rate = 2.0;
  auto solver = std::make_unique<VerletSolver>(vp);
  const int substeps = solver->substeps_for(world.cloth, 1.0 / 90);
  const double dt_bound = solver->stable_dt_bound(world.cloth);
  world.solver = std::move(solver);

  std::printf(
      "drape run: %s form, %s panel %.2f x %.2f m, %d x %d vertices (%d pinned), baseline "
      "solver: %d substeps per 1/90 s tick (h = %.2e s, Gershgorin stability bound %.2e s)%s\n",
      size.c_str(), fabric_name.c_str(), width, height, spec.nx, spec.ny, pinned, substeps,
      1.0 / 90 / substeps, dt_bound, realtime ? ", real time" : ", lock step");

  SimThreadOptions opt;
  opt.tick_rate_hz = 90;
  opt.lock_step = !realtime;
  SimThread sim(std::move(world), opt);
  SnapshotReader reader = sim.make_reader();
  const auto wall0 = std::chrono::steady_clock::now();
  const auto total_ticks = static_cast<uint64_t>(std::lround(seconds * 90));
  sim.start();
  if (realtime) {
    while (sim.ticks() < total_ticks) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      const SceneSnapshot& s = reader.latest();
      if (s.tick % 90 < 9)
        std::printf("  t = %.2f s  tick %llu\n", s.sim_time, (unsigned long long)s.tick);
    }
  } else {
    for (uint64_t done = 0; done < total_ticks;) {
      const int n = static_cast<int>(std::min<uint64_t>(90, total_ticks - done));
      sim.advance(n);
      done += n;
      const SceneSnapshot& s = reader.latest();
      std::printf("  t = %.2f s  step p50 %.2f ms, p99 %.2f ms, max penetration %.2f mm\n",
                  s.sim_time, s.timing.step_ms_p50, s.timing.step_ms_p99,
                  sim.world().last_step.max_penetration * 1e3);
    }
  }
  sim.stop();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const World& w = sim.world();
  const SimTiming tm = sim.timing();

  double inside = 0, min_dist = 1e9;
  int near = 0;
  for (const Vec3& p : w.cloth.state.x) {
    const double d = f.signed_distance(p);
    if (!std::isfinite(d)) continue;
    min_dist = std::min(min_dist, d);
    inside = std::max(inside, -d);
    near += d < w.scene.offset + 0.002;
  }
  std::string invalid = w.cloth.validate();
  if (!invalid.empty()) {
    std::fprintf(stderr, "drape run: the cloth is invalid after the run: %s\n", invalid.c_str());
    return 1;
  }

  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) {
    std::fprintf(stderr, "drape run: cannot create '%s': %s\n", out.c_str(), ec.message().c_str());
    return 1;
  }
  const std::string cloth_path = out + "/drape_cloth.gltf", form_path = out + "/dress_form.gltf";
  if (std::string e = write_meshes(cloth_path, {cloth_to_mesh(w.cloth, "cloth")}); !e.empty()) {
    std::fprintf(stderr, "drape run: %s\n", e.c_str());
    return 1;
  }
  TriMesh fm = f.to_mesh();
  fm.name = "dress_form";
  if (std::string e = write_meshes(form_path, {fm}); !e.empty()) {
    std::fprintf(stderr, "drape run: %s\n", e.c_str());
    return 1;
  }
  std::printf(
      "simulated %.2f s in %.2f s wall (%llu ticks, step p50 %.2f ms, p95 %.2f ms, p99 %.2f ms, "
      "max %.2f ms, missed %llu)\n",
      w.cloth.state.time, wall, (unsigned long long)tm.ticks, tm.step_ms_p50, tm.step_ms_p95,
      tm.step_ms_p99, tm.step_ms_max, (unsigned long long)tm.missed_ticks);
  std::printf(
      "max penetration: %.3f mm into the %.1f mm offset shell during the last step (before the "
      "response); at the end %d vertices on the form, min distance to its surface %.3f mm, "
      "deepest inside the surface %.3f mm\n",
      w.last_step.max_penetration * 1e3, w.scene.offset * 1e3, near, min_dist * 1e3,
      std::max(0.0, inside) * 1e3);
  for (const auto& m : w.messages) std::printf("message: %s\n", m.c_str());
  std::printf("wrote %s\nwrote %s\n", std::filesystem::absolute(cloth_path).c_str(),
              std::filesystem::absolute(form_path).c_str());
  return 0;
}

}  // namespace

DRAPE_COMMAND(run, "headless main job: drop a muslin panel on the 9AR form, write glTF to out/",
              run);
