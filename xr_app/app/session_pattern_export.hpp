// The pattern of the session's cloth, as the user draped it (pinned, cut, mapped): extracted
// from a copy of the cloth and the operations' smoothed cut strokes into
// <out_dir>/pattern/session-<n>/ (sim/draping/session_pattern.hpp), at the session's end or, from a
// snapshot, whenever asked.
#pragma once

#include <cstdint>
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
  uint64_t tick = 0;               // the sim tick of the snapshot it came from (mid-session)
};

// Extracts and writes the pattern of the cloth in `w` (its cut strokes from `ops`). `n` numbers
// the export within the session. Never throws; an error is returned in the result.
SessionPatternExport export_session_pattern(const sim::World& w, const sim::OperationsState& ops,
                                            const std::string& out_dir, int n);

// The same from a published snapshot of the sim (its cloth and its finished cuts' strokes), on
// any thread: a pattern asked for mid-session (app/pattern_board.hpp).
SessionPatternExport export_snapshot_pattern(const sim::SceneSnapshot& snap,
                                             const std::string& out_dir, int n);

}  // namespace drape::app
