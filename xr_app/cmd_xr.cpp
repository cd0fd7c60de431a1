// `drape xr`: runs the OpenXR application on the active runtime (a headset), or on the mock
// runtime when none is configured. See docs/xr.md.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

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
  std::string scenario;
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
          "                [--cloth-res N] [-v]\n"
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
  return r.exit_code;
#endif
}

}  // namespace

DRAPE_COMMAND(xr, "run the OpenXR app (headset, or the mock runtime when none)", cmd_xr);
