// `drape run`: the main job. Live (a headset with no --scenario, or at a desk: a display, no
// headset runtime, no --scenario, the simulated runtime's window) the person drapes the desk scene
// (xr_app/app/desk_scene.hpp: --resolution, --fabric, --form, --mesh, --start) with the sim on its
// own 90 Hz thread until the session ends. Otherwise the simulated runtime plays a scenario
// (assets/scenarios/default.json, or --scenario) and the run writes screenshots, the session log,
// the draped cloth and the pattern to out/ (see docs/xr.md). `drape run --headless` (or no XR
// build) is the sim-core job: builds the 9AR form, drops a muslin panel over its shoulders on the
// simulation thread (lock step, or real time), then writes the draped cloth and the form as glTF
// and prints where, with the max penetration.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "sim/form/dress_form.hpp"
#include "sim/io/mesh_io.hpp"
#include "sim/runtime/sim_thread.hpp"
#include "sim/solvers/verlet_solver.hpp"
#include "tracking/command_map.hpp"
#include "xr_app/command.hpp"
#include "xr_app/hands_key.hpp"
#include "xr_app/paths.hpp"
#ifdef DRAPE_HAVE_XR_APP
#include <nlohmann/json.hpp>

#include "sim/ops/checkpoint.hpp"
#include "xr_app/app/desk_scene.hpp"
#include "xr_app/app/session_record.hpp"
#include "xr_app/app/xr_app.hpp"
#include "xr_app/xr_launch.hpp"
#endif

namespace {

using namespace drape::sim;

std::string fabrics_path() {
  return drape::app::user_or_asset("assets/fabrics.json").string();
}

// Creates `dir` (and its parents); else says why on stderr and returns false.
bool make_dir(const std::string& dir, const std::string& shown) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    std::fprintf(stderr, "drape run: cannot create '%s': %s\n", shown.c_str(),
                 ec.message().c_str());
  return !ec;
}

// The headless job's options.
struct HeadlessOptions {
  double seconds = 3.0, stiffness_scale = 1.0;
  std::string out = "out", fabric = "muslin", size = "9AR";
  int resolution = 31;
  bool realtime = false;
};

int write_headless(const HeadlessOptions& o, const World& w, const DressForm& f,
                   const SimTiming& tm, double wall) {
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

  if (!make_dir(o.out, o.out)) return 1;
  const std::string cloth_path = o.out + "/drape_cloth.gltf",
                    form_path = o.out + "/dress_form.gltf";
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

int run_headless(const HeadlessOptions& o) {
  auto fabric = load_fabric(fabrics_path(), o.fabric);
  if (!fabric) {
    std::fprintf(stderr, "drape run: %s\n", fabric.error().c_str());
    return 1;
  }
  auto meas = measurements_for_size(o.size);
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
  spec.nx = o.resolution;
  spec.ny = std::max(3, static_cast<int>(std::lround((o.resolution - 1) * height / width)) + 1);
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
  vp.stiffness_scale = o.stiffness_scale;
  vp.air_drag = 2.0;
  auto solver = std::make_unique<VerletSolver>(vp);
  const int substeps = solver->substeps_for(world.cloth, 1.0 / 90);
  const double dt_bound = solver->stable_dt_bound(world.cloth);
  world.solver = std::move(solver);

  std::printf(
      "drape run: %s form, %s panel %.2f x %.2f m, %d x %d vertices (%d pinned), baseline "
      "solver: %d substeps per 1/90 s tick (h = %.2e s, Gershgorin stability bound %.2e s)%s\n",
      o.size.c_str(), o.fabric.c_str(), width, height, spec.nx, spec.ny, pinned, substeps,
      1.0 / 90 / substeps, dt_bound, o.realtime ? ", real time" : ", lock step");

  SimThreadOptions opt;
  opt.tick_rate_hz = 90;
  opt.lock_step = !o.realtime;
  SimThread sim(std::move(world), opt);
  SnapshotReader reader = sim.make_reader();
  const auto wall0 = std::chrono::steady_clock::now();
  const auto total_ticks = static_cast<uint64_t>(std::lround(o.seconds * 90));
  sim.start();
  if (o.realtime) {
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
  return write_headless(o, w, f, tm, wall);
}

#ifdef DRAPE_HAVE_XR_APP
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

// `drape run`'s options for the XR app.
struct XrRunOptions {
  drape::app::XrAppOptions app;
  std::string scenario = "assets/scenarios/default.json", out = "out";
  std::string voice;               // --voice as given ("" = the default of the session's kind)
  std::vector<std::string> hands;  // --hands as given (resolved into app by resolve_hands)
  std::string calibration;         // --calibration as given
  std::string hands_key;           // --hands-key as given
  bool pattern = true;
  int every = 30;
  bool scenario_given = false;   // --scenario: always the scripted run
  bool cloth_res_given = false;  // --cloth-res / --resolution: also live
  bool eye_size_given = false, every_given = false;
  bool scene_given = false;  // --start, --fabric, --form or --mesh: the desk scene when scripted
  std::string form;          // --form: a size or a measurements file
  std::string json;          // --json: the live session's figures
  bool lock_step = false;    // --sim-lock-step: live with one sim tick per frame
  bool record = true;        // --no-record: a live session without its default recording
  std::string resume;        // --resume [DIR]
  CLI::Option* resume_opt = nullptr;
  std::string open;  // --open FILE (drape open FILE)
};

// A live session's default recording: OUT/sessions/<UTC date and time>, a crash loses nothing
// of it (docs/sessions.md).
std::string default_record_dir(const std::string& out) {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &utc);
  return out + "/sessions/" + stamp;
}

// The sim's ticks and the cloth's state hash at the end: what `drape replay` of the session's
// recording reproduces.
void print_final_state(const drape::app::XrAppResult& r) {
  if (r.has_final_state)
    std::printf("drape run: final state hash %016llx at tick %llu\n",
                static_cast<unsigned long long>(r.final_state_hash),
                static_cast<unsigned long long>(r.final_ticks));
}

// A live session's cloth resolution, eye size in the simulated runtime's window (swapchain edge:
// shown 1.4x in a 720 px high window; lavapipe renders 2 x 720^2 at about half the frame rate of
// 2 x 512^2, ./drape bench desk --eye-size) and screenshot interval unless the options say
// otherwise.
constexpr int kLiveClothRes = 128, kLiveEyeSize = 512, kLiveEvery = 90;
constexpr const char* kLiveStart = "pinned-top";

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The fraction q of the sorted values (0 when empty).
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())))];
}

