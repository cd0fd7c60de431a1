// The basic bodice block draped geometrically on the form (docs/draping.md, "Bodice"), and the
// sleeveless dress that joins it to a skirt at the waist.
//
// Each half piece (front, back) is the part of the form between its centre line, the side seam
// (the side line from the waist to the armpit), the armhole, the shoulder seam (the side line
// from the shoulder point up to the neck point), the neckline and the waist. Two dart lines
// (the waist dart straight up from the waist to the apex: the bust point in front, the shoulder
// blade at the back; the shoulder dart from the middle of the shoulder seam down to the same
// apex) split it into a centre zone and a side zone, joined only at the apex. Each zone is
// meshed in rows (heights) and columns (even arc steps along each section between the zone's
// two bounding lines), mapped along the grain (weft: arc length along the section from the
// centre line; warp: length up the cloth from the waist), and relaxed flat so its edges take
// their lengths on the form. The side zone then turns about the apex to keep its grain parallel
// to the centre line's: where the form curves, the zones part at the waist and the shoulder and
// the gaps are the darts (the excess taken out).
#pragma once

#include <string>
#include <vector>

#include "sim/draping/pattern_extract.hpp"
#include "sim/draping/pattern_pipeline.hpp"
#include "sim/draping/sew.hpp"

namespace drape::sim {

class DressForm;
class MappingSurface;

// One half piece of the bodice (metres and radians).
struct BodicePieceDesign {
  std::string name = "Bodice front";
  std::string centre_line = "centre_front";  // centre_front | centre_back
  double neck_depth = 0.07;                  // centre-line neck point below the form's neck height
  double armhole_inset = 0.04;    // arc from the side line to the armhole at its middle height
  double apex_angle = 0.65;       // apex angle from the centre line (rad)
  double apex_above_bust = 0.0;   // apex height above the bust line
  double shoulder_dart_at = 0.5;  // shoulder dart position along the shoulder, from the neck
  int quantity = 2;
};

struct BodiceDesign {
  std::string name = "bodice";
  std::string form = "9AR";
  std::string fabric = "muslin";
  double ease = 0.0;             // m of girth ease (the surface offset, as for the skirts)
  double seam_allowance = 0.01;  // m
  double row_step = 0.004;       // m between mesh rows
  double column_step = 0.006;    // m between mesh columns (at most)
  int relax_iterations = 3000;   // flat relaxation sweeps per zone
  int sew_iterations = 200;      // relaxation sweeps of the sewn bodice on the form
  std::vector<BodicePieceDesign> pieces;
};

// A dress: a bodice design and a skirt design joined at the waist.
struct DressDesign {
  std::string name = "dress";
  BodiceDesign bodice;
  Design skirt;
};

// Parses a design file of "type": "bodice" (`source` names it in errors; every error names the
// field). `dir` is where the named parts of a dress design are looked up.
Result<BodiceDesign> parse_bodice_design(const std::string& json_text, const std::string& source);
Result<DressDesign> parse_dress_design(const std::string& json_text, const std::string& source,
                                       const std::string& designs_dir);
// The design file's "type" ("skirt" when absent), or an error naming the file.
Result<std::string> design_type(const std::string& path);

// One bound of the fit report: a measured value against its target.
struct FitCheck {
  std::string name;  // e.g. "Bodice front waist width"
  std::string unit;  // "mm" or "%"
  double value = 0, target = 0, error = 0, bound = 0;
  bool pass = false;
};

struct BodicePieceReport {
  std::string name;
  double bust_width_mm = 0, bust_arc_mm = 0;    // pattern bust line vs the surface's arc
  double waist_width_mm = 0, waist_arc_mm = 0;  // waist seam without the dart vs the arc
  double waist_dart_mm = 0, shoulder_dart_mm = 0;
  double waist_dart_legs_mm[2] = {0, 0}, shoulder_dart_legs_mm[2] = {0, 0};
  double shoulder_mm = 0, side_mm = 0, armhole_mm = 0, neckline_mm = 0;
  double area_piece_cm2 = 0, area_draped_cm2 = 0, area_error_pct = 0;
  double max_strain_pct = 0, rms_strain_pct = 0;  // flat edges against the form's
  std::vector<std::pair<std::string, double>> fairness_deg_per_mm;
};

struct BodiceReport {
  std::string design, form;
  double ease_mm = 0;
  double form_bust_girth_mm = 0, form_waist_girth_mm = 0;
  double pattern_bust_girth_mm = 0, pattern_waist_girth_mm = 0;  // both halves, darts closed
  double sewn_bust_girth_mm = 0, sewn_waist_girth_mm = 0;
  double side_seam_mismatch_mm = 0, shoulder_seam_mismatch_mm = 0;  // front - back
  std::vector<BodicePieceReport> pieces;
  std::vector<FitCheck> checks;
  double pipeline_ms = 0;
  bool all_pass() const;
};

struct BodiceResult {
  std::vector<PatternPiece> pieces;  // right halves, counter-clockwise, darts as folded
  BodiceReport report;
  // The sewn bodice as cloth for the simulation (garment_sim.hpp): every zone of every piece
  // (centre and side, right half and its mirror image) its own vertices with the zone's flat
  // pattern as material coordinates, at the geometrically relaxed placement on the form; the
  // two halves of a zone one vertex on the centre line (the same flat point); the dart legs,
  // side seams and shoulder seams hard ties between nodes the zones share on the form; the waist
  // row as waist_vertices.
  Garment garment;
};

// Drapes the bodice on the form and measures it; writes nothing.
Result<BodiceResult> drape_bodice(const BodiceDesign& design, const DressForm& form);

struct DressReport {
  BodiceReport bodice;
  PipelineReport skirt;
  // Per piece pair (front, back): the bodice's waist seam less its dart against the skirt's
  // waist seam less its darts (mm), and the checks.
  std::vector<std::pair<std::string, double>> waist_mismatch_mm;
  std::vector<FitCheck> checks;
};

// Writes the pieces as pattern.svg, pattern.dxf, pattern_a4.pdf, pattern_letter.pdf and
// `report_json` as report.json into out_dir; returns "" or an error naming the file.
std::string write_pattern_files(const std::string& out_dir, const std::vector<PatternPiece>& pieces,
                                const std::string& style, double seam_allowance,
                                const std::string& report_json, std::vector<std::string>* files);

std::string bodice_report_json(const BodiceReport& r, const std::vector<std::string>& files);
std::string dress_report_json(const DressReport& r, const std::vector<std::string>& files);

// The sewn dress as cloth for the simulation: the bodice's garment and the skirt's (its own
// ties kept, indices moved on) in one, each bodice waist vertex tied to the nearest point of the
// skirt's waist seam (the waist seam as ties); the skirt's waist vertices are the dress's.
Result<Garment> dress_garment(const Garment& bodice, const Garment& skirt);

// Joins the bodice's and the skirt's pieces into the dress's report: waist seams compared.
DressReport dress_report(const BodiceResult& bodice, const PipelineResult& skirt);

}  // namespace drape::sim
