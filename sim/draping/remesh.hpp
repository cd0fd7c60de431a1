// Cutting and remeshing a pattern piece for simulation, done as a conforming
// constrained Delaunay triangulation with quality bounds (CGAL Delaunay_mesher_2) instead of node
// removal + gap filling. Vertices keep material coordinates and seam labels.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "sim/draping/pattern_extract.hpp"

namespace drape::sim {

struct RemeshOptions {
  double max_edge = 0.01;      // m: size bound on triangle edges
  double shape_bound = 0.125;  // CGAL's B = sin^2(min angle) bound; 0.125 ~ 20.7 degrees
};

struct RemeshedPiece {
  std::vector<Vec2> material;                     // material coordinates (m)
  std::vector<std::array<int32_t, 3>> triangles;  // counter-clockwise
  std::vector<double> boundary_param;  // -1 interior; else outline parameter i + f on segment i
  std::vector<int> vertex_label;       // -1 interior; else the label of its outline segment
  double min_angle_deg = 0;            // smallest triangle angle
  double max_edge = 0;                 // longest edge (m)
  double area = 0;                     // total triangle area (m^2)
  // Boundary vertices of one seam ordered along the outline, both end corners included.
  std::vector<int> seam_vertices(const PatternPiece& piece, const std::string& label) const;
};

// Triangulates the inside of the piece outline; every outline point is a mesh vertex and every
// outline segment is covered by mesh edges (split where the quality bound needs it).
Result<RemeshedPiece> remesh_piece(const PatternPiece& piece, const RemeshOptions& opt = {});

}  // namespace drape::sim
