// Output files written whole or not at all: a failed write (a full disk, a write error) leaves
// the previous files of the output folder as they were (docs/faults.md).
#pragma once

#include <functional>
#include <string>

namespace drape::app {

// `write(dir)` writes files into `dir`, the hidden folder out_dir/.partial (emptied first), and
// returns "" or an error. On "" each file written there is moved over its namesake in out_dir
// (a glTF's buffer file keeps the name the glTF gives it); on an error nothing is moved. The
// partial folder is removed either way. Returns "" or the error, the partial folder's paths in
// it named as out_dir's.
std::string write_whole(const std::string& out_dir,
                        const std::function<std::string(const std::string& dir)>& write);

}  // namespace drape::app
