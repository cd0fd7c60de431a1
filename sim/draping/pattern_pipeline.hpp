// The geometric draping pipeline end to end (docs/draping.md): design (data) ->
// slit panels -> mapping -> relaxation -> pattern extraction -> remeshing -> mirror + sew ->
// garment on the form -> SVG/DXF/PDF/glTF + report.json.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "sim/draping/blocks.hpp"
#include "sim/draping/mapping.hpp"
#include "sim/draping/panel.hpp"
#include "sim/draping/pattern_export.hpp"
#include "sim/draping/pattern_extract.hpp"
#include "sim/draping/relax.hpp"
#include "sim/draping/remesh.hpp"
#include "sim/draping/sew.hpp"

namespace drape::sim {

class DressForm;

struct PieceDesign {
  std::string name = "Front";
  std::string centre_line = "centre_front";  // centre_front | centre_back
  std::string side_line = "right_side";      // right_side | left_side
  std::string top_line = "waist";            // waist
  std::string bottom_line = "hem";           // hem | hip
  int quantity = 2;
  PanelDesign panel;
};

struct Design {
  std::string name = "design";
  std::string form = "9AR";
  std::string fabric = "muslin";
  double ease = 0.0;                 // m of girth ease (mapping surface offset ease / 2 pi)
  double seam_allowance = 0.01;      // m, in print
  double length_below_waist = 0.55;  // m: the hem line's height below the waist
  double extraction_step = 0.005;    // m between extracted points
  double remesh_edge = 0.012;        // m: size bound of the remeshed pieces
  int relax_iterations = 200;
  // Flat manipulation after draping: "none" (the draped block as is) or "close_darts" (slash
  // and spread: every dart closed, the hem opened under each dart tip; sim/draping/blocks.hpp).
  std::string flare = "none";
  std::vector<PieceDesign> pieces;
};

// Known reference line names (a design naming any other line is an error).
const std::vector<std::string>& known_lines();

Result<Design> parse_design(const std::string& json_text, const std::string& source);
Result<Design> load_design(const std::string& path);

struct PipelineOptions {
  std::string out_dir;             // empty: write nothing
  double ease = -1;                // >= 0 overrides the design's ease (m)
  double seam_allowance = -1;      // >= 0 overrides the design's print seam allowance (m)
  double spacing = 0;              // > 0 overrides every panel's grid spacing (m)
  double remesh_edge = 0;          // > 0 overrides the remesh size bound (m)
  int relax_iterations = -1;       // >= 0 overrides
  bool use_static_solver = false;  // relax with relax_static (Newton) instead of Gauss-Seidel
  bool grain_control = true;
};

struct PieceReport {
  std::string name;
  double hip_width_mm = 0, waist_seam_mm = 0, waist_width_mm = 0;
  std::vector<double> dart_intake_mm, dart_intake_wanted_mm;
  double outline_error_before_relax_mm = 0;
  double area_piece_cm2 = 0, area_draped_cm2 = 0, area_error_pct = 0;
  GrainDeviation grain_before, grain_after;
  RelaxStats relax;
  int remesh_vertices = 0, remesh_triangles = 0;
  double remesh_min_angle_deg = 0, remesh_max_edge_mm = 0;
  // Per seam line of the exported outline: the largest turning angle per mm (seam_fairness).
  std::vector<std::pair<std::string, double>> fairness_deg_per_mm;
  // Slash and spread (flare "close_darts"): the angle each slash opened, the hem's length.
  std::vector<double> spread_deg;
  double hem_mm = 0;
};

struct PipelineReport {
  std::string design, form;
  double ease_mm = 0;
  double form_hip_girth_mm = 0, form_waist_girth_mm = 0;
  double hip_width_sum_mm = 0, hip_width_error_mm = 0;
  double waist_width_minus_intakes_sum_mm = 0, waist_width_error_mm = 0;
  double area_error_pct = 0;  // worst piece
  double garment_hip_girth_mm = 0, garment_hip_girth_error_pct = 0;
  double garment_waist_girth_mm = 0, garment_waist_girth_error_pct = 0;
  std::string flare = "none";
  double hem_sweep_mm = 0;  // the whole hem (every piece and its mirror image), flat
  // The cut pattern's girth along the hip line (the hip widths plus what the slashes opened
  // there), the sewn garment's hip line measured along the cloth (through folds and pleats),
  // and the difference in per cent of the pattern's.
  double pattern_hip_girth_mm = 0, garment_hip_line_mm = 0, garment_hip_girth_vs_pattern_pct = 0;
  double outline_error_before_relax_mm = 0;
  double quarter_difference_mm = 0;  // (hip - waist) / 4
  double mapping_extraction_ms = 0, relax_ms = 0, remesh_ms = 0, sew_ms = 0, export_ms = 0;
  double pipeline_ms = 0;
  std::string relax_backend;
  std::vector<PieceReport> pieces;
  std::vector<std::string> files;
  std::string to_json() const;
};

struct PipelineResult {
  Design design;
  std::vector<Panel> panels;
  std::vector<PieceMapping> mappings;
  std::vector<PatternPiece> pieces;
  std::vector<RemeshedPiece> meshes;
  std::vector<SpreadPiece> spread;  // per piece, when the design closes its darts
  Garment garment;
  PipelineReport report;
};

Result<PipelineResult> run_pattern_pipeline(const Design& design, const DressForm& form,
                                            const FabricParams& fabric,
                                            const PipelineOptions& opt = {});

}  // namespace drape::sim
