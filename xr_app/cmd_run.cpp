// `drape run`: the main job. With an OpenXR runtime (a headset, or else the headless mock
// runtime built next to the executable) it runs the XR app on the default draping scenario
// (assets/scenarios/default.json) and writes screenshots, the session log, the draped cloth and
// the pattern to out/ (see docs/xr.md). `drape run --headless` (or no XR build / no runtime)
// is the sim-core job: builds the 9AR form, drops a muslin panel over its shoulders on the
// simulation thread (lock step, or real time), then writes the draped cloth and the form as
// glTF and prints where, with the max penetration.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "sim/draping/pattern_pipeline.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/io/mesh_io.hpp"
#include "sim/runtime/sim_thread.hpp"
#include "sim/solvers/verlet_solver.hpp"
#include "xr_app/command.hpp"
#ifdef DRAPE_HAVE_XR_APP
#include <nlohmann/json.hpp>

#include "xr_app/app/xr_app.hpp"
#endif

namespace {

using namespace drape::sim;

void usage() {
  std::printf(
      "usage: drape run [--scenario FILE] [--frames N] [--out DIR] [--eye-size PX]\n"
      "                 [--cloth-res N] [--no-voice] [--no-pattern] [--every K]\n"
      "Runs the OpenXR app (headset, or the mock runtime when none is configured) on a draping\n"
      "scenario (default assets/scenarios/default.json): pinch, pin (a spoken 'pin here' made\n"
      "with espeak-ng), a cut stroke; then the pattern export. Writes DIR/frames/*.png,\n"
      "DIR/session_log.json, DIR/xr_session.txt, DIR/drape_cloth.gltf, DIR/pattern/.\n\n"
      "       drape run --headless [--seconds S] [--out DIR] [--resolution N] [--fabric NAME]\n"
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

int run_headless(int argc, char** argv) {
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
  world.scene.friction = kFormFriction;  // muslin stays where the hand lays it on the form
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

#ifdef DRAPE_HAVE_XR_APP
std::string source_path(const std::string& rel) {
  if (std::filesystem::exists(rel)) return rel;
  return std::string(DRAPE_SOURCE_DIR) + "/" + rel;
}

// A 16 kHz mono WAV of `text` made with espeak-ng (resampled by sox). Empty on failure.
std::string make_voice_wav(const std::string& dir, const std::string& name,
                           const std::string& text) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const std::string raw = dir + "/" + name + "_22k.wav", wav = dir + "/" + name + ".wav";
  const std::string cmd = "espeak-ng -s 140 -w '" + raw + "' '" + text + "' >/dev/null 2>&1 && " +
                          "sox '" + raw + "' -r 16000 -c 1 -b 16 '" + wav +
                          "' pad 0.3 0.5 >/dev/null 2>&1";
  if (std::system(cmd.c_str()) != 0) return "";
  std::filesystem::remove(raw, ec);
  return std::filesystem::absolute(wav).string();
}

int run_xr(int argc, char** argv) {
  std::string scenario = source_path("assets/scenarios/default.json"), out = "out";
  drape::app::XrAppOptions opt;
  opt.eye_size = 256;
  opt.cloth_res = 12;
  bool pattern = true;
  int every = 30;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&](const char* what) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "drape run: %s needs a value\n", what);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      usage();
      return 0;
    } else if (a == "--scenario") {
      scenario = next("--scenario");
    } else if (a == "--frames") {
      opt.max_frames = std::atoll(next("--frames"));
    } else if (a == "--out") {
      out = next("--out");
    } else if (a == "--eye-size") {
      opt.eye_size = std::atoi(next("--eye-size"));
    } else if (a == "--cloth-res") {
      opt.cloth_res = std::atoi(next("--cloth-res"));
    } else if (a == "--every") {
      every = std::max(1, std::atoi(next("--every")));
    } else if (a == "--no-voice") {
      opt.voice = false;
    } else if (a == "--no-pattern") {
      pattern = false;
    } else if (a == "-v") {
      opt.verbose = true;
    } else {
      std::fprintf(stderr, "drape run: unknown option '%s'\n", a.c_str());
      usage();
      return 2;
    }
  }
  if (opt.eye_size < 16 || opt.eye_size > 4096 || opt.cloth_res < 4 || opt.cloth_res > 256) {
    std::fprintf(stderr, "drape run: --eye-size must be in [16, 4096], --cloth-res in [4, 256]\n");
    return 2;
  }
  const auto wall0 = std::chrono::steady_clock::now();
  std::error_code ec;
  std::filesystem::create_directories(out + "/frames", ec);
  if (ec) {
    std::fprintf(stderr, "drape run: cannot create '%s': %s\n", out.c_str(), ec.message().c_str());
    return 1;
  }
  // The scenario, with its audio cues generated: every cue's "text" is spoken by espeak-ng into
  // DIR/voice/ and the copy DIR/scenario.json points at those WAVs.
  std::ifstream in(scenario);
  nlohmann::json sc = nlohmann::json::parse(in, nullptr, false);
  if (!in.good() && !in.eof()) sc = nlohmann::json();
  if (sc.is_discarded() || !sc.is_object()) {
    std::fprintf(stderr, "drape run: %s: cannot read or parse the scenario (JSON object)\n",
                 scenario.c_str());
    return 1;
  }
  if (sc.contains("audio") && sc["audio"].is_array()) {
    int k = 0;
    for (auto& a : sc["audio"]) {
      if (!a.is_object() || !a.contains("text") || !a["text"].is_string()) continue;
      std::string speak = a["text"].get<std::string>();
      if (a.contains("say") && a["say"].is_string()) speak = a["say"].get<std::string>();
      const std::string wav =
          opt.voice ? make_voice_wav(out + "/voice", "cue" + std::to_string(k++), speak) : "";
      if (wav.empty()) {
        if (opt.voice)
          std::fprintf(stderr, "drape run: espeak-ng/sox failed; voice cue '%s' skipped\n",
                       speak.c_str());
        a["wav"] = "/nonexistent/voice_disabled.wav";
      } else {
        a["wav"] = wav;
        std::printf("wrote %s (espeak-ng: \"%s\")\n", wav.c_str(), speak.c_str());
      }
      a.erase("say");
    }
  }
  const std::string sc_path = std::filesystem::absolute(out + "/scenario.json").string();
  {
    std::ofstream o(sc_path);
    o << sc.dump(2) << "\n";
  }
  setenv("DRAPE_MOCK_SCENARIO", sc_path.c_str(), 1);
  const std::string frames_dir = std::filesystem::absolute(out + "/frames").string();
  setenv("DRAPE_MOCK_WRITE_FRAMES", frames_dir.c_str(), 1);
  setenv("DRAPE_MOCK_WRITE_EVERY", std::to_string(every).c_str(), 1);
  opt.out_dir = out;
  const std::string manifest = drape::app::select_runtime();
  std::printf("drape run: runtime manifest %s, scenario %s\n",
              manifest.empty() ? "(system active runtime)" : manifest.c_str(), scenario.c_str());
  auto r = drape::app::run_xr_app(opt);
  for (const auto& l : r.log)
    if (l.rfind("voice", 0) == 0 || l.rfind("cut", 0) == 0) std::printf("  %s\n", l.c_str());
  for (const auto& t : r.triggers) std::printf("  trigger %s\n", t.c_str());
  std::printf(
      "drape run: %s, runtime '%s', %lld frames (%lld rendered), pinched in %lld frames, "
      "%d vertices pinned, %d cut(s) (%d particles split; %d -> %d parts), voice commands %zu\n",
      drape::app::to_string(r.final_state), r.runtime_name.c_str(),
      static_cast<long long>(r.frames), static_cast<long long>(r.frames_rendered),
      static_cast<long long>(r.frames_pinched), r.pinned_added, r.cuts_ok, r.cut_new_vertices,
      r.components_before, r.components_after, r.voice_commands.size());
  if (!r.error.empty()) std::fprintf(stderr, "drape run: error: %s\n", r.error.c_str());
  if (r.exit_code != 0) return r.exit_code;
  for (const auto& e : std::filesystem::directory_iterator(frames_dir, ec))
    std::printf("wrote %s\n", e.path().c_str());
  for (const auto& w : r.written) std::printf("wrote %s\n", std::filesystem::absolute(w).c_str());
  if (pattern) {
    // The pattern export of the bundled design on the same form (sim/draping/pattern_pipeline.hpp).
    auto d = drape::sim::load_design(source_path("assets/designs/tight-skirt.json"));
    auto m = drape::sim::measurements_for_size("9AR");
    if (!d || !m) {
      std::fprintf(stderr, "drape run: pattern: %s\n", !d ? d.error().c_str() : m.error().c_str());
      return 1;
    }
    auto form = drape::sim::DressForm::from_measurements(*m);
    auto fab = drape::sim::load_fabric(fabrics_path(), d->fabric);
    if (!form || !fab) {
      std::fprintf(stderr, "drape run: pattern: %s\n",
                   !form ? form.error().c_str() : fab.error().c_str());
      return 1;
    }
    drape::sim::PipelineOptions po;
    po.out_dir = out + "/pattern";
    auto pr = drape::sim::run_pattern_pipeline(*d, *form, *fab, po);
    if (!pr) {
      // The pattern pipeline is another module: its failure is reported, the session's
      // outputs above stand.
      std::printf("drape run: pattern export failed (skipped): %s\n", pr.error().c_str());
    } else {
      for (const auto& f : pr->report.files) {
        const std::filesystem::path fp = std::filesystem::exists(f)
                                             ? std::filesystem::path(f)
                                             : std::filesystem::path(po.out_dir) / f;
        std::printf("wrote %s\n", std::filesystem::absolute(fp).c_str());
      }
    }
  }
  std::printf("drape run: done in %.1f s\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count());
  return 0;
}
#endif

int run(int argc, char** argv) {
  bool headless = false;
  for (int i = 1; i < argc; ++i) headless = headless || std::strcmp(argv[i], "--headless") == 0;
#ifdef DRAPE_HAVE_XR_APP
  if (!headless) return run_xr(argc, argv);
#endif
  // The headless job: drop "--headless" and run the sim-core path.
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i)
    if (std::strcmp(argv[i], "--headless") != 0) args.push_back(argv[i]);
  if (!headless)
    std::fprintf(stderr, "drape run: built without the XR app; running the headless job\n");
  return run_headless(static_cast<int>(args.size()), args.data());
}

}  // namespace

DRAPE_COMMAND(run, "main job: the XR app on the default draping scenario (--headless: sim only)",
              run);
