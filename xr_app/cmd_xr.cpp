// `drape xr`: runs the OpenXR application on the active runtime (a headset), or on the
// simulated runtime when none is configured. See docs/xr.md.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "xr_app/command.hpp"
#ifdef DRAPE_HAVE_XR_APP
#include "xr_app/app/xr_app.hpp"
#include "xr_app/hands_key.hpp"
#include "xr_app/xr_launch.hpp"
#endif

namespace {

#ifdef DRAPE_HAVE_XR_APP
using drape::app::XrAppOptions;
using drape::app::XrAppResult;

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return -1.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())))];
}

double max_or_none(const std::vector<double>& v) {
  return v.empty() ? -1 : *std::max_element(v.begin(), v.end());
}

// The run's figures: frame time, pose-to-photon and the per-stage profile (frame stages skip the
// first 10 frames: pipeline and cache warm-up; sim.* are per tick, board.* per board drawn).
struct Summary {
  struct Row {
    std::string stage;
    double p50, p99, mean;
    size_t n;
  };
  std::vector<double> frame_ms, latency, cloth_latency;
  double p50 = -1, p99 = -1, lat50 = -1, latmax = -1, clat50 = -1, clatmax = -1;
  double clat_ms = -1, clat_ms99 = -1;
  std::vector<Row> rows;
};

Summary summarise(const XrAppResult& r) {
  Summary s;
  s.frame_ms.assign(r.frame_ms.begin() + std::min<size_t>(10, r.frame_ms.size()), r.frame_ms.end());
  s.latency.assign(r.latency_frames.begin(), r.latency_frames.end());
  s.cloth_latency.assign(r.cloth_latency_frames.begin(), r.cloth_latency_frames.end());
  s.clat_ms = percentile(r.cloth_latency_ms, 0.5);
  s.clat_ms99 = percentile(r.cloth_latency_ms, 0.99);
  s.p50 = percentile(s.frame_ms, 0.5);
  s.p99 = percentile(s.frame_ms, 0.99);
  s.lat50 = percentile(s.latency, 0.5);
  s.latmax = max_or_none(s.latency);
  s.clat50 = percentile(s.cloth_latency, 0.5);
  s.clatmax = max_or_none(s.cloth_latency);
  for (const auto& [stage, all] : r.profile_ms) {
    const bool whole = stage.rfind("sim.", 0) == 0 || stage.rfind("board.", 0) == 0;
    const size_t skip = whole ? 0 : std::min<size_t>(10, all.size());
    std::vector<double> v(all.begin() + static_cast<std::ptrdiff_t>(skip), all.end());
    if (v.empty()) continue;
    double sum = 0;
    for (double x : v) sum += x;
    s.rows.push_back({stage, percentile(v, 0.5), percentile(v, 0.99),
                      sum / static_cast<double>(v.size()), v.size()});
  }
  return s;
}

