// The horizontal reference lines (waist, hip) on a session's pattern piece, as the design
// pipeline measures them: the line where the draped cloth crosses the line's height, read on
// the flat cloth (material coordinates), from one edge of the piece to the other. The piece's
// width along the line is the polyline's length (PatternPiece::hip_width for the hip).
#pragma once

#include <vector>

#include "sim/core/cloth.hpp"

namespace drape::sim {

// The flat polyline where the draped triangles `tris` of `cloth` cross the height `y`: the
// crossing point on each edge whose ends lie on both sides of y (linear along the edge), joined
// triangle by triangle into runs. Each run's ends (on the mesh boundary) are continued straight
// by `reach` and the run is clipped to the closed `outline` (the piece's outline: cut edges
// there are the smoothed cut strokes, not the mesh's zigzag), so the line ends on the outline.
// The longest run inside the outline; empty when the piece does not cross y.
std::vector<Vec2> session_reference_line(const Cloth& cloth, const std::vector<int>& tris,
                                         const std::vector<Vec2>& outline, double y, double reach);

double polyline_length(const std::vector<Vec2>& line);

}  // namespace drape::sim
