// SVG / DXF (AAMA-style R12) / tiled PDF output of pattern pieces.
#include "sim/draping/pattern_export.hpp"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace drape::sim {
namespace {

constexpr double kMm = 1000.0;    // m -> mm
constexpr double kMargin = 20.0;  // mm around and between pieces in the layout
constexpr double kNotch = 6.0;    // mm notch length

Vec2 edge_normal(const Vec2& a, const Vec2& b) {  // outward for a counter-clockwise polygon
  const Vec2 d = (b - a).normalized();
  return Vec2(d.y(), -d.x());
}

std::vector<Vec2> offset_polygon(const std::vector<Vec2>& p, double d) {
  const size_t n = p.size();
  if (d == 0 || n < 3) return p;
  std::vector<Vec2> out(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec2 n1 = edge_normal(p[(i + n - 1) % n], p[i]), n2 = edge_normal(p[i], p[(i + 1) % n]);
    const double c = 1 + n1.dot(n2);
    Vec2 m = c > 1e-6 ? Vec2((n1 + n2) / c) : n2;
    if (m.norm() > 3) m *= 3 / m.norm();  // miter limit
    out[i] = p[i] + d * m;
  }
  return out;
}

Vec2 vertex_normal(const PatternPiece& pc, int i) {
  const int n = static_cast<int>(pc.outline.size());
  const Vec2 a = edge_normal(pc.outline[(i + n - 1) % n], pc.outline[i]);
  const Vec2 b = edge_normal(pc.outline[i], pc.outline[(i + 1) % n]);
  return (a + b).normalized();
}

// Piece placement in the layout: mm, y up, pieces side by side.
struct Placed {
  const PatternPiece* piece;
  std::vector<Vec2> cut, seam;  // mm in layout coordinates
  Vec2 shift;                   // layout = piece * 1000 + shift
  Vec2 lo, hi;
};

struct Layout {
  std::vector<Placed> pieces;
  double width = 0, height = 0;  // mm
  Vec2 map(const Placed& p, const Vec2& m) const { return m * kMm + p.shift; }
};

Layout make_layout(const std::vector<PatternPiece>& pieces, double sa) {
  Layout L;
  double x = kMargin;
  for (const PatternPiece& pc : pieces) {
    Placed p;
    p.piece = &pc;
    const std::vector<Vec2> cut = cut_line(pc, sa);
    Vec2 lo(1e9, 1e9), hi(-1e9, -1e9);
    for (const Vec2& q : cut) {
      lo = lo.cwiseMin(q * kMm);
      hi = hi.cwiseMax(q * kMm);
    }
    p.shift = Vec2(x - lo.x(), kMargin + 20.0 - lo.y());  // room for the texts below
    for (const Vec2& q : cut) p.cut.push_back(q * kMm + p.shift);
    for (const Vec2& q : pc.outline) p.seam.push_back(q * kMm + p.shift);
    p.lo = lo + p.shift;
    p.hi = hi + p.shift;
    x = p.hi.x() + kMargin;
    L.height = std::max(L.height, p.hi.y() + kMargin);
    L.pieces.push_back(p);
  }
  L.width = x;
  return L;
}

struct Notch {
  Vec2 a, b;  // mm layout: from the cut line inward
};

std::vector<Notch> notches(const Layout& L, const Placed& p, double sa) {
  std::vector<Notch> out;
  for (int i : p.piece->notches) {
    const Vec2 n = vertex_normal(*p.piece, i);
    const Vec2 s = L.map(p, p.piece->outline[i]) + n * sa * kMm;
    out.push_back({s, s - n * kNotch});
  }
  return out;
}

// The fold arrow of a dart: from the middle of the dart, two thirds of the way from the tip to
// the leg tops, across to the leg it is pressed onto (in the points' own units).
std::pair<Vec2, Vec2> fold_arrow(const std::vector<Vec2>& seam, const PatternPiece::Dart& d) {
  const Vec2 tip = seam[d.tip], onto = seam[d.fold_leg == 1 ? d.leg1_top : d.leg2_top];
  const Vec2 mid = 0.5 * (seam[d.leg1_top] + seam[d.leg2_top]);
  const Vec2 a = tip + (2.0 / 3.0) * (mid - tip), b = tip + (2.0 / 3.0) * (onto - tip);
  return {a, a + 1.6 * (b - a)};
}

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", v);
  return b;
}

}  // namespace

