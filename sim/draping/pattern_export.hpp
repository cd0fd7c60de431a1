// Pattern output for people and CAD: SVG (mm), DXF in the AAMA/ASTM D6673 style (ASCII R12),
// PDF tiled at 1:1 on A4 or Letter (cairo) with registration marks, page labels and a 10 cm
// scale-check square. Seam allowance is added in print (0 for simulation).
#pragma once

#include <string>
#include <vector>

#include "sim/draping/pattern_extract.hpp"

namespace drape::sim {

struct ExportOptions {
  double seam_allowance = 0.01;  // m, added outside the seam line (cut line); 0 = none
  std::string style = "drape";   // design name written into the files
};

struct Paper {
  std::string name;
  double width_mm = 210, height_mm = 297;
  static Paper a4() { return {"A4", 210.0, 297.0}; }
  static Paper letter() { return {"Letter", 215.9, 279.4}; }
};

// Cut line of a piece: the outline with its dart openings bridged (waist straight across each
// dart), offset outward by the seam allowance with mitred corners (m). Equals the bridged
// outline when the allowance is 0.
std::vector<Vec2> cut_line(const PatternPiece& piece, double seam_allowance);

// Each returns "" or an error message naming the file.
std::string write_svg(const std::string& path, const std::vector<PatternPiece>& pieces,
                      const ExportOptions& opt);
std::string write_dxf(const std::string& path, const std::vector<PatternPiece>& pieces,
                      const ExportOptions& opt);
struct PdfLayout {
  int pages = 0, cols = 0, rows = 0;  // pages includes the cover page with the scale square
};
std::string write_pdf(const std::string& path, const std::vector<PatternPiece>& pieces,
                      const ExportOptions& opt, const Paper& paper, PdfLayout* layout = nullptr);

// Where the cover page draws its 10 cm check square (mm from the top-left corner).
inline constexpr double kScaleSquareX = 20.0, kScaleSquareY = 60.0, kScaleSquareSize = 100.0;

}  // namespace drape::sim
