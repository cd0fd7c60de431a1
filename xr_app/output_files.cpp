// Output files written whole or not at all (see output_files.hpp).
#include "xr_app/output_files.hpp"

#include <filesystem>
#include <system_error>

namespace drape::app {

std::string write_whole(const std::string& out_dir,
                        const std::function<std::string(const std::string& dir)>& write) {
  namespace fs = std::filesystem;
  const fs::path out(out_dir);
  const fs::path partial = out / ".partial";
  std::error_code ec;
  fs::remove_all(partial, ec);
  fs::create_directories(partial, ec);
  if (ec) return partial.string() + ": cannot create: " + ec.message();
  std::string e = write(partial.string());
  if (e.empty()) {
    for (const auto& f : fs::directory_iterator(partial, ec)) {
      fs::rename(f.path(), out / f.path().filename(), ec);
      if (ec) {
        e = (out / f.path().filename()).string() + ": cannot move into place: " + ec.message();
        break;
      }
    }
  }
  fs::remove_all(partial, ec);
  // The messages name the files the user knows.
  const std::string from = partial.string(), to = out.string();
  for (size_t at = e.find(from); at != std::string::npos; at = e.find(from, at + to.size()))
    e.replace(at, from.size(), to);
  return e;
}

}  // namespace drape::app
