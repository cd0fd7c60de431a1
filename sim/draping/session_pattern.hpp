// The pattern of the cloth as the user draped it: each connected piece of the (pinned, cut,
// mapped) cloth becomes a pattern piece in its flat material coordinates. The outline is the
// piece's boundary in material space, except where a cut ran: there the smoothed cut stroke the
// operations kept in material coordinates replaces the grid's zigzag of split edges. Notches
// mark where the form's reference lines (waist, hip) cross the piece's edge on the draped
// cloth; the grain line runs along the warp (v).
#pragma once

#include <string>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/draping/pattern_extract.hpp"

namespace drape::sim {

struct SessionPatternOptions {
  std::string size = "9AR";  // written on each piece
  double waist_y = -1;       // reference line heights on the draped cloth (m); < 0: none
  double hip_y = -1;
  double min_piece_area = 1e-4;  // m^2: smaller pieces (scraps) are left out
  // A boundary vertex within this distance (material, m) of a cut stroke lies on that cut;
  // <= 0: 0.75 of the cloth's grid spacing.
  double cut_tolerance = 0;
};

// Labels of the outline's segments: "cut" (along a smoothed cut stroke) and "edge" (the panel's
// own edge, as woven or folded).
inline constexpr const char* kSessionCutLabel = "cut";
inline constexpr const char* kSessionEdgeLabel = "edge";

// Extracts the pieces; `cut_strokes_uv` are the smoothed strokes of the cuts (material space).
// Errors name what is wrong with the cloth (no triangles, sizes that disagree).
Result<std::vector<PatternPiece>> extract_session_pieces(
    const Cloth& cloth, const std::vector<std::vector<Vec2>>& cut_strokes_uv,
    const SessionPatternOptions& opt = {});

struct SessionPatternReport {
  std::vector<std::string> files;  // written, relative to the output directory
  std::string to_json(const std::vector<PatternPiece>& pieces) const;
};

// Writes pattern.svg, pattern.dxf, pattern_a4.pdf, pattern_letter.pdf and report.json (per
// piece: area, seam lengths and fairness per label, notches) into `dir` (created). Returns the
// report, or an error naming the file that failed.
Result<SessionPatternReport> write_session_pattern(const std::string& dir,
                                                   const std::vector<PatternPiece>& pieces,
                                                   double seam_allowance, const std::string& style);

}  // namespace drape::sim