// The live session's figures: frames per second over the loop's time after the first 30
// frames (pipeline and cache warm-up), the frame's own work, the sim's step, and the app's
// pose-to-photon probes in frames (hand: the frame whose pose the drawn hand has; cloth: the
// frame whose pose the drawn snapshot holds) and in time. Written as JSON to `path`.
bool write_live_json(const std::string& path, const drape::app::XrAppResult& r,
                     const drape::app::XrAppOptions& o) {
  const auto& wait = r.profile_ms.count("xr.wait_frame") ? r.profile_ms.at("xr.wait_frame")
                                                         : std::vector<double>{};
  const size_t skip = std::min<size_t>(30, r.frame_ms.size());
  double loop_ms = 0;
  for (size_t i = skip; i < r.frame_ms.size(); ++i)
    loop_ms += r.frame_ms[i] + (i < wait.size() ? wait[i] : 0.0);
  const auto n = static_cast<double>(r.frame_ms.size() - skip);
  auto as_doubles = [](const std::vector<int>& v) {
    return std::vector<double>(v.begin(), v.end());
  };
  const std::vector<double> hand = as_doubles(r.latency_frames),
                            cloth = as_doubles(r.cloth_latency_frames);
  const std::vector<double> step = r.profile_ms.count("sim.step_wall")
                                       ? r.profile_ms.at("sim.step_wall")
                                       : std::vector<double>{};
  nlohmann::json j = {
      {"cloth_res", o.cloth_res},
      {"eye_size", o.eye_size},
      {"frames", r.frames},
      {"fps", loop_ms > 0 ? 1000.0 * n / loop_ms : 0.0},
      {"frame_work_p50_ms", quantile(r.frame_ms, 0.5)},
      {"sim_step_p50_ms", quantile(step, 0.5)},
      {"sim_ticks", step.size()},
      {"frames_pinched", r.frames_pinched},
      {"hand_latency_frames",
       {{"n", hand.size()}, {"p50", quantile(hand, 0.5)}, {"max", quantile(hand, 1.0)}}},
      {"cloth_latency_frames",
       {{"n", cloth.size()},
        {"p50", quantile(cloth, 0.5)},
        {"p90", quantile(cloth, 0.9)},
        {"max", quantile(cloth, 1.0)}}},
      {"cloth_latency_ms",
       {{"p50", quantile(r.cloth_latency_ms, 0.5)}, {"p90", quantile(r.cloth_latency_ms, 0.9)}}}};
  std::ofstream out(path);
  out << j.dump(2) << "\n";
  if (!out) std::fprintf(stderr, "drape run: --json: cannot write %s\n", path.c_str());
  return static_cast<bool>(out);
}

