// Pattern blocks derived from a draped block by flat pattern manipulation: the A-line / flared
// skirt by slash and spread (each dart closed by turning the part of the piece beyond it about
// the dart tip, which opens a wedge at the hem under the tip), and the way back from the spread
// piece to the block for placing it on the form.
#pragma once

#include <string>
#include <vector>

#include "sim/draping/pattern_extract.hpp"

namespace drape::sim {

// One slash of slash and spread: the slash runs from the dart tip along `dir` (down the dart's
// straight leg to the hem); the part of the piece beyond it (the side part) is turned by `angle`
// (radians, counter-clockwise positive) about the tip, closing the dart and opening a wedge of
// |angle| at the hem.
struct SpreadStep {
  Vec2 tip{0, 0};
  Vec2 dir{0, -1};     // unit direction of the slash, from the tip toward the hem
  double angle = 0;    // rotation of the side part (closes the dart)
  double hem_gap = 0;  // m: width the hem opens by (chord between the two slash ends)
  double hip_gap = 0;  // m: opening across the hip line (0 when the tip is below the hip)
};

struct SpreadPiece {
  PatternPiece piece;  // no darts left; the hem runs across each wedge as an arc about the tip
  std::vector<SpreadStep> steps;
  double hip_width = 0;           // m: the hip line's length on the cloth (slash openings excluded)
  double hem_length = 0;          // m: the hem seam's length (the piece's share of the hem sweep)
  double dart_intake_closed = 0;  // m: sum of the intakes the closed darts took at the waist
};

// Closes every dart of a draped block and spreads the hem (slash and spread). `arc_step` is the
// point spacing along each new hem arc. Errors name the piece and the dart whose slash does
// not reach the hem.
Result<SpreadPiece> slash_and_spread(const PatternPiece& block, double arc_step = 0.005);

// Where a point of the spread piece lies in the block before spreading (the side parts turned
// back; a point in a wedge, new cloth, goes onto its slash at its distance from the tip), and in
// `extra_arc` how much cloth the wedges it lies in or beyond add before it along its row (wedge
// angle x the row's distance down the slash): the pipeline spreads the flare round the form by it.
Vec2 unspread_arc(const SpreadPiece& sp, const Vec2& m, double* extra_arc);
// The cloth all of the piece's wedges add along the material row v (m).
double spread_arc_at_row(const SpreadPiece& sp, double v);

}  // namespace drape::sim
