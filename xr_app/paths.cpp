#include "xr_app/paths.hpp"

#include <system_error>

namespace drape::app {
namespace fs = std::filesystem;

namespace {
fs::path& assets_override() {
  static fs::path dir;
  return dir;
}
}  // namespace

fs::path executable_dir() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::current_path(ec) : exe.parent_path();
}

void set_assets_dir(const fs::path& dir) {
  assets_override() = dir;
}

fs::path assets_dir() {
  if (!assets_override().empty()) return assets_override();
  return (executable_dir() / ".." / "share" / "drape" / "assets").lexically_normal();
}

fs::path asset(const std::string& relative) {
  return assets_dir() / relative;
}

fs::path user_or_asset(const std::string& path) {
  std::error_code ec;
  if (fs::exists(path, ec)) return path;
  const std::string prefix = "assets/";
  if (path.rfind(prefix, 0) == 0) {
    fs::path p = asset(path.substr(prefix.size()));
    if (fs::exists(p, ec)) return p;
  }
  return path;
}

fs::path mock_runtime_manifest() {
  std::error_code ec;
  const fs::path dir = executable_dir();
  for (const fs::path& p : {dir / "drape_mock_runtime.json",
                            (dir / ".." / "lib" / "drape" / "drape_mock_runtime.json")})
    if (fs::exists(p, ec)) return p.lexically_normal();
  return {};
}

}  // namespace drape::app
