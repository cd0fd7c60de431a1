// The session's pattern: the draped cloth's pieces with the cut strokes as their cut edges.
#include "xr_app/app/session_pattern_export.hpp"

#include <cstdio>
#include <filesystem>

#include "sim/draping/session_pattern.hpp"
#include "sim/form/dress_form.hpp"
#include "xr_app/app/pattern_board.hpp"

namespace drape::app {

namespace {
// Writes the extracted pieces (or says why there are none) into <out_dir>/pattern/session-<n>/.
SessionPatternExport write_pieces(const sim::Result<std::vector<sim::PatternPiece>>& pieces,
                                  size_t cuts, const std::string& out_dir, int n) {
  SessionPatternExport out;
  if (!pieces) {
    out.error = pieces.error();
    out.summary = "pattern: " + out.error;
    return out;
  }
  const std::string dir = out_dir + "/pattern/session-" + std::to_string(n);
  auto rep = sim::write_session_pattern(dir, *pieces, 0.01, "session-" + std::to_string(n));
  if (!rep) {
    out.error = rep.error();
    out.summary = "pattern: " + out.error;
    return out;
  }
  out.dir = dir;
  for (const std::string& f : rep->files) out.files.push_back(dir + "/" + f);
  char line[256];
  std::snprintf(line, sizeof line, "pattern: %zu piece(s), %zu cut edge(s) -> %s", pieces->size(),
                cuts, dir.c_str());
  out.summary = line;
  return out;
}
}  // namespace

SessionPatternExport export_session_pattern(const sim::World& w, const sim::OperationsState& ops,
                                            const std::string& out_dir, int n) {
  std::vector<std::vector<sim::Vec2>> strokes;
  for (const sim::CutStroke& s : ops.cut_strokes)
    if (s.material.size() >= 2) strokes.push_back(s.material);
  sim::SessionPatternOptions opt;
  if (w.scene.form) {
    opt.waist_y = w.scene.form->landmarks().waist_y;
    opt.hip_y = w.scene.form->landmarks().hip_y;
  }
  return write_pieces(sim::extract_session_pieces(w.cloth, strokes, opt), strokes.size(), out_dir,
                      n);
}

SessionPatternExport export_snapshot_pattern(const sim::SceneSnapshot& snap,
                                             const std::string& out_dir, int n) {
  size_t cuts = 0;
  for (const auto& s : snap.cut_strokes_material) cuts += s.size() >= 2;
  SessionPatternExport out = write_pieces(snapshot_pieces(snap), cuts, out_dir, n);
  out.tick = snap.tick;
  if (!out.error.empty() || out.summary.empty()) return out;
  out.summary += " (tick " + std::to_string(snap.tick) + ")";
  return out;
}

}  // namespace drape::app