// The live session's scene, as the first line says it.
void print_live_scene(const drape::app::XrAppOptions& a) {
  const char* form = !a.form_mesh.empty()           ? a.form_mesh.c_str()
                     : !a.form_measurements.empty() ? a.form_measurements.c_str()
                                                    : a.form_size.c_str();
  if (a.garment.empty())
    std::printf("drape run: live, %d x %d %s cloth, start %s, form %s, eyes %d px\n", a.cloth_res,
                a.cloth_res, a.fabric.c_str(), a.start.c_str(), form, a.eye_size);
  else
    std::printf(
        "drape run: live, the garment of %s (fabric %s), form %s, eyes %d px\n", a.garment.c_str(),
        a.garment_fabric.empty() ? "the design's" : a.garment_fabric.c_str(), form, a.eye_size);
}

// Live at a desk: the simulated runtime's window (DRAPE_MOCK_WINDOW, docs/mock-window.md) is the
// headset; the person drives the head and hands with mouse and keyboard, no scenario, the sim
// on its own 90 Hz clock, until Escape or the window is closed (or --frames).
int run_live(XrRunOptions& o, const std::string& manifest, bool simulated) {
  namespace app = drape::app;
  const auto wall0 = std::chrono::steady_clock::now();
  if (!make_dir(o.out + "/frames", o.out)) return 1;
  if (simulated) {
    app::set_mock_window();
    // Every K-th frame's left eye as a screenshot, at the eye size.
    const std::string frames_dir = std::filesystem::absolute(o.out + "/frames").string();
    setenv("DRAPE_MOCK_WRITE_FRAMES", frames_dir.c_str(), 1);
    setenv("DRAPE_MOCK_WRITE_EVERY", std::to_string(o.every_given ? o.every : kLiveEvery).c_str(),
           1);
  }
  o.app.out_dir = o.out;
  o.app.export_pattern = o.pattern;
  o.app.scenario_path.clear();
  o.app.voice = false;  // no scenario: no audio cues
  o.app.sim_lock_step = o.lock_step;
  o.app.commands_path = app::commands_file("");
  o.app.api_layers = app::loader_api_layers();
  // A journal's header names the panel's scene only: a garment session is not recorded.
  if (!o.app.garment.empty() && o.app.record_dir.empty() && o.record) {
    o.record = false;
    std::printf("drape run: --garment: the session is not recorded (no journal of a garment)\n");
  }
  if (o.app.record_dir.empty() && o.record) o.app.record_dir = default_record_dir(o.out);
  if (!app::prepare_record_dir("drape run", o.app.record_dir)) return 2;
  if (!app::resolve_garment("drape run", o.app)) return 2;
  if (!o.app.record_dir.empty())
    std::printf("drape run: recording the session into %s\n", o.app.record_dir.c_str());
  print_live_scene(o.app);
  if (simulated)
    std::printf(
        "drape run: live in the simulated runtime's window (%s): the mouse moves the right hand, "
        "the left button pinches, right-drag looks, W/A/S/D/Q/E move the head; Escape or "
        "closing the window ends the session (docs/mock-window.md); live voice %s\n",
        manifest.c_str(), o.app.voice_input.empty() ? "off" : o.app.voice_input.c_str());
  else
    std::printf(
        "drape run: live on the headset (runtime %s); the headset's quit ends it; live voice %s\n",
        manifest.empty() ? "(system active runtime)" : manifest.c_str(),
        o.app.voice_input.empty() ? "off" : o.app.voice_input.c_str());
  std::fflush(stdout);
  auto r = app::run_xr_app(o.app);
  for (const auto& l : r.log)
    if (l.rfind("pinch:", 0) == 0 || l.rfind("depth:", 0) == 0 || l.rfind("cut", 0) == 0 ||
        l.rfind("voice", 0) == 0 || l.rfind("pattern", 0) == 0 || l.rfind("resume", 0) == 0 ||
        l.rfind("record", 0) == 0)
      std::printf("  %s\n", l.c_str());
  for (const auto& t : r.triggers) std::printf("  trigger %s\n", t.c_str());
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  // Frames per second as shown: the frames over the loop's time (waits included); the frame's
  // own work (xrWaitFrame's return to xrEndFrame's) as its median.
  const double p50 = median(r.frame_ms);
  double loop_ms = 0;
  for (double ms : r.frame_ms) loop_ms += ms;
  for (double ms : r.profile_ms["xr.wait_frame"]) loop_ms += ms;
  const double fps = loop_ms > 0 ? 1000.0 * static_cast<double>(r.frames) / loop_ms : 0.0;
  std::printf(
      "drape run: %s, runtime '%s', %lld frames (%lld rendered), %.1f fps (frame work p50 %.1f "
      "ms), "
      "sim step p50 %.1f ms, pinched in %lld frames, %d vertices pinned, cloth %d x %d\n",
      app::to_string(r.final_state), r.runtime_name.c_str(), static_cast<long long>(r.frames),
      static_cast<long long>(r.frames_rendered), fps, p50, median(r.profile_ms["sim.step_wall"]),
      static_cast<long long>(r.frames_pinched), r.pinned_added, o.app.cloth_res, o.app.cloth_res);
  print_final_state(r);
  if (!r.error.empty()) std::fprintf(stderr, "drape run: error: %s\n", r.error.c_str());
  if (r.exit_code != 0) return r.exit_code;
  for (const auto& w : r.written) std::printf("wrote %s\n", std::filesystem::absolute(w).c_str());
  if (!o.json.empty() && !write_live_json(o.json, r, o.app)) return 1;
  std::printf("drape run: done in %.1f s\n", secs);
  return 0;
}