std::vector<Vec2> cut_line(const PatternPiece& pc, double sa) {
  const int n = static_cast<int>(pc.outline.size());
  std::vector<bool> skip(n, false);
  for (const auto& d : pc.darts) {
    // Points strictly between the two leg tops along the outline (the dart V) are bridged.
    for (int i = (d.leg2_top + 1) % n, guard = 0; i != d.leg1_top && guard < n;
         i = (i + 1) % n, ++guard)
      skip[i] = true;
    if (skip[d.leg1_top]) {  // the V runs the other way round (reversed outline)
      std::fill(skip.begin(), skip.end(), false);
      for (const auto& e : pc.darts)
        for (int i = (e.leg1_top + 1) % n, g2 = 0; i != e.leg2_top && g2 < n; i = (i + 1) % n, ++g2)
          skip[i] = true;
      break;
    }
  }
  std::vector<Vec2> bridged;
  for (int i = 0; i < n; ++i)
    if (!skip[i]) bridged.push_back(pc.outline[i]);
  return offset_polygon(bridged, sa);
}

std::string write_svg(const std::string& path, const std::vector<PatternPiece>& pieces,
                      const ExportOptions& opt) {
  const Layout L = make_layout(pieces, opt.seam_allowance);
  std::ofstream f(path);
  if (!f) return path + ": cannot open for writing";
  const auto X = [&](const Vec2& p) { return fmt(p.x()) + "," + fmt(L.height - p.y()); };
  f << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << fmt(L.width) << "mm\" height=\""
    << fmt(L.height) << "mm\" viewBox=\"0 0 " << fmt(L.width) << " " << fmt(L.height) << "\">\n"
    << "<title>" << opt.style << " pattern (units: mm, scale 1:1)</title>\n"
    << "<defs><marker id=\"arrow\" markerWidth=\"6\" markerHeight=\"6\" refX=\"5\" refY=\"3\" "
       "orient=\"auto-start-reverse\"><path d=\"M0,0 L6,3 L0,6 z\" "
       "fill=\"black\"/></marker></defs>\n";
  for (const Placed& p : L.pieces) {
    const PatternPiece& pc = *p.piece;
    f << "<g id=\"" << pc.name << "\">\n<path class=\"cut\" fill=\"none\" stroke=\"black\" "
      << "stroke-width=\"0.5\" d=\"M";
    for (size_t i = 0; i < p.cut.size(); ++i) f << (i ? " L" : "") << X(p.cut[i]);
    f << " Z\"/>\n";
    if (opt.seam_allowance > 0) {
      f << "<path class=\"seam\" fill=\"none\" stroke=\"black\" stroke-width=\"0.3\" "
           "stroke-dasharray=\"3,2\" d=\"M";
      for (size_t i = 0; i < p.seam.size(); ++i) f << (i ? " L" : "") << X(p.seam[i]);
      f << " Z\"/>\n";
    }
    for (const auto& d : pc.darts)
      for (int top : {d.leg1_top, d.leg2_top})
        f << "<line class=\"dart\" x1=\"" << X(p.seam[d.tip]).substr(0, X(p.seam[d.tip]).find(','))
          << "\" y1=\"" << fmt(L.height - p.seam[d.tip].y()) << "\" x2=\"" << fmt(p.seam[top].x())
          << "\" y2=\"" << fmt(L.height - p.seam[top].y())
          << "\" stroke=\"blue\" stroke-width=\"0.3\"/>\n";
    for (const auto& d : pc.darts) {
      if (d.fold_leg == 0) continue;
      const auto [a, b] = fold_arrow(p.seam, d);
      f << "<line class=\"fold\" x1=\"" << fmt(a.x()) << "\" y1=\"" << fmt(L.height - a.y())
        << "\" x2=\"" << fmt(b.x()) << "\" y2=\"" << fmt(L.height - b.y())
        << "\" stroke=\"blue\" stroke-width=\"0.3\" marker-end=\"url(#arrow)\"/>\n";
    }
    const Vec2 ga = L.map(p, pc.grain_a), gb = L.map(p, pc.grain_b);
    f << "<line class=\"grain\" x1=\"" << fmt(ga.x()) << "\" y1=\"" << fmt(L.height - ga.y())
      << "\" x2=\"" << fmt(gb.x()) << "\" y2=\"" << fmt(L.height - gb.y())
      << "\" stroke=\"black\" stroke-width=\"0.4\" marker-start=\"url(#arrow)\" "
         "marker-end=\"url(#arrow)\"/>\n";
    for (const Notch& nt : notches(L, p, opt.seam_allowance))
      f << "<line class=\"notch\" x1=\"" << fmt(nt.a.x()) << "\" y1=\"" << fmt(L.height - nt.a.y())
        << "\" x2=\"" << fmt(nt.b.x()) << "\" y2=\"" << fmt(L.height - nt.b.y())
        << "\" stroke=\"red\" stroke-width=\"0.4\"/>\n";
    const Vec2 t = 0.5 * (ga + gb) + Vec2(4, 0);
    f << "<text x=\"" << fmt(t.x()) << "\" y=\"" << fmt(L.height - t.y())
      << "\" font-size=\"6\" font-family=\"sans-serif\">" << pc.name << " · size " << pc.size
      << " · cut " << pc.quantity << "</text>\n</g>\n";
  }
  f << "</svg>\n";
  return f ? "" : path + ": write failed";
}

