// The executable's side of the OpenXR app (see xr_launch.hpp).
#include "xr_app/xr_launch.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "sim/core/fabric.hpp"
#include "xr_app/paths.hpp"

namespace drape::app {

namespace fs = std::filesystem;

namespace {
std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

// select_runtime pointed XR_RUNTIME_JSON at the simulated runtime itself (a re-run of the program
// must see the environment it was started with).
bool runtime_json_set_here = false;

std::vector<std::string> split(const std::string& s, const char* separators) {
  std::vector<std::string> out;
  size_t p = 0;
  while (p <= s.size()) {
    size_t q = s.find_first_of(separators, p);
    if (q == std::string::npos) q = s.size();
    if (q > p) out.push_back(s.substr(p, q - p));
    p = q + 1;
  }
  return out;
}
}  // namespace

std::string select_runtime(bool* simulated) {
  if (simulated) *simulated = false;
  if (std::string j = env("XR_RUNTIME_JSON"); !j.empty()) return j;
  std::vector<fs::path> dirs;
  if (std::string x = env("XDG_CONFIG_HOME"); !x.empty()) dirs.emplace_back(x);
  if (std::string h = env("HOME"); !h.empty()) dirs.push_back(fs::path(h) / ".config");
  for (const auto& d : split(env("XDG_CONFIG_DIRS"), ":")) dirs.emplace_back(d);
  dirs.emplace_back("/etc/xdg");
  std::error_code ec;
  for (const auto& d : dirs)
    if (fs::exists(d / "openxr/1/active_runtime.json", ec)) return "";
  // No runtime configured: the simulated runtime, through the loader's own variable.
  const fs::path mock = mock_runtime_manifest();
  if (mock.empty()) return "";
  setenv("XR_RUNTIME_JSON", mock.c_str(), 1);
  runtime_json_set_here = true;
  if (simulated) *simulated = true;
  return mock.string();
}

bool has_display() {
  return !env("DISPLAY").empty() || !env("WAYLAND_DISPLAY").empty();
}

void set_mock_window() {
  setenv("DRAPE_MOCK_WINDOW", "1", 1);
}

bool mock_window() {
  return env("DRAPE_MOCK_WINDOW") == "1";
}

bool simulated_runtime(const std::string& manifest, bool simulated) {
  if (simulated) return true;
  if (manifest.empty()) return false;
  const fs::path mock = mock_runtime_manifest();
  std::error_code ec;
  return !mock.empty() && fs::equivalent(manifest, mock, ec);
}

std::vector<std::string> loader_api_layers() {
  return split(env("XR_ENABLE_API_LAYERS"), ":;");
}

std::string mock_scenario() {
  return env("DRAPE_MOCK_SCENARIO");
}

void set_mock_scenario(const std::string& path) {
  setenv("DRAPE_MOCK_SCENARIO", path.c_str(), 1);
}

void add_app_options(CLI::App& cli, XrAppOptions& opt) {
  cli.option_defaults()->always_capture_default();
  cli.add_option("--frames", opt.max_frames,
                 "stop after N frames (default: when the runtime ends the session)")
      ->check(CLI::Range(int64_t{1}, int64_t{1000000000}));
  cli.add_option(
         "--eye-size", opt.eye_size,
         "swapchain edge in pixels" +
             std::string(opt.eye_size > 0 ? "" : " (default: the runtime's recommendation)"))
      ->check(CLI::Range(16, 4096));
  cli.add_option("--cloth-res", opt.cloth_res, "cloth vertices across the default scene's panel")
      ->check(CLI::Range(4, 256));
  cli.add_flag("-v,--verbose", opt.verbose, "print the app's log as it happens");
  add_off_switches(cli, {{"--no-feedback-panel", &opt.feedback_panel,
                          "no feedback panel over the scene (tests of the cloth's image)"},
                         {"--no-board", &opt.pattern_board,
                          "no live pattern board beside the form (its cost: drape bench board)"}});
  cli.add_option(
         "--garment", opt.garment,
         "instead of the panel, the sewn garment of a skirt, bodice or dress design "
         "(assets/designs/ by name, or a design file) on the form, simulated with its seams as "
         "ties")
      ->type_name("NAME|FILE.json");
  cli.add_option("--garment-fabric", opt.garment_fabric,
                 "with --garment: a fabric of assets/fabrics.json (default: the design's)")
      ->type_name("NAME");
  cli.add_option_function<std::string>(
         "--assets", [](const std::string& dir) { set_assets_dir(dir); },
         "the assets directory (default: <exe dir>/../share/drape/assets)")
      ->check(CLI::ExistingDirectory);
}

void add_off_switches(CLI::App& cli, std::initializer_list<OffSwitch> switches) {
  for (const OffSwitch& s : switches)
    cli.add_flag_callback(
        s.name, [setting = s.setting] { *setting = false; }, s.help);
}

bool resolve_input_file(const char* command, const char* option, std::string& path) {
  std::error_code ec;
  path = user_or_asset(path).string();
  if (fs::is_regular_file(path, ec)) return true;
  std::fprintf(stderr, "%s: %s: no such file: %s\n", command, option, path.c_str());
  return false;
}

void add_voice_option(CLI::App& cli, std::string& voice) {
  cli.add_option("--voice", voice,
                 "live voice commands: mic (the default ALSA capture device), off, or a 16 kHz "
                 "mono WAV file streamed at real time as if it were the microphone (default: mic "
                 "on a live session, off on a scripted run)")
      ->always_capture_default(false);
}

bool resolve_voice(const char* command, const std::string& given, bool live, std::string& out) {
  if (given.empty()) {
    out = live ? "mic" : "";
    return true;
  }
  if (given == "off" || given == "mic") {
    out = given == "mic" ? "mic" : "";
    return true;
  }
  out = given;
  return resolve_input_file(command, "--voice", out);
}

void add_hands_options(CLI::App& cli, std::vector<std::string>& hands, std::string& calibration,
                       XrAppOptions& opt) {
  cli.add_option("--hands", hands,
                 "where the hands come from: xr (the runtime's), udp[:ADDR:PORT] (a skeleton "
                 "stream, docs/tracking.md; default 127.0.0.1:9740), trace FILE (a recorded "
                 "trace played from the first frame) or kinect (a Kinect v1 through libfreenect)")
      ->expected(1, 2)
      ->default_str("xr");
  cli.add_option("--kinect-record", opt.kinect_record,
                 "with --hands kinect: replay this fakenect recording directory (DIR/INDEX.txt, "
                 "libfreenect's fakenect-record) instead of the device; its end is the Kinect "
                 "going away")
      ->always_capture_default(false);
  cli.add_option("--calibration", calibration,
                 "tracker-to-stage calibration file (tracking/calibration's JSON) for --hands "
                 "udp, trace or kinect (default: the source's saved calibration, "
                 "$XDG_CONFIG_HOME/drape/calibration-<source>.json, when there is one; else "
                 "identity)")
      ->always_capture_default(false);
  cli.add_flag("--calibrate", opt.calibrate,
               "calibrate --hands udp, trace or kinect: touch the 4 marked points in turn, "
               "holding the palm still 1 s on each; the result is saved as the source's "
               "calibration");
}

std::string saved_calibration_file(const std::string& source) {
  fs::path dir;
  if (std::string x = env("XDG_CONFIG_HOME"); !x.empty())
    dir = x;
  else if (std::string h = env("HOME"); !h.empty())
    dir = fs::path(h) / ".config";
  else
    return "";
  return (dir / "drape" / ("calibration-" + source + ".json")).string();
}

namespace {
bool hands_usage(const char* command, const std::string& why) {
  std::fprintf(stderr, "%s: --hands: %s (xr, udp[:ADDR:PORT], trace FILE or kinect)\n", command,
               why.c_str());
  return false;
}

// "udp", "udp:PORT" or "udp:ADDR:PORT" into opt.
bool parse_udp(const char* command, const std::string& v, XrAppOptions& opt) {
  if (v == "udp") return true;
  const std::string rest = v.substr(4);
  const size_t colon = rest.rfind(':');
  const std::string port = colon == std::string::npos ? rest : rest.substr(colon + 1);
  if (colon != std::string::npos) opt.hands_address = rest.substr(0, colon);
  if (opt.hands_address.empty()) return hands_usage(command, "empty address in '" + v + "'");
  char* end = nullptr;
  const long p = std::strtol(port.c_str(), &end, 10);
  if (port.empty() || *end != '\0' || p < 1 || p > 65535)
    return hands_usage(command, "bad port '" + port + "' in '" + v + "' (1..65535)");
  opt.hands_port = static_cast<int>(p);
  return true;
}
// This program's arguments as it was started (/proc/self/cmdline).
std::vector<std::string> own_arguments() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  const std::string all{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::vector<std::string> args;
  size_t p = 0;
  while (p < all.size()) {
    const size_t q = all.find('\0', p);
    args.push_back(all.substr(p, q == std::string::npos ? std::string::npos : q - p));
    if (q == std::string::npos) break;
    p = q + 1;
  }
  return args;
}

// --kinect-record DIR: checks the recording, then runs this program again under libfreenect's
// `fakenect DIR` wrapper unless it already runs under it (FAKENECT_PATH is DIR).
bool replay_kinect_record(const char* command, XrAppOptions& opt) {
  std::error_code ec;
  const fs::path dir = fs::absolute(opt.kinect_record, ec);
  if (!fs::is_regular_file(dir / "INDEX.txt", ec)) {
    std::fprintf(stderr, "%s: --kinect-record: no fakenect recording in %s (no INDEX.txt)\n",
                 command, opt.kinect_record.c_str());
    return false;
  }
  opt.kinect_record = dir.string();
  if (env("FAKENECT_PATH") == opt.kinect_record) return true;
  char exe[4096];
  const ssize_t n = ::readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n <= 0) {
    std::fprintf(stderr, "%s: --kinect-record: cannot find this program to run it under fakenect\n",
                 command);
    return false;
  }
  exe[n] = '\0';
  std::vector<std::string> args = {"fakenect", opt.kinect_record, exe};
  const std::vector<std::string> own = own_arguments();
  if (own.size() > 1) args.insert(args.end(), own.begin() + 1, own.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  setenv("FAKENECT_LOOP", "0", 0);
  if (runtime_json_set_here) unsetenv("XR_RUNTIME_JSON");
  std::fflush(nullptr);
  ::execvp("fakenect", argv.data());
  std::fprintf(stderr, "%s: --kinect-record: cannot run libfreenect's fakenect wrapper: %s\n",
               command, std::strerror(errno));
  return false;
}
}  // namespace

bool resolve_hands(const char* command, const std::vector<std::string>& hands,
                   const std::string& calibration, XrAppOptions& opt) {
  const std::string kind = hands.empty() ? "xr" : hands[0];
  if (kind == "trace") {
    if (hands.size() != 2) return hands_usage(command, "trace needs a FILE");
    opt.hands = "trace";
    opt.hands_trace = hands[1];
    if (!resolve_input_file(command, "--hands trace", opt.hands_trace)) return false;
  } else if (hands.size() > 1) {
    return hands_usage(command, "unexpected '" + hands[1] + "' after '" + kind + "'");
  } else if (kind == "xr") {
    opt.hands = "xr";
  } else if (kind == "udp" || kind.rfind("udp:", 0) == 0) {
    opt.hands = "udp";
    if (!parse_udp(command, kind, opt)) return false;
  } else if (kind == "kinect") {
    opt.hands = "kinect";
  } else {
    return hands_usage(command, "unknown source '" + kind + "'");
  }
  opt.calibration_path = calibration;
  if (!calibration.empty() && !resolve_input_file(command, "--calibration", opt.calibration_path))
    return false;
  if (opt.calibrate) {
    if (opt.hands == "xr") {
      std::fprintf(stderr, "%s: --calibrate: needs --hands udp, trace or kinect\n", command);
      return false;
    }
    opt.calibration_save = saved_calibration_file(opt.hands);
    if (opt.calibration_save.empty()) {
      std::fprintf(stderr,
                   "%s: --calibrate: no config directory to save to (neither XDG_CONFIG_HOME "
                   "nor HOME is set)\n",
                   command);
      return false;
    }
  } else if (calibration.empty() && opt.hands != "xr") {
    std::error_code ec;
    const std::string saved = saved_calibration_file(opt.hands);
    if (!saved.empty() && fs::is_regular_file(saved, ec)) {
      opt.calibration_path = saved;
      opt.calibration_saved = true;
    }
  }
  if (opt.kinect_record.empty()) return true;
  if (opt.hands != "kinect") {
    std::fprintf(stderr, "%s: --kinect-record: needs --hands kinect\n", command);
    return false;
  }
  return replay_kinect_record(command, opt);
}

std::string commands_file(const std::string& given) {
  if (!given.empty()) return given;
  std::error_code ec;
  const fs::path bundled = user_or_asset("assets/commands.json");
  return fs::exists(bundled, ec) ? bundled.string() : "";
}

void add_record_option(CLI::App& cli, std::string& dir, double& checkpoint_every) {
  cli.add_option("--record", dir,
                 "record the session into DIR: journal.bin (the sim's inputs, for drape replay "
                 "and --resume), checkpoints, meta.json, session.txt, audio.wav (live voice), "
                 "hands.csv (external hands)");
  cli.add_option("--checkpoint-every", checkpoint_every,
                 "with --record: a checkpoint of the World every this many seconds of session "
                 "time (0: none), from which drape replay and --resume start; it holds the "
                 "solver's state, so the session goes on as without it")
      ->check(CLI::Range(0.0, 3600.0))
      ->capture_default_str();
}

bool resolve_garment(const char* command, XrAppOptions& opt) {
  auto bad = [&](const std::string& why) {
    std::fprintf(stderr, "%s: %s\n", command, why.c_str());
    return false;
  };
  if (opt.garment.empty())
    return opt.garment_fabric.empty() || bad("--garment-fabric: needs --garment");
  if (!opt.record_dir.empty() || !opt.resume_dir.empty() || !opt.open_file.empty())
    return bad("--garment: a garment session is not recorded, resumed or opened");
  const bool named =
      opt.garment.find('/') == std::string::npos && opt.garment.find(".json") == std::string::npos;
  const std::string path = named ? asset("designs/" + opt.garment + ".json").string() : opt.garment;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    return bad("--garment: no such design: " + opt.garment + " (" + path + ")");
  opt.garment = path;
  if (opt.fabrics_path.empty()) opt.fabrics_path = asset("fabrics.json").string();
  if (!opt.garment_fabric.empty()) {
    auto f = sim::load_fabric(opt.fabrics_path, opt.garment_fabric);
    if (!f) return bad("--garment-fabric " + opt.garment_fabric + ": " + f.error());
  }
  // The board and the end's pattern read a draped panel, not a sewn garment.
  opt.pattern_board = false;
  opt.export_pattern = false;
  return true;
}

bool prepare_record_dir(const char* command, const std::string& dir) {
  if (dir.empty()) return true;
  std::error_code ec;
  fs::create_directories(dir, ec);
  const fs::path probe = fs::path(dir) / ".write_test";
  std::FILE* f = ec ? nullptr : std::fopen(probe.c_str(), "wb");
  if (!f) {
    std::fprintf(stderr, "%s: --record %s: cannot write there%s%s\n", command, dir.c_str(),
                 ec ? ": " : "", ec ? ec.message().c_str() : "");
    return false;
  }
  std::fclose(f);
  fs::remove(probe, ec);
  return true;
}

}  // namespace drape::app
