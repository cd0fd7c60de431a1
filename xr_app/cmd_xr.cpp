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
          "                [--no-ops] [--out DIR] [--json FILE] [-v]\n"
          "--sim-free: the sim on its own 90 Hz clock (default: one tick per frame);\n"
          "--pose-wait-ms: (free sim) how long a frame waits for the tick that took its hand\n"
          "pose (default 6); --commands: the command map (default assets/commands.json);\n"
          "--json: frame-time percentiles, pose-to-photon frames, sim tick jitter.\n"
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
  const double p50 = pct(ft, 0.5), p99 = pct(ft, 0.99), lat50 = pct(lat, 0.5),
               latmax = lat.empty() ? -1 : *std::max_element(lat.begin(), lat.end()),
               clat50 = pct(clat, 0.5),
               clatmax = clat.empty() ? -1 : *std::max_element(clat.begin(), clat.end());
  std::fprintf(stderr,
               "drape xr: frame time (wait -> end, %zu frames) p50 %.2f ms, p99 %.2f ms; "
               "pose-to-photon: hand %.0f frames (median of %zu, max %.0f), cloth response "
               "%.0f frames (median of %zu, max %.0f); sim tick jitter %.3f ms\n",
               ft.size(), p50, p99, lat50, lat.size(), latmax, clat50, clat.size(), clatmax,
               r.sim_tick_jitter_ms);
  for (const auto& w : r.written) std::fprintf(stderr, "wrote %s\n", w.c_str());
  if (!json_path.empty()) {
    std::ofstream o(json_path);
    o << "{\"latency_frames\": " << lat50 << ", \"latency_frames_max\": " << latmax
      << ", \"latency_samples\": " << lat.size() << ", \"cloth_latency_frames\": " << clat50
      << ", \"cloth_latency_frames_max\": " << clatmax
      << ", \"cloth_latency_samples\": " << clat.size() << ", \"frame_ms_p50\": " << p50
      << ", \"frame_ms_p99\": " << p99 << ", \"sim_tick_jitter_ms\": " << r.sim_tick_jitter_ms
      << ", \"frames\": " << r.frames << ", \"eye_size\": " << opt.eye_size
      << ", \"cloth_res\": " << opt.cloth_res << ", \"pose_wait_ms\": " << opt.pose_wait_ms
      << ", \"sim\": \"" << (opt.sim_lock_step ? "lock_step" : "free_90hz") << "\"}\n";
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