std::string write_dxf(const std::string& path, const std::vector<PatternPiece>& pieces,
                      const ExportOptions& opt) {
  const Layout L = make_layout(pieces, opt.seam_allowance);
  std::ofstream f(path);
  if (!f) return path + ": cannot open for writing";
  const auto g = [&](int code, const std::string& v) { f << code << "\n" << v << "\n"; };
  const auto num = [&](int code, double v) { g(code, fmt(v)); };
  const auto line = [&](const std::string& layer, const Vec2& a, const Vec2& b) {
    g(0, "LINE");
    g(8, layer);
    num(10, a.x());
    num(20, a.y());
    num(30, 0);
    num(11, b.x());
    num(21, b.y());
    num(31, 0);
  };
  const auto text = [&](const std::string& layer, const Vec2& p, double h, const std::string& s) {
    g(0, "TEXT");
    g(8, layer);
    num(10, p.x());
    num(20, p.y());
    num(30, 0);
    num(40, h);
    g(1, s);
  };
  const auto polyline = [&](const std::string& layer, const std::vector<Vec2>& pts, bool closed) {
    g(0, "POLYLINE");
    g(8, layer);
    g(66, "1");
    num(10, 0);
    num(20, 0);
    num(30, 0);
    g(70, closed ? "1" : "0");
    for (const Vec2& q : pts) {
      g(0, "VERTEX");
      g(8, layer);
      num(10, q.x());
      num(20, q.y());
      num(30, 0);
    }
    g(0, "SEQEND");
    g(8, layer);
  };
  g(0, "SECTION");
  g(2, "HEADER");
  g(9, "$ACADVER");
  g(1, "AC1009");
  g(9, "$INSUNITS");
  g(70, "4");
  g(9, "$MEASUREMENT");
  g(70, "1");
  g(0, "ENDSEC");
  g(0, "SECTION");
  g(2, "TABLES");
  g(0, "TABLE");
  g(2, "LTYPE");
  g(70, "1");
  g(0, "LTYPE");
  g(2, "CONTINUOUS");
  g(70, "0");
  g(3, "Solid line");
  g(72, "65");
  g(73, "0");
  num(40, 0);
  g(0, "ENDTAB");
  const char* layers[] = {"0", "1", "4", "7", "8", "14"};
  g(0, "TABLE");
  g(2, "LAYER");
  g(70, "6");
  for (const char* l : layers) {
    g(0, "LAYER");
    g(2, l);
    g(70, "0");
    g(62, "7");
    g(6, "CONTINUOUS");
  }
  g(0, "ENDTAB");
  g(0, "ENDSEC");
  // One block per piece in piece coordinates (mm); inserted at its layout position.
  g(0, "SECTION");
  g(2, "BLOCKS");
  for (const Placed& p : L.pieces) {
    const PatternPiece& pc = *p.piece;
    const auto loc = [&](const Vec2& q) { return Vec2(q - p.shift); };
    g(0, "BLOCK");
    g(8, "0");
    g(2, pc.name);
    g(70, "0");
    num(10, 0);
    num(20, 0);
    num(30, 0);
    g(3, pc.name);
    std::vector<Vec2> cut, seam;
    for (const Vec2& q : p.cut) cut.push_back(loc(q));
    for (const Vec2& q : p.seam) seam.push_back(loc(q));
    polyline("1", cut, true);                                // boundary (cut line)
    if (opt.seam_allowance > 0) polyline("14", seam, true);  // sew line
    line("7", pc.grain_a * kMm, pc.grain_b * kMm);           // grain line
    for (const Notch& nt : notches(L, p, opt.seam_allowance)) line("4", loc(nt.a), loc(nt.b));
    for (const auto& d : pc.darts) {  // internal lines: dart legs
      line("8", seam[d.tip], seam[d.leg1_top]);
      line("8", seam[d.tip], seam[d.leg2_top]);
    }
    for (const auto& d : pc.darts) {  // annotation: which way each dart is pressed
      if (d.fold_leg == 0) continue;
      const auto [a, b] = fold_arrow(seam, d);
      line("15", a, b);
      text("15", b, 3, "FOLD");
    }
    const Vec2 t = 0.5 * (pc.grain_a + pc.grain_b) * kMm + Vec2(5, 0);
    text("1", t, 5, "Piece Name: " + pc.name);
    text("1", t - Vec2(0, 8), 5, "Size: " + pc.size);
    text("1", t - Vec2(0, 16), 5, "Quantity: " + std::to_string(pc.quantity));
    g(0, "ENDBLK");
    g(8, "0");
  }
  g(0, "ENDSEC");
  g(0, "SECTION");
  g(2, "ENTITIES");
  text("1", Vec2(kMargin, 8), 5, "Style Name: " + opt.style);
  text("1", Vec2(kMargin + 120, 8), 5, "Units: METRIC");
  for (const Placed& p : L.pieces) {
    g(0, "INSERT");
    g(8, "0");
    g(2, p.piece->name);
    num(10, p.shift.x());
    num(20, p.shift.y());
    num(30, 0);
  }
  g(0, "ENDSEC");
  g(0, "EOF");
  return f ? "" : path + ": write failed";
}

