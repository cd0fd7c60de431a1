// The executable's side of the OpenXR app (the app library reads no environment variable):
// which runtime the Khronos loader loads, what the loader and the simulated runtime take from
// the environment (their own interfaces), the app's files under the asset rule (paths.hpp), and
// the options `drape xr` and `drape run` share.
#pragma once

#include <CLI/CLI.hpp>
#include <initializer_list>
#include <string>
#include <vector>

#include "xr_app/app/xr_app.hpp"

namespace drape::app {

// The runtime the loader will load: XR_RUNTIME_JSON when set; else the system's active runtime
// (openxr/1/active_runtime.json below $XDG_CONFIG_HOME, ~/.config, $XDG_CONFIG_DIRS or
// /etc/xdg); else the simulated runtime (paths.hpp), which XR_RUNTIME_JSON is then pointed at.
// Returns the manifest ("" = the system's active runtime); *simulated (when given) says whether
// it fell back to the simulated runtime (no runtime configured).
std::string select_runtime(bool* simulated = nullptr);

// Whether there is a desktop to open a window on (DISPLAY or WAYLAND_DISPLAY set).
bool has_display();

// The simulated runtime opens its desktop window (DRAPE_MOCK_WINDOW=1, docs/mock-window.md):
// the person at the desk is the headset's wearer.
void set_mock_window();

// Whether the simulated runtime opens its desktop window (DRAPE_MOCK_WINDOW=1).
bool mock_window();

// Whether the loader will load the simulated runtime: the fallback (`simulated`, from
// select_runtime) or a manifest (XR_RUNTIME_JSON) that is the simulated runtime's own file.
bool simulated_runtime(const std::string& manifest, bool simulated);

// The API layers the loader enables from XR_ENABLE_API_LAYERS (':' or ';' separated).
std::vector<std::string> loader_api_layers();

// The scenario the simulated runtime plays (DRAPE_MOCK_SCENARIO; "" = none).
std::string mock_scenario();
void set_mock_scenario(const std::string& path);

// The options both commands have: --frames, --eye-size, --cloth-res, -v/--verbose (opt's
// values are the defaults) and --assets DIR (applied while parsing: set_assets_dir). Added
// first: it makes --help show every later option's default too.
void add_app_options(CLI::App& cli, XrAppOptions& opt);

// Flags that turn a setting that is on by default off (--no-render, --sim-free, ...).
struct OffSwitch {
  const char* name;
  bool* setting;
  const char* help;
};
void add_off_switches(CLI::App& cli, std::initializer_list<OffSwitch> switches);

// After parsing: resolves `path` (user_or_asset) and checks that it is a file; else prints
// "<command>: <option>: no such file: <path>" and returns false.
bool resolve_input_file(const char* command, const char* option, std::string& path);

// --voice mic|off|FILE.wav, the live voice input (both commands); `voice` stays "" when not
// given.
void add_voice_option(CLI::App& cli, std::string& voice);

// After parsing: XrAppOptions::voice_input from --voice's value `given`: "" (not given) = "mic"
// on a live session (a headset, or the simulated runtime's window without a scenario), none on a
// scripted run; "off" = none; "mic"; else a WAV file, resolved as resolve_input_file does (a
// missing file prints its message and returns false; a malformed one is the session's message).
bool resolve_voice(const char* command, const std::string& given, bool live, std::string& out);

// --hands xr|udp[:ADDR:PORT]|trace FILE|kinect, --kinect-record DIR (into opt.kinect_record),
// --calibration FILE and --calibrate (into opt.calibrate) (both commands).
void add_hands_options(CLI::App& cli, std::vector<std::string>& hands, std::string& calibration,
                       XrAppOptions& opt);

// The file a source's calibration is saved to and loaded from by default:
// $XDG_CONFIG_HOME/drape/calibration-<source>.json (else ~/.config/drape/...; "" when neither
// variable is set).
std::string saved_calibration_file(const std::string& source);

// After parsing: the hands' options into opt (hands, hands_address, hands_port, hands_trace,
// calibration_path; opt.kinect_record is --kinect-record's value). A bad value or a missing file
// prints "<command>: <option>: ..." and returns false (the caller exits with the usage status 2).
// `--hands kinect --kinect-record DIR`: DIR must hold a fakenect recording (DIR/INDEX.txt); the
// process then runs itself again under libfreenect's `fakenect DIR` wrapper (its replay library
// must be loaded in place of libfreenect before the program starts), with FAKENECT_LOOP=0 unless
// set (the recording's end is the Kinect going away); it does not return on success.
// --calibrate (udp, trace or kinect only): opt.calibration_save = saved_calibration_file(source).
// Without --calibration (and not calibrating), an existing saved_calibration_file(source) is
// used (opt.calibration_saved).
bool resolve_hands(const char* command, const std::vector<std::string>& hands,
                   const std::string& calibration, XrAppOptions& opt);

// The command map: `given` when set (already resolved), else assets/commands.json (from the
// working directory, else the assets directory) when present, else "" (the built-in defaults).
std::string commands_file(const std::string& given);

// --record DIR (both commands): record the session there (docs/sessions.md).
void add_record_option(CLI::App& cli, std::string& dir, double& checkpoint_every);
// After parsing: creates `dir` (when set) and checks that a file can be written there; else
// prints "<command>: --record DIR: ..." and returns false.
bool prepare_record_dir(const char* command, const std::string& dir);
// After parsing --garment NAME|FILE (add_app_options): the design file (a name is looked up in
// the assets' designs/), the fabrics file, no board or end-of-session pattern (they read a
// draped panel); false (printed "<command>: --garment...: ...") for a missing design or fabric,
// --garment-fabric without --garment, or a garment with --record, --resume or open.
bool resolve_garment(const char* command, XrAppOptions& opt);

}  // namespace drape::app
