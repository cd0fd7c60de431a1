// Pattern extraction: points along the reference lines on the form, rays from the
// section centres, the hit cloth triangle chosen by zone where layers overlap, barycentric
// coordinates evaluated on the flat cloth -> a closed piece outline with labelled seams.
#pragma once

#include <string>
#include <vector>

#include "sim/draping/mapping.hpp"
#include "sim/draping/panel.hpp"

namespace drape::sim {

// A sewing pattern piece in flat material coordinates (metres), counter-clockwise.
struct PatternPiece {
  std::string name = "piece";
  std::string size = "9AR";
  int quantity = 1;
  std::vector<Vec2> outline;        // closed polygon, the last point is not repeated
  std::vector<Vec3> outline3d;      // where each outline point lies on the draped cloth
  std::vector<Vec3> ref;            // (y, theta, zone) of the reference point of each outline point
  std::vector<int> seg_label;       // label of segment i (outline[i] -> outline[i + 1])
  std::vector<std::string> labels;  // seam names: centre_front, side, waist, hem, dart1_leg1...
  std::vector<int> notches;         // outline indices marked with a notch (dart legs, hip line)
  struct Dart {
    int tip = -1, leg1_top = -1, leg2_top = -1;  // outline indices
    double intake = 0;                           // flat distance between the leg tops (m)
    // The leg the folded dart is pressed onto (1 or 2; 0: not given): the exports draw an arrow
    // across the dart toward it.
    int fold_leg = 0;
  };
  std::vector<Dart> darts;
  std::vector<Vec2> hip_line;         // flat points along the hip line, centre -> side
  std::vector<Vec2> waist_line;       // the same along the waist (session pieces only)
  Vec2 grain_a{0, 0}, grain_b{0, 0};  // grain line (parallel to the warp)
  int loops_removed = 0;              // self-crossing loops cut out of the extracted outline

  int label_index(const std::string& name) const;
  double area() const;                                 // polygon area (m^2)
  double seam_length(const std::string& label) const;  // total length of segments with label
  double hip_width() const;                            // length of the hip polyline
  // Outline indices of one seam in order (empty if absent).
  std::vector<int> seam_points(const std::string& label) const;
};

// The reference lines bounding one quarter piece.
struct PieceLines {
  std::string centre_label = "centre_front";
  double hem_y = 0, hip_y = 0, waist_y = 0;
};

struct ExtractOptions {
  double step = 0.005;  // m between points along each line
};

struct ExtractStats {
  double outline_error_mm = 0;  // max distance to the analytic inverse of the mapping
  double ms = 0;
};

// Extracts the piece from the draped panel. Errors name the line a ray missed.
Result<PatternPiece> extract_piece(const Panel& panel, const MappingSurface& surf,
                                   const PieceMapping& pm, const PieceLines& lines,
                                   const ExtractOptions& opt = {});

// Max distance (m) between the extracted outline and the analytic flat pre-image of its 3D
// reference points under the mapping (valid before relaxation: ~0 expected).
double outline_error_vs_mapping(const PatternPiece& piece, const Panel& panel,
                                const MappingSurface& surf, const PieceMapping& pm);

// Area of the draped 3D cloth inside the piece outline (m^2): the flat/3D area ratio of the
// cloth triangles, weighted by how much of each lies inside the outline, times the piece area.
double draped_area(const PatternPiece& piece, const Panel& panel);

// Cuts self-crossing loops out of a closed outline (the shorter way round, the crossing point
// inserted; notches follow). extract_piece calls it; returns the number of loops removed.
int remove_outline_loops(PatternPiece& piece);

// Fairness of one seam line of the outline: the largest turning angle per millimetre along it
// (deg/mm). At each interior point of the seam the angle between the incoming and the outgoing
// segment is divided by the mean length of the two; the seam's end points (its corners with
// the neighbouring seams) are not counted. A label in several runs (the waist between darts,
// two cut edges) gives the worst run. A fair curve of radius R gives about 57.3 / R(mm);
// a bump a pattern maker would redraw shows as a spike well above that. 0 for a seam of fewer
// than three points or a label the piece lacks.
double seam_fairness(const PatternPiece& piece, const std::string& label);

// The same over a polyline (metres): interior points only.
double polyline_fairness(const std::vector<Vec2>& pts);

// Point-in-polygon by crossing parity.
bool inside_polygon(const std::vector<Vec2>& poly, const Vec2& p);

}  // namespace drape::sim