std::string write_pdf(const std::string& path, const std::vector<PatternPiece>& pieces,
                      const ExportOptions& opt, const Paper& paper, PdfLayout* out) {
  const Layout L = make_layout(pieces, opt.seam_allowance);
  const double pt = 72.0 / 25.4;  // points per mm
  const double margin = 10.0, overlap = 10.0;
  const double pw = paper.width_mm - 2 * margin, ph = paper.height_mm - 2 * margin;
  const double sx = pw - overlap, sy = ph - overlap;
  const int cols = std::max(1, static_cast<int>(std::ceil((L.width - overlap) / sx)));
  const int rows = std::max(1, static_cast<int>(std::ceil((L.height - overlap) / sy)));
  cairo_surface_t* s =
      cairo_pdf_surface_create(path.c_str(), paper.width_mm * pt, paper.height_mm * pt);
  if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS) {
    cairo_surface_destroy(s);
    return path + ": cannot create PDF";
  }
  cairo_t* cr = cairo_create(s);
  cairo_scale(cr, pt, pt);  // user units: mm, origin top-left
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  // Cover page: title, the 10 cm check square, the tile map.
  cairo_set_font_size(cr, 6);
  cairo_move_to(cr, 20, 25);
  cairo_show_text(
      cr, (opt.style + " pattern, 1:1, " + paper.name + ", " + std::to_string(rows * cols) +
           " tiles (" + std::to_string(rows) + " rows x " + std::to_string(cols) + " columns)")
              .c_str());
  cairo_set_font_size(cr, 4);
  cairo_move_to(cr, 20, 35);
  cairo_show_text(cr,
                  "Print at 100% (no fit-to-page). The black square must measure 10 cm x 10 cm.");
  cairo_move_to(cr, 20, 42);
  cairo_show_text(cr,
                  "Trim each page on its margin, align the registration crosses, tape. Units: mm.");
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_rectangle(cr, kScaleSquareX, kScaleSquareY, kScaleSquareSize, kScaleSquareSize);
  cairo_fill(cr);
  cairo_move_to(cr, kScaleSquareX, kScaleSquareY + kScaleSquareSize + 6);
  cairo_show_text(cr, "10 cm scale check");
  const double map_y = kScaleSquareY + kScaleSquareSize + 20, cell = std::min(12.0, 150.0 / cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      cairo_rectangle(cr, 20 + c * cell, map_y + r * cell, cell, cell);
      cairo_set_line_width(cr, 0.2);
      cairo_stroke(cr);
      cairo_move_to(cr, 21 + c * cell, map_y + r * cell + 4);
      cairo_set_font_size(cr, 2.5);
      cairo_show_text(cr,
                      (std::string(1, static_cast<char>('A' + r)) + std::to_string(c + 1)).c_str());
    }
  cairo_show_page(cr);
  const auto draw_poly = [&](const std::vector<Vec2>& pts, double lw, bool dashed) {
    for (size_t i = 0; i < pts.size(); ++i) {
      const double x = pts[i].x(), y = L.height - pts[i].y();
      if (i)
        cairo_line_to(cr, x, y);
      else
        cairo_move_to(cr, x, y);
    }
    cairo_close_path(cr);
    cairo_set_line_width(cr, lw);
    const double dash[] = {3, 2};
    cairo_set_dash(cr, dash, dashed ? 2 : 0, 0);
    cairo_stroke(cr);
    cairo_set_dash(cr, dash, 0, 0);
  };
  const auto seg = [&](const Vec2& a, const Vec2& b, double lw) {
    cairo_move_to(cr, a.x(), L.height - a.y());
    cairo_line_to(cr, b.x(), L.height - b.y());
    cairo_set_line_width(cr, lw);
    cairo_stroke(cr);
  };
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const std::string label = std::string(1, static_cast<char>('A' + r)) + std::to_string(c + 1);
      cairo_save(cr);
      cairo_rectangle(cr, margin, margin, pw, ph);
      cairo_clip(cr);
      cairo_translate(cr, margin - c * sx, margin - r * sy);
      for (const Placed& p : L.pieces) {
        draw_poly(p.cut, 0.4, false);
        if (opt.seam_allowance > 0) draw_poly(p.seam, 0.25, true);
        for (const auto& d : p.piece->darts) {
          seg(p.seam[d.tip], p.seam[d.leg1_top], 0.25);
          seg(p.seam[d.tip], p.seam[d.leg2_top], 0.25);
        }
        seg(L.map(p, p.piece->grain_a), L.map(p, p.piece->grain_b), 0.4);
        for (const Notch& nt : notches(L, p, opt.seam_allowance)) seg(nt.a, nt.b, 0.4);
        const Vec2 t = L.map(p, 0.5 * (p.piece->grain_a + p.piece->grain_b)) + Vec2(4, 0);
        cairo_move_to(cr, t.x(), L.height - t.y());
        cairo_set_font_size(cr, 5);
        cairo_show_text(cr, (p.piece->name + " - size " + p.piece->size + " - cut " +
                             std::to_string(p.piece->quantity))
                                .c_str());
      }
      cairo_restore(cr);
      // Registration crosses at the corners of the printable area, the page label outside it.
      cairo_set_line_width(cr, 0.2);
      for (double x : {margin, margin + pw})
        for (double y : {margin, margin + ph}) {
          cairo_move_to(cr, x - 4, y);
          cairo_line_to(cr, x + 4, y);
          cairo_move_to(cr, x, y - 4);
          cairo_line_to(cr, x, y + 4);
          cairo_stroke(cr);
          cairo_arc(cr, x, y, 2, 0, 2 * 3.141592653589793);
          cairo_stroke(cr);
        }
      cairo_set_font_size(cr, 3.5);
      cairo_move_to(cr, margin + 6, margin - 3);
      cairo_show_text(cr, ("page " + label + " (row " + std::to_string(r + 1) + "/" +
                           std::to_string(rows) + ", column " + std::to_string(c + 1) + "/" +
                           std::to_string(cols) + "), overlap 10 mm")
                              .c_str());
      cairo_show_page(cr);
    }
  cairo_destroy(cr);
  cairo_surface_finish(s);
  const bool ok = cairo_surface_status(s) == CAIRO_STATUS_SUCCESS;
  cairo_surface_destroy(s);
  if (out) *out = {rows * cols + 1, cols, rows};
  return ok ? "" : path + ": cairo failed writing the PDF";
}

}  // namespace drape::sim