void print_summary(const XrAppResult& r, const Summary& s) {
  std::fprintf(stderr,
               "drape xr: %s, runtime '%s', frames %lld (rendered %lld), sessions %d (lost %d), "
               "hand tracking %s, validation messages %u\n",
               drape::app::to_string(r.final_state), r.runtime_name.c_str(),
               static_cast<long long>(r.frames), static_cast<long long>(r.frames_rendered),
               r.sessions, r.sessions_lost, r.hand_tracking ? "yes" : "no", r.validation_messages);
  if (!r.error.empty()) std::fprintf(stderr, "drape xr: error: %s\n", r.error.c_str());
  std::fprintf(stderr,
               "drape xr: frame time (wait -> end, %zu frames) p50 %.2f ms, p99 %.2f ms; "
               "pose-to-photon: hand %.0f frames (median of %zu, max %.0f), cloth response "
               "%.0f frames (median of %zu, max %.0f) = %.1f ms (p99 %.1f ms) from posting the "
               "pose to the end of the frame; sim tick jitter %.3f ms\n",
               s.frame_ms.size(), s.p50, s.p99, s.lat50, s.latency.size(), s.latmax, s.clat50,
               s.cloth_latency.size(), s.clatmax, s.clat_ms, s.clat_ms99, r.sim_tick_jitter_ms);
  if (!s.rows.empty()) {
    std::fprintf(stderr, "drape xr: profile (ms)       %9s %9s %9s %7s\n", "p50", "p99", "mean",
                 "n");
    for (const auto& row : s.rows)
      std::fprintf(stderr, "drape xr:   %-22s %9.3f %9.3f %9.3f %7zu\n", row.stage.c_str(), row.p50,
                   row.p99, row.mean, row.n);
  }
  for (const auto& [group, sec] : r.thread_cpu_s)
    std::fprintf(stderr, "drape xr: cpu %-34s %8.2f s (%.2f ms per frame)\n", group.c_str(), sec,
                 r.frames ? 1e3 * sec / static_cast<double>(r.frames) : 0.0);
  if (r.has_final_state)
    std::fprintf(stderr, "drape xr: final state hash %016llx at tick %llu\n",
                 static_cast<unsigned long long>(r.final_state_hash),
                 static_cast<unsigned long long>(r.final_ticks));
  for (const auto& w : r.written) std::fprintf(stderr, "wrote %s\n", w.c_str());
}

bool write_json(const std::string& path, const XrAppOptions& opt, const XrAppResult& r,
                const Summary& s) {
  std::ofstream o(path);
  o << "{\"latency_frames\": " << s.lat50 << ", \"latency_frames_max\": " << s.latmax
    << ", \"latency_samples\": " << s.latency.size() << ", \"cloth_latency_frames\": " << s.clat50
    << ", \"cloth_latency_frames_max\": " << s.clatmax
    << ", \"cloth_latency_samples\": " << s.cloth_latency.size()
    << ", \"cloth_latency_ms\": " << s.clat_ms << ", \"cloth_latency_ms_p99\": " << s.clat_ms99
    << ", \"frame_ms_p50\": " << s.p50 << ", \"frame_ms_p99\": " << s.p99
    << ", \"sim_tick_jitter_ms\": " << r.sim_tick_jitter_ms << ", \"frames\": " << r.frames
    << ", \"eye_size\": " << opt.eye_size << ", \"cloth_res\": " << opt.cloth_res
    << ", \"pose_wait_ms\": " << opt.pose_wait_ms << ", \"sim\": \""
    << (opt.sim_lock_step ? "lock_step" : "free_90hz") << "\"";
  o << ", \"profile_ms\": {";
  for (size_t i = 0; i < s.rows.size(); ++i)
    o << (i ? ", " : "") << "\"" << s.rows[i].stage << "\": {\"p50\": " << s.rows[i].p50
      << ", \"p99\": " << s.rows[i].p99 << ", \"mean\": " << s.rows[i].mean
      << ", \"n\": " << s.rows[i].n << "}";
  o << "}, \"thread_cpu_s\": {";
  size_t i = 0;
  for (const auto& [group, sec] : r.thread_cpu_s)
    o << (i++ ? ", " : "") << "\"" << group << "\": " << sec;
  o << "}}\n";
  return static_cast<bool>(o);
}
#endif

