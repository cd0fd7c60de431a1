// The session's pattern: the draped cloth's pieces with the cut strokes as their cut edges.
#include "xr_app/app/session_pattern_export.hpp"

#include <cstdio>
#include <filesystem>

#include "sim/draping/session_pattern.hpp"
#include "sim/form/dress_form.hpp"

namespace drape::app {

SessionPatternExport export_session_pattern(const sim::World& w, const sim::OperationsState& ops,
                                            const std::string& out_dir, int n) {
  SessionPatternExport out;
  std::vector<std::vector<sim::Vec2>> strokes;
  for (const sim::CutStroke& s : ops.cut_strokes)
    if (s.material.size() >= 2) strokes.push_back(s.material);
  sim::SessionPatternOptions opt;
  if (w.scene.form) {
    opt.waist_y = w.scene.form->landmarks().waist_y;
    opt.hip_y = w.scene.form->landmarks().hip_y;
  }
  auto pieces = sim::extract_session_pieces(w.cloth, strokes, opt);
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
                strokes.size(), dir.c_str());
  out.summary = line;
  return out;
}

}  // namespace drape::app
