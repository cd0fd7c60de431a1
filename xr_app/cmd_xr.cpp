// `drape xr`: runs the OpenXR application on the active runtime (a headset), or on the mock
// runtime when none is configured. See docs/xr.md.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "xr_app/command.hpp"
#ifdef DRAPE_HAVE_XR_APP
#include "xr_app/app/xr_app.hpp"
#endif

namespace {

int cmd_xr(int argc, char** argv) {
#ifndef DRAPE_HAVE_XR_APP
  (void)argc;
  (void)argv;
  std::fprintf(stderr, "drape xr: built without OpenXR (DRAPE_BUILD_XR=OFF)\n");
  return 2;
#else
  drape::app::XrAppOptions opt;
  std::string scenario, json_path;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto next = [&](const char* what) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "drape xr: %s needs a value\n", what);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::printf(
          "usage: drape xr [--frames N] [--scenario FILE] [--eye-size PX] [--no-render]\n"
          "                [--cloth-res N] [--sim-free] [--pose-wait-ms MS] [--commands FILE]\n"
          "                [--no-ops] [--out DIR] [--json FILE] [--full-form]\n"
          "                [--no-malloc-tuning] [-v]\n"
          "--sim-free: the sim on its own 90 Hz clock (default: one tick per frame);\n"
          "--pose-wait-ms: (free sim) how long a frame waits for the tick that took its hand\n"
          "pose (default 6); --commands: the command map (default assets/commands.json);\n"
          "--json: frame-time percentiles, pose-to-photon frames, sim tick jitter and the\n"
          "per-stage profile; --full-form: draw the form at full detail (no level of detail\n"
          "from the eye size); --no-malloc-tuning: let glibc trim freed memory every frame.\n"
          "Runs the OpenXR app. Without XR_RUNTIME_JSON or an active_runtime.json it uses the\n"
          "mock runtime (build/bin/drape_mock_runtime.json); --scenario sets DRAPE_MOCK_SCENARIO.\n"
          "Exit codes: 0 ok, 1 failure, 2 usage, 3 no OpenXR runtime.\n");
      return 0;
    } else if (a == "--frames") {
      opt.max_frames = std::atoll(next("--frames"));
    } else if (a == "--scenario") {
      scenario = next("--scenario");
    } else if (a == "--eye-size") {
      opt.eye_size = std::atoi(next("--eye-size"));
    } else if (a == "--cloth-res") {
      opt.cloth_res = std::atoi(next("--cloth-res"));
    } else if (a == "--sim-free") {
      opt.sim_lock_step = false;
    } else if (a == "--pose-wait-ms") {
      opt.pose_wait_ms = std::atof(next("--pose-wait-ms"));
    } else if (a == "--commands") {
      opt.commands_path = next("--commands");
    } else if (a == "--no-ops") {
      opt.operations = false;
    } else if (a == "--out") {
      opt.out_dir = next("--out");
    } else if (a == "--json") {
      json_path = next("--json");
    } else if (a == "--full-form") {
      opt.form_lod = false;
    } else if (a == "--no-malloc-tuning") {
      opt.tune_malloc = false;
    } else if (a == "--no-render") {
      opt.render = false;
    } else if (a == "-v" || a == "--verbose") {
      opt.verbose = true;
    } else {
      std::fprintf(stderr, "drape xr: unknown option '%s' (see --help)\n", a.c_str());
      return 2;
    }
  }
  if (!scenario.empty()) setenv("DRAPE_MOCK_SCENARIO", scenario.c_str(), 1);
  std::string manifest = drape::app::select_runtime();
  std::fprintf(stderr, "drape xr: runtime manifest: %s\n",
               manifest.empty() ? "(system active runtime)" : manifest.c_str());
  auto r = drape::app::run_xr_app(opt);
  std::fprintf(stderr,
               "drape xr: %s, runtime '%s', frames %lld (rendered %lld), sessions %d (lost %d), "
               "hand tracking %s, validation messages %u\n",
               drape::app::to_string(r.final_state), r.runtime_name.c_str(),
               static_cast<long long>(r.frames), static_cast<long long>(r.frames_rendered),
               r.sessions, r.sessions_lost, r.hand_tracking ? "yes" : "no", r.validation_messages);
  if (!r.error.empty()) std::fprintf(stderr, "drape xr: error: %s\n", r.error.c_str());
  auto pct = [](std::vector<double> v, double q) {
    if (v.empty()) return -1.0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())))];
  };
  // Skip the first 10 frames (pipeline and cache warm-up).
  std::vector<double> ft(r.frame_ms.begin() + std::min<size_t>(10, r.frame_ms.size()),
                         r.frame_ms.end());
  std::vector<double> lat(r.latency_frames.begin(), r.latency_frames.end());
  std::vector<double> clat(r.cloth_latency_frames.begin(), r.cloth_latency_frames.end());
  const double clat_ms = pct(r.cloth_latency_ms, 0.5), clat_ms99 = pct(r.cloth_latency_ms, 0.99);
  const double p50 = pct(ft, 0.5), p99 = pct(ft, 0.99), lat50 = pct(lat, 0.5),
               latmax = lat.empty() ? -1 : *std::max_element(lat.begin(), lat.end()),
               clat50 = pct(clat, 0.5),
               clatmax = clat.empty() ? -1 : *std::max_element(clat.begin(), clat.end());
  std::fprintf(stderr,
               "drape xr: frame time (wait -> end, %zu frames) p50 %.2f ms, p99 %.2f ms; "
               "pose-to-photon: hand %.0f frames (median of %zu, max %.0f), cloth response "
               "%.0f frames (median of %zu, max %.0f) = %.1f ms (p99 %.1f ms) from posting the "
               "pose to the end of the frame; sim tick jitter %.3f ms\n",
               ft.size(), p50, p99, lat50, lat.size(), latmax, clat50, clat.size(), clatmax,
               clat_ms, clat_ms99, r.sim_tick_jitter_ms);
  // Per-stage profile (frame stages skip the same 10 warm-up frames; sim.* are per tick).
  struct Row {
    std::string stage;
    double p50, p99, mean;
    size_t n;
  };
  std::vector<Row> rows;
  for (const auto& [stage, all] : r.profile_ms) {
    const size_t skip = stage.rfind("sim.", 0) == 0 ? 0 : std::min<size_t>(10, all.size());
    std::vector<double> v(all.begin() + static_cast<std::ptrdiff_t>(skip), all.end());
    if (v.empty()) continue;
    double sum = 0;
    for (double x : v) sum += x;
    rows.push_back(
        {stage, pct(v, 0.5), pct(v, 0.99), sum / static_cast<double>(v.size()), v.size()});
  }
  if (!rows.empty()) {
    std::fprintf(stderr, "drape xr: profile (ms)       %9s %9s %9s %7s\n", "p50", "p99", "mean",
                 "n");
    for (const auto& row : rows)
      std::fprintf(stderr, "drape xr:   %-22s %9.3f %9.3f %9.3f %7zu\n", row.stage.c_str(), row.p50,
                   row.p99, row.mean, row.n);
  }
  for (const auto& [group, sec] : r.thread_cpu_s)
    std::fprintf(stderr, "drape xr: cpu %-34s %8.2f s (%.2f ms per frame)\n", group.c_str(), sec,
                 r.frames ? 1e3 * sec / static_cast<double>(r.frames) : 0.0);
  for (const auto& w : r.written) std::fprintf(stderr, "wrote %s\n", w.c_str());
  if (!json_path.empty()) {
    std::ofstream o(json_path);
    o << "{\"latency_frames\": " << lat50 << ", \"latency_frames_max\": " << latmax
      << ", \"latency_samples\": " << lat.size() << ", \"cloth_latency_frames\": " << clat50
      << ", \"cloth_latency_frames_max\": " << clatmax
      << ", \"cloth_latency_samples\": " << clat.size() << ", \"cloth_latency_ms\": " << clat_ms
      << ", \"cloth_latency_ms_p99\": " << clat_ms99 << ", \"frame_ms_p50\": " << p50
      << ", \"frame_ms_p99\": " << p99 << ", \"sim_tick_jitter_ms\": " << r.sim_tick_jitter_ms
      << ", \"frames\": " << r.frames << ", \"eye_size\": " << opt.eye_size
      << ", \"cloth_res\": " << opt.cloth_res << ", \"pose_wait_ms\": " << opt.pose_wait_ms
      << ", \"sim\": \"" << (opt.sim_lock_step ? "lock_step" : "free_90hz") << "\"";
    o << ", \"profile_ms\": {";
    for (size_t i = 0; i < rows.size(); ++i)
      o << (i ? ", " : "") << "\"" << rows[i].stage << "\": {\"p50\": " << rows[i].p50
        << ", \"p99\": " << rows[i].p99 << ", \"mean\": " << rows[i].mean
        << ", \"n\": " << rows[i].n << "}";
    o << "}, \"thread_cpu_s\": {";
    size_t i = 0;
    for (const auto& [group, sec] : r.thread_cpu_s)
      o << (i++ ? ", " : "") << "\"" << group << "\": " << sec;
    o << "}}\n";
    if (!o) {
      std::fprintf(stderr, "drape xr: cannot write %s\n", json_path.c_str());
      return 1;
    }
  }
  return r.exit_code;
#endif
}

}  // namespace

DRAPE_COMMAND(xr, "run the OpenXR app (headset, or the mock runtime when none)", cmd_xr);