// The scenario with its audio cues generated: every cue's "text" (or "say") is spoken by
// espeak-ng into DIR/voice/ and the copy DIR/scenario.json points at those WAVs. Returns that
// copy's path, "" when the scenario does not parse.
std::string prepare_scenario(const XrRunOptions& o) {
  std::ifstream in(o.scenario);
  nlohmann::json sc = nlohmann::json::parse(in, nullptr, false);
  if (!in.good() && !in.eof()) sc = nlohmann::json();
  if (sc.is_discarded() || !sc.is_object()) {
    std::fprintf(stderr, "drape run: %s: cannot read or parse the scenario (JSON object)\n",
                 o.scenario.c_str());
    return "";
  }
  if (sc.contains("audio") && sc["audio"].is_array()) {
    int k = 0;
    for (auto& a : sc["audio"]) {
      if (!a.is_object() || !a.contains("text") || !a["text"].is_string()) continue;
      std::string speak = a["text"].get<std::string>();
      if (a.contains("say") && a["say"].is_string()) speak = a["say"].get<std::string>();
      const std::string wav =
          o.app.voice ? make_voice_wav(o.out + "/voice", "cue" + std::to_string(k++), speak) : "";
      if (wav.empty()) {
        if (o.app.voice)
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
  const std::string sc_path = std::filesystem::absolute(o.out + "/scenario.json").string();
  std::ofstream(sc_path) << sc.dump(2) << "\n";
  return sc_path;
}

// Resolves --form (a standard size, else a measurements file), --mesh and the fabrics file, then
// builds the desk scene once: bad input is reported (naming the option and the file) before a
// session opens. No desk scene (the default scenario's): nothing to check.
bool check_scene(XrRunOptions& o) {
  namespace app = drape::app;
  app::XrAppOptions& a = o.app;
  a.fabrics_path = fabrics_path();
  a.forms_dir = app::asset("forms").string();
  const bool is_file = o.form.find('/') != std::string::npos ||
                       (o.form.size() > 5 && o.form.compare(o.form.size() - 5, 5, ".json") == 0);
  if (!is_file) {
    a.form_size = o.form;
  } else {
    a.form_measurements = o.form;
    if (!app::resolve_input_file("drape run", "--form", a.form_measurements)) return false;
  }
  if (!a.form_mesh.empty() && !app::resolve_input_file("drape run", "--mesh", a.form_mesh))
    return false;
  if (a.start.empty()) return true;
  auto scene = app::make_desk_scene(a);
  if (!scene) std::fprintf(stderr, "drape run: %s\n", scene.error().c_str());
  return scene.ok();
}

// --resume [DIR]: the session directory (default: the newest under OUT/sessions/), its journal's
// scene options into o.app, recording appended to that journal.
bool resume_options(XrRunOptions& o) {
  namespace fs = std::filesystem;
  std::string dir = o.resume;
  if (dir.empty()) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(o.out + "/sessions", ec))
      if (e.is_directory() && fs::exists(e.path() / "journal.bin") &&
          e.path().filename().string() > fs::path(dir).filename().string())
        dir = e.path().string();
    if (dir.empty()) {
      std::fprintf(stderr, "drape run: --resume: no recorded session under %s/sessions/\n",
                   o.out.c_str());
      return false;
    }
  }
  const std::string path = dir + "/journal.bin";
  drape::sim::JournalContents j;
  std::string err = drape::sim::load_journal(path, j);
  if (err.empty()) {
    const bool lock_step = o.app.sim_lock_step;
    err = drape::app::options_from_header(j.header, path, o.app);
    o.app.sim_lock_step = lock_step;  // the mode of this run (run_live sets it from the options)
  }
  if (!err.empty()) {
    std::fprintf(stderr, "drape run: --resume %s: %s\n", dir.c_str(), err.c_str());
    return false;
  }
  if (!j.cut_message.empty()) std::printf("drape run: --resume: %s\n", j.cut_message.c_str());
  o.app.resume_dir = dir;
  o.app.record_dir = dir;
  std::printf("drape run: resuming %s (%zu input records)\n", dir.c_str(), j.ticks.size());
  return true;
}

// --open FILE: the saved session's scene options into o.app (its header, as a journal's).
bool open_options(XrRunOptions& o) {
  drape::sim::WorldCheckpoint c;
  std::string err = drape::sim::load_checkpoint(o.open, c);
  if (err.empty()) {
    const bool lock_step = o.app.sim_lock_step;
    drape::sim::JournalHeader h;
    h.fields = c.header;
    err = drape::app::options_from_header(h, o.open, o.app);
    o.app.sim_lock_step = lock_step;
  }
  if (!err.empty()) {
    std::fprintf(stderr, "drape open: %s\n", err.c_str());
    return false;
  }
  if (!o.resume.empty() || o.resume_opt->count() > 0) {
    std::fprintf(stderr, "drape open: --resume: a saved session is opened, not resumed\n");
    return false;
  }
  o.app.open_file = o.open;
  std::printf("drape open: %s: the session at tick %llu\n", o.open.c_str(),
              static_cast<unsigned long long>(c.tick));
  return true;
}

int run_xr(XrRunOptions& o) {
  namespace app = drape::app;
  bool simulated = false;
  const std::string manifest = app::select_runtime(&simulated);
  // Live on a headset, or at a desk without one in the simulated runtime's window. Otherwise (the
  // simulated runtime without a display, or --scenario) the scripted run. A live session takes
  // the microphone by default and plays no scenario audio cues.
  const bool window = simulated && app::has_display() && !o.scenario_given;
  const bool headset = !app::simulated_runtime(manifest, simulated);
  if (!app::resolve_voice("drape run", o.voice, window || headset, o.app.voice_input)) return 2;
  if (!app::resolve_hands("drape run", o.hands, o.calibration, o.app)) return 2;
  if (!app::resolve_hands_key("drape run", o.app.hands == "udp", o.hands_key, o.app.hands_address,
                              o.app.hands_key))
    return 2;
  if (window || (headset && !o.scenario_given)) {
    if (!o.cloth_res_given) o.app.cloth_res = kLiveClothRes;
    if (!o.eye_size_given && !simulated) o.app.eye_size = 0;  // the headset's own size
    if (o.app.start.empty()) o.app.start = kLiveStart;
    if (!check_scene(o)) return 2;
    if (o.resume_opt->count() > 0 && !resume_options(o)) return 2;
    if (!o.open.empty() && !open_options(o)) return 2;
    return run_live(o, manifest, simulated);
  }
  if (!o.open.empty()) {
    std::fprintf(stderr,
                 "drape open: needs a live session (a headset, or a display for the simulated "
                 "runtime's window) and no --scenario\n");
    return 2;
  }
  if (o.resume_opt->count() > 0) {
    std::fprintf(stderr,
                 "drape run: --resume: needs a live session (a headset, or a display for the "
                 "simulated runtime's window) and no --scenario\n");
    return 2;
  }
  if (headset) o.app.voice = false;
  if (o.scene_given && o.app.start.empty()) o.app.start = kLiveStart;
  if (!check_scene(o)) return 2;
  const auto wall0 = std::chrono::steady_clock::now();
  if (!make_dir(o.out + "/frames", o.out)) return 1;
  std::error_code ec;
  const std::string sc_path = prepare_scenario(o);
  if (sc_path.empty()) return 1;
  // The simulated runtime plays the scenario and writes every K-th frame's screenshot.
  app::set_mock_scenario(sc_path);
  const std::string frames_dir = std::filesystem::absolute(o.out + "/frames").string();
  setenv("DRAPE_MOCK_WRITE_FRAMES", frames_dir.c_str(), 1);
  setenv("DRAPE_MOCK_WRITE_EVERY", std::to_string(o.every).c_str(), 1);
  o.app.out_dir = o.out;
  o.app.export_pattern = o.pattern;
  o.app.scenario_path = sc_path;
  o.app.commands_path = app::commands_file("");
  o.app.api_layers = app::loader_api_layers();
  if (!app::prepare_record_dir("drape run", o.app.record_dir)) return 2;
  if (!app::resolve_garment("drape run", o.app)) return 2;
  std::printf("drape run: runtime manifest %s, scenario %s, live voice %s\n",
              manifest.empty() ? "(system active runtime)" : manifest.c_str(), o.scenario.c_str(),
              o.app.voice_input.empty() ? "off" : o.app.voice_input.c_str());
  auto r = app::run_xr_app(o.app);
  for (const auto& l : r.log)
    if (l.rfind("voice", 0) == 0 || l.rfind("cut", 0) == 0 || l.rfind("pattern", 0) == 0)
      std::printf("  %s\n", l.c_str());
  for (const auto& t : r.triggers) std::printf("  trigger %s\n", t.c_str());
  std::printf(
      "drape run: %s, runtime '%s', %lld frames (%lld rendered), pinched in %lld frames, "
      "%d vertices pinned, %d cut(s) (%d particles split; %d -> %d parts), voice commands %zu\n",
      app::to_string(r.final_state), r.runtime_name.c_str(), static_cast<long long>(r.frames),
      static_cast<long long>(r.frames_rendered), static_cast<long long>(r.frames_pinched),
      r.pinned_added, r.cuts_ok, r.cut_new_vertices, r.components_before, r.components_after,
      r.voice_commands.size());
  print_final_state(r);
  if (!r.error.empty()) std::fprintf(stderr, "drape run: error: %s\n", r.error.c_str());
  if (r.exit_code != 0) return r.exit_code;
  for (const auto& e : std::filesystem::directory_iterator(frames_dir, ec))
    std::printf("wrote %s\n", e.path().c_str());
  for (const auto& w : r.written) std::printf("wrote %s\n", std::filesystem::absolute(w).c_str());
  std::printf("drape run: done in %.1f s\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count());
  return 0;
}

// The XR job's options; they exclude --headless.
void add_xr_options(CLI::App& cli, XrRunOptions& o, CLI::Option* headless) {
  o.app.eye_size = kLiveEyeSize;  // screenshots a person can read (512 px), scripted or live
  o.app.cloth_res = 12;
  o.form = "9AR";
  drape::app::add_app_options(cli, o.app);
  cli.add_option("--scenario", o.scenario,
                 "the draping scenario the simulated runtime plays (given: the scripted run even "
                 "with a display)");
  drape::app::add_off_switches(
      cli, {{"--no-voice", &o.app.voice, "no voice cues (no espeak-ng)"},
            {"--no-pattern", &o.pattern,
             "skip the pattern of the draped cloth at the session's end (pattern/session-N/; "
             "\"make pattern\" still writes one)"},
            {"--no-record", &o.record, "live: do not record the session into OUT/sessions/"},
            {"--no-self-collision", &o.app.self_collision,
             "the cloth does not collide with itself (cheaper; folds may pass through each "
             "other)"}});
  drape::app::add_record_option(cli, o.app.record_dir, o.app.checkpoint_every_s);
  o.resume_opt = cli.add_option("--resume", o.resume,
                                "live: resume the session recorded in DIR (default: the newest "
                                "under OUT/sessions/): its journal replayed, then live, appending")
                     ->expected(0, 1);
  cli.add_option("--open", o.open,
                 "live: open the saved session FILE (\"save session\" writes "
                 "OUT/saved_session.drape) and go on draping from it (drape open FILE)")
      ->check(CLI::ExistingFile);
  cli.add_option("--json", o.json,
                 "live: write the session's frame rate, sim step and pose-to-photon probes "
                 "(frames) as JSON to this file");
  cli.add_option("--every", o.every, "write every K-th frame's screenshot (live default: 90)")
      ->check(CLI::Range(1, 1000000));
  drape::app::add_voice_option(cli, o.voice);
  drape::app::add_hands_options(cli, o.hands, o.calibration, o.app);
  drape::app::add_hands_key_option(cli, o.hands_key);
  cli.add_option("--form", o.form,
                 "the dress form: a standard size (7AR, 9AR, 11AR, 13AR) or a measurements file "
                 "(JSON, as assets/forms/9AR.json)");
  cli.add_option("--mesh", o.app.form_mesh,
                 "a scanned or modelled dress form (OBJ, PLY, STL, glTF; as drape form --mesh)")
      ->excludes("--form");
  cli.add_flag_callback(
      "--sim-lock-step", [&o] { o.lock_step = true; },
      "live: one sim tick per frame (repeatable: tests, replays) instead of the sim's own 90 Hz "
      "thread");
  cli.add_flag("--state-hashes", o.app.log_state_hashes,
               "log the cloth's state hash before and after each operation's outcome in "
               "xr_session.txt (tests)");
  cli.add_option("--start", o.app.start,
                 std::string("the cloth's start state: ") + drape::app::desk_start_names() +
                     " (default: pinned-top live; the scenario's scene when scripted)");
  for (const char* name :
       {"--frames",   "--eye-size",   "--cloth-res",     "--verbose",      "--scenario",
        "--no-voice", "--no-pattern", "--every",         "--form",         "--mesh",
        "--start",    "--json",       "--sim-lock-step", "--state-hashes", "--voice",
        "--record",   "--no-record",  "--resume",        "--open",         "--no-self-collision"})
    cli.get_option(name)->excludes(headless);
}
#endif

// The headless job's options; they need --headless.
void add_headless_options(CLI::App& cli, HeadlessOptions& o, CLI::Option* headless) {
  // A number in (lo, hi), or (lo, hi] when hi_closed; `range` names it in messages.
  const auto number_in = [](double lo, double hi, bool hi_closed, const std::string& range) {
    return CLI::Validator(
        [=](std::string& s) -> std::string {
          char* end = nullptr;
          const double v = std::strtod(s.c_str(), &end);
          const bool ok = !s.empty() && !*end && v > lo && (hi_closed ? v <= hi : v < hi);
          return ok ? "" : "Value " + s + " not a number in " + range;
        },
        "in " + range);
  };
  cli.add_option("--seconds", o.seconds, "simulated seconds")
      ->check(number_in(0, 3600, false, "(0, 3600)"))
      ->needs(headless);
  cli.add_option("--resolution", o.resolution,
                 "cloth vertices across (--headless: 31, 2 cm; live: 128; scripted: 12)")
      ->check(CLI::Range(3, 400));
  cli.add_option("--fabric", o.fabric, "a fabric of assets/fabrics.json");
  cli.add_option("--size", o.size, "the dress form's size")->needs(headless);
  cli.add_flag("--realtime", o.realtime,
               "the sim on its real-time 90 Hz clock (default: lock step)")
      ->needs(headless);
  cli.add_option("--stiffness-scale", o.stiffness_scale, "the baseline solver's stiffness scale")
      ->check(number_in(0, 10, true, "(0, 10]"))
      ->needs(headless);
}

// The bindings of the command map the app loads (assets/commands.json, else the built-in
// defaults), one line each, for the end of --help: which trigger starts or ends which operation.
std::string bindings_help() {
  std::string error;
  const std::string path = drape::app::user_or_asset("assets/commands.json").string();
  auto map = drape::tracking::CommandMap::load(path, &error);
  std::string out = "Bindings (" + (map ? path : std::string("built-in defaults")) +
                    "; any source can start any operation):\n";
  if (!map) map = drape::tracking::CommandMap::defaults();
  for (const drape::tracking::Binding& b : map->bindings()) {
    char line[160];
    std::snprintf(line, sizeof line, "  %-10s %-22s %-5s -> %s %s", b.source.c_str(),
                  b.command.c_str(), b.edge.c_str(), b.action.operation.c_str(),
                  drape::tracking::phase_name(b.action.phase));
    std::string who = b.hand.empty() ? "" : b.hand + " hand";
    if (!b.profile.empty()) who += (who.empty() ? "" : ", ") + b.profile;
    out += line + (b.label.empty() ? "" : "  " + b.label) + (who.empty() ? "" : "  (" + who + ")") +
           "\n";
  }
  return out +
         "The simulated runtime's window turns mouse and keys into these hands and buttons: "
         "docs/mock-window.md.";
}

#ifdef DRAPE_HAVE_XR_APP
// After parsing: the options the headless job shares with the XR job (--resolution, --fabric) and
// which of the scene's options were given. False (the message printed) when --resolution is out
// of the XR app's range.
bool xr_scene_args(CLI::App& cli, const HeadlessOptions& ho, XrRunOptions& xo) {
  auto given = [&](const char* name) { return cli.get_option(name)->count() > 0; };
  if (given("--resolution")) {
    if (ho.resolution < 4 || ho.resolution > 256) {
      std::fprintf(stderr, "drape run: --resolution: Value %d not in range 4 to 256\n",
                   ho.resolution);
      return false;
    }
    xo.app.cloth_res = ho.resolution;
  }
  xo.app.fabric = ho.fabric;
  xo.cloth_res_given = given("--cloth-res") || given("--resolution");
  xo.eye_size_given = given("--eye-size");
  xo.every_given = given("--every");
  xo.scene_given = given("--start") || given("--fabric") || given("--form") || given("--mesh");
  return true;
}
#endif

int run(int argc, char** argv) {
  CLI::App cli(
      "Runs the OpenXR app on a draping scenario (--scenario; without it on the simulated "
      "runtime when no headset runtime is configured and there is no display): pinch, pin (a "
      "spoken 'pin here' made with espeak-ng), a cut stroke; "
      "then the pattern of the cloth as draped. Writes DIR/frames/*.png, DIR/session_log.json, "
      "DIR/xr_session.txt, DIR/drape_cloth.gltf, DIR/pattern/session-1/.\n"
      "At a desk (DISPLAY or WAYLAND_DISPLAY set, no headset runtime configured, no --scenario): "
      "the simulated runtime's window instead; drape live with mouse and keyboard until Escape "
      "(docs/mock-window.md); on a headset with no --scenario, live the same way. Live: a 128^2 "
      "panel (--resolution, --fabric) on the form (--form, --mesh) in a start state (--start), "
      "the sim on its own 90 Hz thread. Writes the session log, xr_session.txt, the cloth, "
      "every 90th frame, the pattern.\n"
      "With --headless: drops a 0.6 m x 0.7 m panel over the dress form's shoulders, its centre "
      "pinned above the neck, and simulates it with the baseline solver (mass-spring + damped "
      "Verlet, substeps chosen for stability) on the 90 Hz simulation thread. Writes "
      "DIR/drape_cloth.gltf and DIR/dress_form.gltf.",
      "drape run");
  cli.option_defaults()->always_capture_default();
  cli.footer(bindings_help);
  HeadlessOptions ho;
  std::string out = "out";
  bool headless_job = false;
  CLI::Option* headless =
      cli.add_flag("--headless", headless_job, "the sim-core job only (no XR app)");
  cli.add_option("--out", out, "the output directory");
#ifdef DRAPE_HAVE_XR_APP
  XrRunOptions xo;
  add_xr_options(cli, xo, headless);
#endif
  add_headless_options(cli, ho, headless);
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli.exit(e) == 0 ? 0 : 2;  // --help: 0; a usage error (its message names the option)
  }
  ho.out = out;
#ifdef DRAPE_HAVE_XR_APP
  if (!headless_job) {
    xo.out = out;
    xo.scenario_given = cli.get_option("--scenario")->count() > 0;
    if (!xr_scene_args(cli, ho, xo)) return 2;
    if (!drape::app::resolve_input_file("drape run", "--scenario", xo.scenario)) return 2;
    return run_xr(xo);
  }
#else
  if (!headless_job)
    std::fprintf(stderr, "drape run: built without the XR app; running the headless job\n");
#endif
  return run_headless(ho);
}

}  // namespace

DRAPE_COMMAND(run, "main job: the XR app on the default draping scenario (--headless: sim only)",
              run);

namespace {
// drape open FILE [drape run's options]: drape run --open FILE.
int open_command(int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') {
    if (argc >= 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
      std::printf(
          "usage: drape open FILE [drape run's options]: opens the saved session FILE "
          "(\"save session\" writes OUT/saved_session.drape) live and goes on draping "
          "from it\n");
      return 0;
    }
    std::fprintf(stderr, "drape open: FILE is required (drape open FILE)\n");
    return 2;
  }
  std::vector<std::string> args = {"run", "--open", argv[1]};
  for (int i = 2; i < argc; ++i) args.emplace_back(argv[i]);
  std::vector<char*> av;
  for (auto& a : args) av.push_back(a.data());
  return run(static_cast<int>(av.size()), av.data());
}
}  // namespace

DRAPE_COMMAND(open, "open a saved session live and go on draping (drape open FILE)", open_command);
