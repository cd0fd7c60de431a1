// The pattern of the session's cloth, as the user draped it (pinned, cut, mapped): extracted
// from a copy of the cloth and the operations' smoothed cut strokes into
// <out_dir>/pattern/session-<n>/ (sim/draping/session_pattern.hpp).
#pragma once

#include <string>
#include <vector>

#include "sim/ops/operations.hpp"
#include "sim/runtime/world.hpp"

namespace drape::app {

struct SessionPatternExport {
  std::string dir;                 // where the files went ("" when nothing was written)
  std::vector<std::string> files;  // full paths
  std::string summary;             // one line for the log and the feedback panel
  std::string error;               // "" when written
};

// Extracts and writes the pattern of the cloth in `w` (its cut strokes from `ops`). `n` numbers
// the export within the session. Never throws; an error is returned in the result.
SessionPatternExport export_session_pattern(const sim::World& w, const sim::OperationsState& ops,
                                            const std::string& out_dir, int n);

}  // namespace drape::app
