// Where the `drape` executable finds its assets and the simulated OpenXR runtime. One rule for
// the build tree and an install, relative to the executable, so a moved install still works:
//   assets   --assets DIR when given, else <exe dir>/../share/drape/assets
//            (build tree: build/share/drape/assets links to the source's assets/;
//             install: <prefix>/bin/drape and <prefix>/share/drape/assets)
//   runtime  <exe dir>/drape_mock_runtime.json (build tree: both in build/bin), else
//            <exe dir>/../lib/drape/drape_mock_runtime.json (install)
// `cmake --install` lays out <prefix>/bin, lib/drape and share/drape/assets so; a moved prefix
// still works (ctest build_relocatable_install).
// The libraries take paths as arguments; only the executable applies this rule.
#pragma once

#include <filesystem>
#include <string>

namespace drape::app {

// The directory of the running executable (/proc/self/exe).
std::filesystem::path executable_dir();
// Overrides the assets directory (the --assets option); empty restores the rule.
void set_assets_dir(const std::filesystem::path& dir);
// The assets directory under the rule above (not checked for existence).
std::filesystem::path assets_dir();
// A file below the assets directory: asset("fabrics.json"), asset("scenarios/default.json").
std::filesystem::path asset(const std::string& relative);
// A path given by the user: as given when it exists (relative to the working directory), else
// below the assets directory when it starts with "assets/" and exists there, else as given.
std::filesystem::path user_or_asset(const std::string& path);
// The simulated runtime's manifest under the rule above; empty when neither place has it.
std::filesystem::path mock_runtime_manifest();

}  // namespace drape::app