int cmd_xr(int argc, char** argv) {
#ifndef DRAPE_HAVE_XR_APP
  (void)argc;
  (void)argv;
  std::fprintf(stderr, "drape xr: built without OpenXR (DRAPE_BUILD_XR=OFF)\n");
  return 2;
#else
  namespace app = drape::app;
  XrAppOptions opt;
  std::string scenario, commands, json_path, voice;
  CLI::App cli(
      "Runs the OpenXR app. Without XR_RUNTIME_JSON or an active_runtime.json it uses the "
      "simulated runtime (<exe dir>/drape_mock_runtime.json). Exit codes: 0 ok, 1 failure, "
      "2 usage, 3 no OpenXR runtime.",
      "drape xr");
  app::add_app_options(cli, opt);
  cli.add_option("--scenario", scenario,
                 "the scenario the simulated runtime plays (default: $DRAPE_MOCK_SCENARIO); its "
                 "audio cues are the voice input");
  app::add_voice_option(cli, voice);
  std::vector<std::string> hands;
  std::string calibration, hands_key;
  app::add_hands_options(cli, hands, calibration, opt);
  app::add_hands_key_option(cli, hands_key);
  cli.add_option("--pose-wait-ms", opt.pose_wait_ms,
                 "free sim: how long a frame waits for the tick that took its hand pose")
      ->check(CLI::Range(0.0, 1000.0));
  cli.add_option("--commands", commands,
                 "the command map: triggers -> operations (default: assets/commands.json)");
  cli.add_option("--out", opt.out_dir,
                 "write session_log.json, drape_cloth.gltf and xr_session.txt there");
  app::add_record_option(cli, opt.record_dir, opt.checkpoint_every_s);
  cli.add_option("--json", json_path,
                 "write frame-time percentiles, pose-to-photon frames, sim tick jitter and the "
                 "per-stage profile there");
  app::add_off_switches(
      cli,
      {{"--no-render", &opt.render, "only submit the swapchain images (no scene, no sim)"},
       {"--sim-free", &opt.sim_lock_step,
        "the sim on its own 90 Hz clock (default: one tick per frame)"},
       {"--no-ops", &opt.operations, "no interaction: hands and triggers do not drive the sim"},
       {"--no-self-collision", &opt.self_collision,
        "the cloth does not collide with itself (cheaper; folds may pass through each other)"},
       {"--full-form", &opt.form_lod,
        "draw the form at full detail (no level of detail from the eye size)"},
       {"--no-malloc-tuning", &opt.tune_malloc, "let glibc trim freed memory every frame"}});
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli.exit(e) == 0 ? 0 : 2;  // --help: 0; a usage error (its message names the option)
  }
  if (!scenario.empty()) {
    if (!app::resolve_input_file("drape xr", "--scenario", scenario)) return 2;
    app::set_mock_scenario(scenario);
  }
  if (!commands.empty() && !app::resolve_input_file("drape xr", "--commands", commands)) return 2;
  opt.scenario_path = app::mock_scenario();
  opt.commands_path = app::commands_file(commands);
  opt.api_layers = app::loader_api_layers();
  bool simulated = false;
  const std::string manifest = app::select_runtime(&simulated);
  // A live session (a headset, or the simulated runtime's window with no scenario) listens to the
  // microphone by default; the scenario's audio cues play only on the simulated runtime's
  // scripted runs, which it plays.
  const bool live = !app::simulated_runtime(manifest, simulated) ||
                    (app::mock_window() && opt.scenario_path.empty());
  if (live) opt.voice = false;
  if (!app::resolve_voice("drape xr", voice, live, opt.voice_input)) return 2;
  if (!app::resolve_hands("drape xr", hands, calibration, opt)) return 2;
  if (!app::resolve_hands_key("drape xr", opt.hands == "udp", hands_key, opt.hands_address,
                              opt.hands_key))
    return 2;
  if (!app::prepare_record_dir("drape xr", opt.record_dir)) return 2;
  if (!app::resolve_garment("drape xr", opt)) return 2;
  std::fprintf(stderr, "drape xr: runtime manifest: %s\n",
               manifest.empty() ? "(system active runtime)" : manifest.c_str());
  std::fprintf(stderr, "drape xr: live voice: %s\n",
               opt.voice_input.empty() ? "off" : opt.voice_input.c_str());
  const XrAppResult r = app::run_xr_app(opt);
  const Summary s = summarise(r);
  print_summary(r, s);
  if (!json_path.empty() && !write_json(json_path, opt, r, s)) {
    std::fprintf(stderr, "drape xr: cannot write %s\n", json_path.c_str());
    return 1;
  }
  return r.exit_code;
#endif
}

}  // namespace

DRAPE_COMMAND(xr, "run the OpenXR app (headset, or the simulated runtime when none)", cmd_xr);
