// The basic bodice draped geometrically on the form, and the dress joining it to a skirt
// (see bodice.hpp and docs/draping.md).
#include "sim/draping/bodice.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "sim/core/stopwatch.hpp"
#include "sim/draping/mapping.hpp"
#include "sim/draping/pattern_export.hpp"
#include "sim/draping/sew.hpp"
#include "sim/form/dress_form.hpp"

namespace drape::sim {
namespace {
constexpr double kPi = 3.141592653589793;
using json = nlohmann::json;

// Where one half piece lies on the form: angles as phi, the angle from the centre line toward
// the side line (theta = theta_c + dir * phi), heights in stage metres.
struct PieceGeom {
  double theta_c = 0, span = kPi / 2;
  int dir = -1;
  double waist_y = 0, neck_y = 0, neck_centre_y = 0;  // neck point on the centre line
  double apex_y = 0, apex_phi = 0, dart_top_y = 0;    // shoulder dart's end on the shoulder
  double bust_y = 0;                                  // the form's bust line
  double armpit_y = 0, shoulder_y = 0, inset = 0;
  double apex_x = 0, dart_top_x = 0, neck_x = 0;  // distances from the centre plane
  const MappingSurface* surf = nullptr;
  double theta(double phi) const { return theta_c + dir * phi; }
  // The angle whose surface point at height y lies `x` from the centre plane (x grows with phi
  // from the centre line to the side line on a convex section).
  double phi_at_x(double y, double x) const {
    const double cx = surf->centre(y).x();
    double lo = 0, hi = span;
    for (int it = 0; it < 50; ++it) {
      const double mid = 0.5 * (lo + hi);
      (std::abs(surf->point(y, theta(mid)).x() - cx) < x ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
  // The dart line: straight up from the waist to the apex, then running out from the centre
  // plane evenly with height to its end on the shoulder seam (over the chest or the blade, then
  // over the top of the shoulder).
  double dart_phi(double y) const {
    if (y <= apex_y) return apex_phi;
    const double t = std::min(1.0, (y - apex_y) / (dart_top_y - apex_y));
    return t >= 1 ? span : phi_at_x(y, apex_x + (dart_top_x - apex_x) * t);
  }
  // The neckline: level at the centre line, rising ever more steeply to the neck point (a
  // quarter ellipse in height and distance from the centre plane).
  double neck_phi(double y) const {
    if (y <= neck_centre_y) return 0;
    const double t = std::min(1.0, (y - neck_centre_y) / (neck_y - neck_centre_y));
    return t >= 1 ? span : phi_at_x(y, neck_x * std::sqrt(1 - (1 - t) * (1 - t)));
  }
  // The armhole's arc in from the side line: half an ellipse between armpit and shoulder point.
  double armhole_inset(double y) const {
    if (y <= armpit_y || y >= shoulder_y) return 0;
    const double t = (2 * y - armpit_y - shoulder_y) / (shoulder_y - armpit_y);
    return inset * std::sqrt(std::max(0.0, 1 - t * t));
  }
};

// One zone of a piece: a grid of rows x cols nodes, each on the form and flat.
struct Zone {
  int rows = 0, cols = 0;
  std::vector<double> row_y;
  std::vector<Vec3> x3;     // on the (eased) form
  std::vector<Vec2> flat;   // relaxed flat position
  std::vector<Vec2> start;  // the along-grain mapping (before relaxation)
  int at(int r, int c) const { return r * cols + c; }
};

struct Edge {
  int a, b;
  double rest;
  double stiffness = 1.0;  // fraction of the length error corrected per sweep
};
// The diagonals (shear) give way to the rows and columns (weft and warp, whose lengths the widths
// and seams carry): over a curved form the cloth shears rather than stretches.
constexpr double kShearStiffness = 0.4;
// In the seams' phase of the flat relaxation the seam lines are this many times as stiff as the
// cloth inside the zone (relax_flat).
constexpr double kSeamWeight = 20;

// The cell edges: along rows, along columns and both diagonals (shear).
std::vector<Edge> zone_edges(const Zone& z) {
  std::vector<Edge> e;
  const auto add = [&](int a, int b) { e.push_back({a, b, (z.x3[a] - z.x3[b]).norm()}); };
  for (int r = 0; r < z.rows; ++r)
    for (int c = 0; c < z.cols; ++c) {
      if (c + 1 < z.cols) add(z.at(r, c), z.at(r, c + 1));
      if (r + 1 < z.rows) add(z.at(r, c), z.at(r + 1, c));
      if (r + 1 < z.rows && c + 1 < z.cols) {
        add(z.at(r, c), z.at(r + 1, c + 1));
        add(z.at(r, c + 1), z.at(r + 1, c));
        e[e.size() - 2].stiffness = e.back().stiffness = kShearStiffness;
      }
    }
  return e;
}

// Heights of the mesh rows: every `step` from the waist plus every key height of every piece,
// so that seams shared by two zones or two pieces have their nodes at the same heights.
std::vector<double> row_heights(const std::vector<PieceGeom>& g, double step) {
  std::vector<double> y;
  const double w = g.front().waist_y, top = g.front().neck_y;
  const int n = static_cast<int>(std::ceil((top - w) / step));
  for (int k = 0; k <= n; ++k) y.push_back(w + (top - w) * k / n);
  for (const PieceGeom& p : g)
    for (double k : {p.apex_y, p.dart_top_y, p.armpit_y, p.shoulder_y, p.neck_centre_y})
      y.push_back(k);
  std::sort(y.begin(), y.end());
  std::vector<double> out;
  for (double v : y)
    if (out.empty() || v - out.back() > 1e-4 * step) out.push_back(v);
  return out;
}

// Meshes one zone between two bounding lines given as arcs from the centre line per row (rows
// from the waist up to `top`), maps it along the grain and returns it unrelaxed.
template <class Bounds>
Zone mesh_zone(const MappingSurface& surf, const PieceGeom& g, const std::vector<double>& ys,
               double top, double col_step, Bounds bounds) {
  Zone z;
  for (double y : ys)
    if (y <= top + 1e-9) z.row_y.push_back(y);
  z.rows = static_cast<int>(z.row_y.size());
  std::vector<ArcTable> T;
  std::vector<std::pair<double, double>> lr;
  double widest = 0;
  for (double y : z.row_y) {
    T.push_back(ArcTable::build(surf, y, g.theta_c, g.dir));
    lr.push_back(bounds(T.back(), y));
    widest = std::max(widest, lr.back().second - lr.back().first);
  }
  z.cols = std::max(3, static_cast<int>(std::ceil(widest / col_step)) + 1);
  z.x3.resize(static_cast<size_t>(z.rows) * z.cols);
  z.start.resize(z.x3.size());
  for (int r = 0; r < z.rows; ++r)
    for (int c = 0; c < z.cols; ++c) {
      const double a = lr[r].first + (lr[r].second - lr[r].first) * c / (z.cols - 1);
      z.x3[z.at(r, c)] = surf.point(z.row_y[r], T[r].theta_at(a));
      // Weft: the arc from the centre line; warp: the length up the cloth from the waist.
      const double up =
          r == 0 ? 0.0
                 : z.start[z.at(r - 1, c)].y() + (z.x3[z.at(r, c)] - z.x3[z.at(r - 1, c)]).norm();
      z.start[z.at(r, c)] = Vec2(a, up);
    }
  z.flat = z.start;
  return z;
}

// A run of a zone's column edges that is a seam line (sewn to another piece or zone).
struct SeamRun {
  int col, r0, r1;  // the edges between rows r0 .. r1
};

// Projects one edge toward its rest length (`stiffness` of the error per call).
void project_flat(Zone& z, const Edge& e) {
  const Vec2 d = z.flat[e.b] - z.flat[e.a];
  const double len = d.norm();
  if (len < 1e-12) return;
  const Vec2 corr = 0.5 * e.stiffness * (len - e.rest) / len * d;
  z.flat[e.a] += corr;
  z.flat[e.b] -= corr;
}

// Relaxes the zone flat (Gauss-Seidel on the edge lengths). `pin_x0` holds the nodes of column
// 0 below `pin_top_row` on x = 0 (the centre line is the grain line, straight) and the first
// node at the origin.
//
// `iterations` sweeps with every edge alike, then twice as many with the seams held: the edges
// of `seams`, the waist row and the bust row (`bust_row`, -1: none) at full stiffness, the rest
// of the cloth at 1/kSeamWeight of its own. A doubly curved zone cannot lie flat at all its
// lengths; left alike, the flattening stretches its outer columns (the front side seam came out
// 6.5 mm longer than on the form, the back's 0.7 mm shorter, so the two did not match). Held,
// two seams sewn together keep their common length on the form and the widths keep theirs; the
// inside takes up the rest. Each seam also holds the chord over every two of its edges, so a
// held line cannot zigzag to keep its length where the inside pushes it shorter.
void relax_flat(Zone& z, int iterations, bool pin_x0, int pin_top_row,
                const std::vector<SeamRun>& seams, int bust_row) {
  const std::vector<Edge> edges = zone_edges(z);
  std::vector<Edge> held, soft;
  for (const Edge& e : edges) {
    // Nodes at one point on the form (a row where the zone's bounding lines meet) stay one.
    if (e.rest < 1e-9) held.push_back(e);
    soft.push_back(e);
    soft.back().stiffness /= kSeamWeight;
  }
  const auto hold = [&](int a, int b) { held.push_back({a, b, (z.x3[a] - z.x3[b]).norm()}); };
  for (const SeamRun& s : seams)
    for (int r = s.r0; r < s.r1; ++r) {
      hold(z.at(r, s.col), z.at(r + 1, s.col));
      if (r + 2 <= s.r1) hold(z.at(r, s.col), z.at(r + 2, s.col));
    }
  for (int r : {0, bust_row})
    for (int c = 0; r >= 0 && c + 1 < z.cols; ++c) hold(z.at(r, c), z.at(r, c + 1));
  for (int it = 0; it < 3 * iterations; ++it) {
    for (const Edge& e : it < iterations ? edges : soft) project_flat(z, e);
    if (it >= iterations)
      for (const Edge& e : held) project_flat(z, e);
    if (!pin_x0) continue;
    const Vec2 shift = z.flat[0];
    for (Vec2& p : z.flat) p -= Vec2(0, shift.y());
    for (int r = 0; r <= pin_top_row; ++r) z.flat[z.at(r, 0)].x() = 0;
  }
}

// Turns and moves the zone so that it best fits its along-grain mapping (its grain stays
// parallel to the centre line's), then moves it so `node` lands on `target`.
void align_zone(Zone& z, int node, const Vec2& target) {
  Vec2 mf = Vec2::Zero(), ms = Vec2::Zero();
  for (size_t i = 0; i < z.flat.size(); ++i) mf += z.flat[i], ms += z.start[i];
  mf /= static_cast<double>(z.flat.size());
  ms /= static_cast<double>(z.flat.size());
  double sxx = 0, sxy = 0;
  for (size_t i = 0; i < z.flat.size(); ++i) {
    const Vec2 a = z.flat[i] - mf, b = z.start[i] - ms;
    sxx += a.dot(b);
    sxy += a.x() * b.y() - a.y() * b.x();
  }
  const double ang = std::atan2(sxy, sxx), c = std::cos(ang), s = std::sin(ang);
  for (Vec2& p : z.flat) {
    const Vec2 q = p - mf;
    p = Vec2(c * q.x() - s * q.y(), s * q.x() + c * q.y());
  }
  const Vec2 t = target - z.flat[node];
  for (Vec2& p : z.flat) p += t;
}

double row_length(const Zone& z, int r) {
  double l = 0;
  for (int c = 0; c + 1 < z.cols; ++c) l += (z.flat[z.at(r, c + 1)] - z.flat[z.at(r, c)]).norm();
  return l;
}
double column_length(const Zone& z, int c, int r0, int r1) {
  double l = 0;
  for (int r = r0; r < r1; ++r) l += (z.flat[z.at(r + 1, c)] - z.flat[z.at(r, c)]).norm();
  return l;
}
int row_of(const Zone& z, double y) {
  int best = 0;
  for (int r = 0; r < z.rows; ++r)
    if (std::abs(z.row_y[r] - y) < std::abs(z.row_y[best] - y)) best = r;
  return best;
}

// Flat and draped areas (m^2) of a zone's cells.
std::pair<double, double> zone_areas(const Zone& z) {
  double a2 = 0, a3 = 0;
  for (int r = 0; r + 1 < z.rows; ++r)
    for (int c = 0; c + 1 < z.cols; ++c) {
      const int p = z.at(r, c), q = z.at(r, c + 1), s = z.at(r + 1, c + 1), t = z.at(r + 1, c);
      for (auto [i, j, k] : {std::array<int, 3>{p, q, s}, std::array<int, 3>{p, s, t}}) {
        const Vec2 u = z.flat[j] - z.flat[i], v = z.flat[k] - z.flat[i];
        a2 += 0.5 * std::abs(u.x() * v.y() - u.y() * v.x());
        a3 += 0.5 * (z.x3[j] - z.x3[i]).cross(z.x3[k] - z.x3[i]).norm();
      }
    }
  return {a2, a3};
}

struct DrapedPiece {
  PieceGeom g;
  Zone centre, side;
  int apex_row_centre = 0, apex_row_side = 0, dart_top_row = 0;
};

PieceGeom piece_geometry(const BodicePieceDesign& pd, const DressForm& form,
                         const MappingSurface& surf) {
  const FormLandmarks& lm = form.landmarks();
  PieceGeom g;
  const bool back = pd.centre_line == "centre_back";
  g.theta_c = back ? lm.centre_back_theta : lm.centre_front_theta;
  const double th_s = lm.right_side_theta;
  const double delta = std::fmod(th_s - g.theta_c + 3 * kPi, 2 * kPi) - kPi;
  g.dir = delta < 0 ? -1 : 1;
  g.span = std::abs(delta);
  g.waist_y = lm.waist_y;
  g.neck_y = lm.neck_y;
  g.neck_centre_y = lm.neck_y - pd.neck_depth;
  g.apex_y = lm.bust_y + pd.apex_above_bust;
  g.bust_y = lm.bust_y;
  g.apex_phi = pd.apex_angle;
  g.armpit_y = lm.armpit_y;
  g.shoulder_y = lm.shoulder_y;
  g.inset = pd.armhole_inset;
  // The shoulder dart's end: `shoulder_dart_at` of the shoulder seam's length on the form from
  // the neck point toward the shoulder point.
  std::vector<double> ys, len{0};
  for (int k = 0; k <= 200; ++k) ys.push_back(lm.neck_y - (lm.neck_y - lm.shoulder_y) * k / 200);
  for (int k = 1; k <= 200; ++k)
    len.push_back(len.back() + (surf.point(ys[k], th_s) - surf.point(ys[k - 1], th_s)).norm());
  int k = 0;
  while (k < 200 && len[k] < pd.shoulder_dart_at * len.back()) ++k;
  g.dart_top_y = ys[k];
  g.surf = &surf;
  const auto off_centre = [&](double y, double th) {
    return std::abs(surf.point(y, th).x() - surf.centre(y).x());
  };
  g.apex_x = off_centre(g.apex_y, g.theta(g.apex_phi));
  g.dart_top_x = off_centre(g.dart_top_y, th_s);
  g.neck_x = off_centre(g.neck_y, th_s);
  return g;
}

DrapedPiece drape_piece(const BodiceDesign& d, const PieceGeom& g, const MappingSurface& surf,
                        const std::vector<double>& ys) {
  DrapedPiece p;
  p.g = g;
  const auto arc = [&](const ArcTable& T, double phi) { return T.arc_at(g.theta(phi)); };
  p.centre = mesh_zone(surf, g, ys, g.neck_y, d.column_step, [&](const ArcTable& T, double y) {
    const double right = y <= g.dart_top_y ? arc(T, g.dart_phi(y)) : arc(T, g.span);
    return std::make_pair(std::min(arc(T, g.neck_phi(y)), right), right);
  });
  p.side = mesh_zone(surf, g, ys, g.dart_top_y, d.column_step, [&](const ArcTable& T, double y) {
    const double left = arc(T, g.dart_phi(y));
    return std::make_pair(left, std::max(left, arc(T, g.span) - g.armhole_inset(y)));
  });
  p.apex_row_centre = row_of(p.centre, g.apex_y);
  p.apex_row_side = row_of(p.side, g.apex_y);
  p.dart_top_row = row_of(p.centre, g.dart_top_y);
  // Seams: the centre zone's dart edge and inner shoulder (its last column), the side zone's
  // dart edge (column 0), side seam (up to the armpit) and outer shoulder (from the shoulder
  // point).
  const int cc = p.centre.cols - 1, sc = p.side.cols - 1, st = p.side.rows - 1;
  relax_flat(p.centre, d.relax_iterations, true, row_of(p.centre, g.neck_centre_y),
             {{cc, 0, p.centre.rows - 1}}, row_of(p.centre, g.bust_y));
  relax_flat(
      p.side, d.relax_iterations, false, 0,
      {{0, 0, st}, {sc, 0, row_of(p.side, g.armpit_y)}, {sc, row_of(p.side, g.shoulder_y), st}},
      row_of(p.side, g.bust_y));
  align_zone(p.side, p.side.at(p.apex_row_side, 0),
             p.centre.flat[p.centre.at(p.apex_row_centre, p.centre.cols - 1)]);
  return p;
}

// The piece outline, counter-clockwise from the centre line's waist point: waist (centre zone),
// the waist dart (up the centre zone's dart edge to the apex, down the side zone's), waist (side
// zone), side seam, armhole, shoulder (outer part), the shoulder dart (down the side zone's dart
// edge to the apex, up the centre zone's), shoulder (inner part), neckline, centre line.
PatternPiece outline_of(const DrapedPiece& p, const BodicePieceDesign& pd, const std::string& size,
                        double min_step) {
  PatternPiece pc;
  pc.name = pd.name;
  pc.size = size;
  pc.quantity = pd.quantity;
  pc.labels = {"waist",    "dart1_leg2", "dart1_leg1", "side",     "armhole",
               "shoulder", "dart2_leg2", "dart2_leg1", "neckline", pd.centre_line};
  const Zone &C = p.centre, &S = p.side;
  std::vector<std::pair<Vec2, int>> pts;
  // A point of the same line as the last one and nearer than `min_step` to it is left out: the
  // rows at the key heights (apex, armpit, shoulder, dart end, neck) lie a millimetre or less
  // from their neighbours, and so flat a row can fold over in the relaxation; through its
  // nodes the line would turn back on itself (40-60 deg/mm in the fairness figure).
  const auto push = [&](const Vec2& q, int label) {
    if (!pts.empty() && (pts.back().first - q).norm() < 1e-9) {
      pts.back().second = label;
      return;
    }
    if (pts.size() > 1 && pts.back().second == label && (pts.back().first - q).norm() < min_step)
      return;
    pts.emplace_back(q, label);
  };
  const int cc = C.cols - 1, sc = S.cols - 1, st = S.rows - 1;
  int waist_leg2 = 0, waist_tip = 0, waist_leg1 = 0, sh_leg2 = 0, sh_tip = 0, sh_leg1 = 0;
  for (int c = 0; c < cc; ++c) push(C.flat[C.at(0, c)], 0);
  waist_leg2 = static_cast<int>(pts.size());
  for (int r = 0; r < p.apex_row_centre; ++r) push(C.flat[C.at(r, cc)], 1);
  waist_tip = static_cast<int>(pts.size());
  for (int r = p.apex_row_side; r > 0; --r) push(S.flat[S.at(r, 0)], 2);
  waist_leg1 = static_cast<int>(pts.size());
  for (int c = 0; c < sc; ++c) push(S.flat[S.at(0, c)], 0);
  const int arm0 = row_of(S, p.g.armpit_y), sh0 = row_of(S, p.g.shoulder_y);
  for (int r = 0; r < st; ++r) push(S.flat[S.at(r, sc)], r < arm0 ? 3 : r < sh0 ? 4 : 5);
  sh_leg2 = static_cast<int>(pts.size());
  for (int r = st; r > p.apex_row_side; --r) push(S.flat[S.at(r, 0)], 6);
  sh_tip = static_cast<int>(pts.size());
  for (int r = p.apex_row_centre; r < p.dart_top_row; ++r) push(C.flat[C.at(r, cc)], 7);
  sh_leg1 = static_cast<int>(pts.size());
  for (int r = p.dart_top_row; r < C.rows - 1; ++r) push(C.flat[C.at(r, cc)], 5);
  const int neck0 = row_of(C, p.g.neck_centre_y);
  for (int r = C.rows - 1; r > neck0; --r) push(C.flat[C.at(r, 0)], 8);
  for (int r = neck0; r > 0; --r) push(C.flat[C.at(r, 0)], 9);
  for (const auto& [q, l] : pts) {
    pc.outline.push_back(q);
    pc.seg_label.push_back(l);
  }
  // Darts as folded: the waist dart pressed toward the centre line, the shoulder dart toward
  // the neck (both onto their leg 1 side); notches at the leg tops and mid-armhole.
  pc.darts.push_back({waist_tip, waist_leg1, waist_leg2,
                      (pc.outline[waist_leg1] - pc.outline[waist_leg2]).norm(), 2});
  pc.darts.push_back(
      {sh_tip, sh_leg1, sh_leg2, (pc.outline[sh_leg1] - pc.outline[sh_leg2]).norm(), 1});
  pc.notches = {waist_leg1, waist_leg2, sh_leg1, sh_leg2};
  const std::vector<int> arm = pc.seam_points("armhole");
  if (!arm.empty()) pc.notches.push_back(arm[arm.size() / 2]);
  // Grain line: parallel to the centre line, a third of the waist width in.
  const double gx = 0.33 * pc.outline[waist_leg2].x();
  pc.grain_a = Vec2(gx, 0.04);
  pc.grain_b = Vec2(gx, 0.04 + 0.5 * (p.g.apex_y - p.g.waist_y));
  return pc;
}

// The bust line on the pattern (flat points, centre to side, darts closed: the zones' rows
// joined at the dart line).
std::vector<Vec2> bust_line(const DrapedPiece& p, double bust_y) {
  std::vector<Vec2> l;
  const int rc = row_of(p.centre, bust_y), rs = row_of(p.side, bust_y);
  for (int c = 0; c < p.centre.cols; ++c) l.push_back(p.centre.flat[p.centre.at(rc, c)]);
  for (int c = 1; c < p.side.cols; ++c) l.push_back(p.side.flat[p.side.at(rs, c)]);
  return l;
}

void strain_of(const Zone& z, double* max_pct, double* sum_sq, int* count) {
  for (const Edge& e : zone_edges(z)) {
    if (e.rest < 1e-6) continue;
    const double s = ((z.flat[e.b] - z.flat[e.a]).norm() - e.rest) / e.rest * 100;
    *max_pct = std::max(*max_pct, std::abs(s));
    *sum_sq += s * s;
    ++*count;
  }
}

BodicePieceReport measure_piece(const DrapedPiece& p, const PatternPiece& pc,
                                const MappingSurface& surf, const FormLandmarks& lm) {
  BodicePieceReport r;
  r.name = pc.name;
  const auto arc_to_side = [&](double y) {
    return ArcTable::build(surf, y, p.g.theta_c, p.g.dir).arc_at(p.g.theta(p.g.span)) * 1000;
  };
  const std::vector<Vec2> bl = bust_line(p, lm.bust_y);
  for (size_t i = 0; i + 1 < bl.size(); ++i) r.bust_width_mm += (bl[i + 1] - bl[i]).norm() * 1000;
  r.bust_arc_mm = arc_to_side(lm.bust_y);
  r.waist_width_mm = (row_length(p.centre, 0) + row_length(p.side, 0)) * 1000;
  r.waist_arc_mm = arc_to_side(lm.waist_y);
  r.waist_dart_mm = pc.darts[0].intake * 1000;
  r.shoulder_dart_mm = pc.darts[1].intake * 1000;
  const int cc = p.centre.cols - 1;
  r.waist_dart_legs_mm[0] = column_length(p.centre, cc, 0, p.apex_row_centre) * 1000;
  r.waist_dart_legs_mm[1] = column_length(p.side, 0, 0, p.apex_row_side) * 1000;
  r.shoulder_dart_legs_mm[0] =
      column_length(p.centre, cc, p.apex_row_centre, p.dart_top_row) * 1000;
  r.shoulder_dart_legs_mm[1] = column_length(p.side, 0, p.apex_row_side, p.side.rows - 1) * 1000;
  r.shoulder_mm = pc.seam_length("shoulder") * 1000;
  r.side_mm = pc.seam_length("side") * 1000;
  r.armhole_mm = pc.seam_length("armhole") * 1000;
  r.neckline_mm = pc.seam_length("neckline") * 1000;
  const auto [c2, c3] = zone_areas(p.centre);
  const auto [s2, s3] = zone_areas(p.side);
  r.area_piece_cm2 = std::abs(pc.area()) * 1e4;
  r.area_draped_cm2 = (c3 + s3) * 1e4;
  r.area_error_pct = (r.area_piece_cm2 - r.area_draped_cm2) / r.area_draped_cm2 * 100;
  (void)c2;
  (void)s2;
  double sum = 0;
  int n = 0;
  strain_of(p.centre, &r.max_strain_pct, &sum, &n);
  strain_of(p.side, &r.max_strain_pct, &sum, &n);
  r.rms_strain_pct = n ? std::sqrt(sum / n) : 0;
  for (const std::string& l : pc.labels)
    r.fairness_deg_per_mm.emplace_back(l, seam_fairness(pc, l));
  return r;
}

// The sewn bodice on the form: every zone of every piece and its mirror image, nodes at the
// same place on the form joined (the seams and the closed darts), each edge at its flat
// length, relaxed (Gauss-Seidel) against the form; then its girths.
// `node_vertex` gets the sewn vertex of every zone node, in the order piece, zone (centre,
// side), half (right, mirror image), node.
Garment sew_bodice(const std::vector<DrapedPiece>& pieces, const MappingSurface& surf,
                   double mirror_x, int iterations, std::vector<int>* node_vertex) {
  Garment g;
  std::map<std::array<long long, 3>, int> id;
  std::vector<Edge> edges;
  const auto vertex = [&](const Vec3& p) {
    const std::array<long long, 3> key{std::llround(p.x() * 1e6), std::llround(p.y() * 1e6),
                                       std::llround(p.z() * 1e6)};
    auto [it, fresh] = id.emplace(key, static_cast<int>(g.x.size()));
    if (fresh) g.x.push_back(p);
    return it->second;
  };
  for (const DrapedPiece& p : pieces)
    for (const Zone* z : {&p.centre, &p.side})
      for (int half = 0; half < 2; ++half) {
        std::vector<int> v(z->x3.size());
        for (size_t i = 0; i < v.size(); ++i) {
          Vec3 q = z->x3[i];
          if (half) q.x() = 2 * mirror_x - q.x();
          v[i] = vertex(q);
        }
        node_vertex->insert(node_vertex->end(), v.begin(), v.end());
        for (const Edge& e : zone_edges(*z))
          edges.push_back({v[e.a], v[e.b], (z->flat[e.b] - z->flat[e.a]).norm(), e.stiffness});
        for (int r = 0; r + 1 < z->rows; ++r)
          for (int c = 0; c + 1 < z->cols; ++c) {
            const int a = v[z->at(r, c)], b = v[z->at(r, c + 1)], s = v[z->at(r + 1, c + 1)],
                      t = v[z->at(r + 1, c)];
            g.triangles.push_back({a, b, s});
            g.triangles.push_back({a, s, t});
          }
      }
  for (int it = 0; it < iterations; ++it) {
    for (const Edge& e : edges) {
      const Vec3 d = g.x[e.b] - g.x[e.a];
      const double len = d.norm();
      if (len < 1e-12 || e.a == e.b) continue;
      const Vec3 corr = 0.5 * e.stiffness * (len - e.rest) / len * d;
      g.x[e.a] += corr;
      g.x[e.b] -= corr;
    }
    for (Vec3& p : g.x) surf.form().push_outside(p, surf.offset());
  }
  g.vertex_piece.assign(g.x.size(), 0);
  g.piece_names = {"Bodice"};
  return g;
}

// The cells of one zone as triangles of the vertices `id` (counter-clockwise in the flat
// pattern; `mirrored`: the flat pattern's mirror image, the winding turned). Where a zone's
// bounding lines meet (the neckline's corner, the dart's end on the shoulder) a row's nodes are
// one vertex: the cells' triangles with a vertex twice are left out.
void add_zone_triangles(const Zone& z, const std::vector<int>& id, bool mirrored, Garment& g) {
  const auto add = [&](int a, int b, int c) {
    if (a == b || b == c || a == c) return;
    g.triangles.push_back(mirrored ? std::array<int32_t, 3>{a, c, b} : std::array{a, b, c});
  };
  for (int r = 0; r + 1 < z.rows; ++r)
    for (int c = 0; c + 1 < z.cols; ++c) {
      const int a = id[z.at(r, c)], b = id[z.at(r, c + 1)], s = id[z.at(r + 1, c + 1)],
                t = id[z.at(r + 1, c)];
      add(a, b, s);
      add(a, s, t);
    }
}

// Where the bodice's vertices come from while its cloth is built (bodice_cloth).
struct ClothBuild {
  const Garment& welded;
  const std::vector<int>& node_vertex;
  std::vector<int> first;  // per sewn vertex: the cloth vertex made for it first (-1: none)
  double min_gap = 0;      // m: nodes of a row nearer than this are one vertex
  Garment g;
  std::set<std::pair<int, int>> tied;  // (vertex, the vertex it is tied onto)
  // Ties `v` onto `onto` once: the nodes of a collapsed row are one vertex, and a tie per node
  // would repeat the same tie (28 times at the back's neck point), projected as many times.
  void tie(int v, int onto) {
    if (tied.emplace(v, onto).second) g.ties.push_back({v, onto, onto, 0.0});
  }
};

// The vertices of one zone's half (`half` 1: the mirror image; `k` the zone's first node in
// node_vertex, `right` the right half's vertices): a node at a sewn vertex this half already has
// at the same flat point is that vertex (a collapsed row); the mirror image of a centre-line node
// (its own image, flat x = 0) is the right half's vertex; otherwise a new vertex, tied onto the
// first one made at its sewn vertex (dart legs, apex, side and shoulder seams).
std::vector<int> zone_vertices(ClothBuild& cb, const Zone& z, size_t k, int half,
                               const std::vector<int>& right, int piece) {
  Garment& g = cb.g;
  std::map<int, int> here;  // sewn vertex -> this half's vertex
  std::vector<int> id(z.flat.size());
  for (size_t i = 0; i < id.size(); ++i) {
    const int w = cb.node_vertex[k + (half ? id.size() : 0) + i];
    const Vec2 m(half ? -z.flat[i].x() : z.flat[i].x(), z.flat[i].y());
    if (auto it = here.find(w); it != here.end() && (g.material[it->second] - m).norm() < 1e-7) {
      id[i] = it->second;
      continue;
    }
    if (half && cb.node_vertex[k + i] == w && std::abs(z.flat[i].x()) < 1e-9) {
      id[i] = here[w] = right[i];
      continue;
    }
    // A node nearer than min_gap to the one before it in its row, flat and sewn (where the zone's
    // bounding lines nearly meet) is that node's vertex: their cells would be slivers a fraction of
    // a mm across, which the solver cannot hold at their rest shape (they stretched thousands of
    // per cent and kept the cloth from coming to rest). Its seam, if any, is tied there.
    if (i % z.cols != 0 && (z.flat[i] - z.flat[i - 1]).norm() < cb.min_gap &&
        (cb.welded.x[w] - g.x[id[i - 1]]).norm() < cb.min_gap) {
      id[i] = here[w] = id[i - 1];
      if (cb.first[w] < 0)
        cb.first[w] = id[i];
      else if (cb.first[w] != id[i])
        cb.tie(id[i], cb.first[w]);
      continue;
    }
    id[i] = here[w] = static_cast<int>(g.x.size());
    g.x.push_back(cb.welded.x[w]);
    g.material.push_back(m);
    g.vertex_piece.push_back(piece);
    if (static_cast<int>(i) < z.cols) g.waist_vertices.push_back(id[i]);
    if (cb.first[w] < 0)
      cb.first[w] = id[i];
    else
      cb.tie(id[i], cb.first[w]);
  }
  return id;
}

// The sewn bodice as cloth (BodiceResult::garment): per zone and half the zone's nodes at their
// sewn (welded) placement with the zone's flat points as material coordinates (zone_vertices).
Garment bodice_cloth(const std::vector<DrapedPiece>& pieces, const Garment& welded,
                     const std::vector<int>& node_vertex, const BodiceDesign& d) {
  // Nodes of a row nearer than a quarter of a column step are one vertex.
  ClothBuild cb{welded, node_vertex, std::vector<int>(welded.x.size(), -1), 0.25 * d.column_step,
                {},     {}};
  size_t k = 0;
  for (size_t pi = 0; pi < pieces.size(); ++pi)
    for (const Zone* z : {&pieces[pi].centre, &pieces[pi].side}) {
      std::vector<int> right;
      for (int half = 0; half < 2; ++half) {
        const int pid = static_cast<int>(cb.g.piece_names.size());
        cb.g.piece_names.push_back(d.pieces[pi].name +
                                   (z == &pieces[pi].centre ? " centre" : " side") +
                                   (half ? " (left)" : " (right)"));
        const std::vector<int> id = zone_vertices(cb, *z, k, half, right, pid);
        if (!half) right = id;
        add_zone_triangles(*z, id, half == 1, cb.g);
      }
      k += 2 * z->flat.size();
    }
  cb.g.seams.push_back("bodice: " + std::to_string(cb.g.ties.size()) +
                       " ties (dart legs, side and shoulder seams); centre lines one vertex");
  return std::move(cb.g);
}

// A waist seam as a closed loop around the body: its vertices in the order of their angle about
// a vertical axis through `centre`, and each one's place along the loop in quarters: q + f is
// the fraction f of the arc length between the points where the loop crosses the angles
// -pi + q pi/2 and -pi + (q + 1) pi/2 (the centre lines and the sides, roughly). Two loops sewn
// together meet at equal places: arc length shared out in proportion within each quarter, as a
// pattern maker walks one seam along the other.
struct WaistLoop {
  std::vector<int> v;
  std::vector<double> place;
};

WaistLoop waist_loop(const std::vector<Vec3>& x, std::vector<int> verts, const Vec3& centre) {
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  const auto angle = [&](int v) {
    return std::atan2(x[v].x() - centre.x(), x[v].z() - centre.z());
  };
  std::sort(verts.begin(), verts.end(), [&](int a, int b) { return angle(a) < angle(b); });
  const size_t n = verts.size();
  WaistLoop L{verts, std::vector<double>(n, 0.0)};
  if (n < 4) return L;
  // Arc length at each vertex from the first; where the loop crosses each quarter angle.
  std::vector<double> len(n + 1, 0.0);
  for (size_t i = 0; i < n; ++i) len[i + 1] = len[i] + (x[verts[(i + 1) % n]] - x[verts[i]]).norm();
  const double total = len[n];
  std::array<double, 5> cross{};
  for (int q = 0; q < 4; ++q) {
    const double phi = -M_PI + q * M_PI / 2;
    size_t i = 0;
    while (i < n && angle(verts[i]) < phi) ++i;
    // Between vertex i - 1 and i (wrapping): the crossing by angle, interpolated.
    const size_t i0 = (i + n - 1) % n, i1 = i % n;
    double a0 = angle(verts[i0]), a1 = angle(verts[i1]);
    if (a1 <= a0) a1 += 2 * M_PI;
    double p = phi;
    if (p < a0) p += 2 * M_PI;
    const double f = a1 > a0 ? std::clamp((p - a0) / (a1 - a0), 0.0, 1.0) : 0.0;
    const double s0 = i == 0 ? len[n - 1] - total : len[i0];
    cross[q] = s0 + f * (len[i0 + 1] - len[i0]);
  }
  cross[4] = cross[0] + total;
  for (size_t i = 0; i < n; ++i) {
    double s = len[i];
    if (s < cross[0]) s += total;
    int q = 0;
    while (q < 3 && s >= cross[q + 1]) ++q;
    L.place[i] = q + (s - cross[q]) / std::max(cross[q + 1] - cross[q], 1e-12);
  }
  return L;
}

// Ties every vertex of loop `from` onto loop `to` at the same place (between the two vertices of
// `to` whose places hold it, wrapping at 4).
void tie_loops(const WaistLoop& from, const WaistLoop& to, int from_offset, int to_offset,
               std::vector<SeamTie>& ties) {
  const size_t m = to.v.size();
  if (m < 2) return;
  for (size_t i = 0; i < from.v.size(); ++i) {
    const double p = from.place[i];
    size_t j = std::upper_bound(to.place.begin(), to.place.end(), p) - to.place.begin();
    const size_t j0 = (j + m - 1) % m, j1 = j % m;
    double p0 = to.place[j0], p1 = to.place[j1], pp = p;
    if (p1 <= p0) p1 += 4;
    if (pp < p0) pp += 4;
    const double t = p1 > p0 ? std::clamp((pp - p0) / (p1 - p0), 0.0, 1.0) : 0.0;
    ties.push_back({from.v[i] + from_offset, to.v[j0] + to_offset, to.v[j1] + to_offset, t});
  }
}

FitCheck check(const std::string& name, const std::string& unit, double value, double target,
               double bound, bool relative) {
  FitCheck c;
  c.name = name;
  c.unit = unit;
  c.value = value;
  c.target = target;
  c.error = relative ? (value - target) / target * 100 : value - target;
  c.bound = bound;
  c.pass = std::abs(c.error) <= bound;
  return c;
}

std::string get_num(const json& j, const char* key, const std::string& where, double* out) {
  if (!j.contains(key)) return "";
  if (!j[key].is_number() || !std::isfinite(j[key].get<double>()))
    return where + "." + key + ": must be a finite number";
  *out = j[key].get<double>();
  return "";
}

Result<json> parse_json(const std::string& text, const std::string& source) {
  try {
    json j = json::parse(text);
    if (!j.is_object()) return Error{source + ": expected a JSON object"};
    return j;
  } catch (const std::exception& e) {
    return Error{source + ": not valid JSON (" + e.what() + ")"};
  }
}

std::string parse_piece(const json& pj, const std::string& w, BodicePieceDesign* p) {
  if (!pj.is_object()) return w + ": must be an object";
  if (pj.contains("name")) {
    if (!pj["name"].is_string()) return w + ".name: must be a string";
    p->name = pj["name"].get<std::string>();
  }
  if (pj.contains("centre_line")) {
    if (!pj["centre_line"].is_string()) return w + ".centre_line: must be a string";
    p->centre_line = pj["centre_line"].get<std::string>();
  }
  if (p->centre_line != "centre_front" && p->centre_line != "centre_back")
    return w + ".centre_line: '" + p->centre_line + "' (known: centre_front, centre_back)";
  double apex_deg = p->apex_angle * 180 / kPi, q = p->quantity;
  for (std::string e :
       {get_num(pj, "neck_depth", w, &p->neck_depth),
        get_num(pj, "armhole_inset", w, &p->armhole_inset),
        get_num(pj, "apex_angle_deg", w, &apex_deg),
        get_num(pj, "apex_above_bust", w, &p->apex_above_bust),
        get_num(pj, "shoulder_dart_at", w, &p->shoulder_dart_at), get_num(pj, "quantity", w, &q)})
    if (!e.empty()) return e;
  p->apex_angle = apex_deg * kPi / 180;
  p->quantity = static_cast<int>(q);
  if (!(p->neck_depth > 0.005 && p->neck_depth < 0.2))
    return w + ".neck_depth: not in (0.005, 0.2) m";
  if (!(p->armhole_inset >= 0 && p->armhole_inset < 0.1))
    return w + ".armhole_inset: not in [0, 0.1) m";
  if (!(apex_deg > 5 && apex_deg < 80)) return w + ".apex_angle_deg: not in (5, 80) degrees";
  if (!(std::abs(p->apex_above_bust) < 0.1)) return w + ".apex_above_bust: not in (-0.1, 0.1) m";
  if (!(p->shoulder_dart_at > 0.1 && p->shoulder_dart_at < 0.9))
    return w + ".shoulder_dart_at: not in (0.1, 0.9)";
  if (q < 1 || q != std::floor(q)) return w + ".quantity: must be a whole number >= 1";
  return "";
}

json checks_json(const std::vector<FitCheck>& cs) {
  json a = json::array();
  for (const FitCheck& c : cs)
    a.push_back({{"name", c.name},
                 {"unit", c.unit},
                 {"value", c.value},
                 {"target", c.target},
                 {"error", c.error},
                 {"bound", c.bound},
                 {"pass", c.pass}});
  return a;
}

json bodice_json(const BodiceReport& r) {
  json j;
  j["design"] = r.design;
  j["form"] = r.form;
  j["ease_mm"] = r.ease_mm;
  j["form_bust_girth_mm"] = r.form_bust_girth_mm;
  j["form_waist_girth_mm"] = r.form_waist_girth_mm;
  j["pattern_bust_girth_mm"] = r.pattern_bust_girth_mm;
  j["pattern_waist_girth_mm"] = r.pattern_waist_girth_mm;
  j["sewn_bust_girth_mm"] = r.sewn_bust_girth_mm;
  j["sewn_waist_girth_mm"] = r.sewn_waist_girth_mm;
  j["side_seam_mismatch_mm"] = r.side_seam_mismatch_mm;
  j["shoulder_seam_mismatch_mm"] = r.shoulder_seam_mismatch_mm;
  j["pipeline_ms"] = r.pipeline_ms;
  j["pieces"] = json::array();
  for (const BodicePieceReport& p : r.pieces) {
    json pj = {{"name", p.name},
               {"bust_width_mm", p.bust_width_mm},
               {"bust_arc_mm", p.bust_arc_mm},
               {"waist_width_mm", p.waist_width_mm},
               {"waist_arc_mm", p.waist_arc_mm},
               {"waist_dart",
                {{"intake_mm", p.waist_dart_mm},
                 {"legs_mm", {p.waist_dart_legs_mm[0], p.waist_dart_legs_mm[1]}},
                 {"fold", "toward the centre line"}}},
               {"shoulder_dart",
                {{"intake_mm", p.shoulder_dart_mm},
                 {"legs_mm", {p.shoulder_dart_legs_mm[0], p.shoulder_dart_legs_mm[1]}},
                 {"fold", "toward the neck"}}},
               {"shoulder_mm", p.shoulder_mm},
               {"side_mm", p.side_mm},
               {"armhole_mm", p.armhole_mm},
               {"neckline_mm", p.neckline_mm},
               {"area_piece_cm2", p.area_piece_cm2},
               {"area_draped_cm2", p.area_draped_cm2},
               {"area_error_pct", p.area_error_pct},
               {"max_strain_pct", p.max_strain_pct},
               {"rms_strain_pct", p.rms_strain_pct}};
    pj["fairness_deg_per_mm"] = json::object();
    for (const auto& [l, f] : p.fairness_deg_per_mm) pj["fairness_deg_per_mm"][l] = f;
    j["pieces"].push_back(pj);
  }
  j["checks"] = checks_json(r.checks);
  j["all_pass"] = r.all_pass();
  return j;
}

void add_checks(BodiceReport& rep, double bust_target, double waist_target) {
  for (const BodicePieceReport& p : rep.pieces) {
    rep.checks.push_back(
        check(p.name + " bust width", "mm", p.bust_width_mm, p.bust_arc_mm, 2.0, false));
    rep.checks.push_back(
        check(p.name + " waist width", "mm", p.waist_width_mm, p.waist_arc_mm, 2.0, false));
    rep.checks.push_back(
        check(p.name + " area vs draped", "%", p.area_piece_cm2, p.area_draped_cm2, 1.0, true));
  }
  rep.checks.push_back(
      check("sewn bust girth", "%", rep.sewn_bust_girth_mm, bust_target, 1.0, true));
  rep.checks.push_back(
      check("sewn waist girth", "%", rep.sewn_waist_girth_mm, waist_target, 1.0, true));
}

}  // namespace

bool BodiceReport::all_pass() const {
  for (const FitCheck& c : checks)
    if (!c.pass) return false;
  return !checks.empty();
}

Result<BodiceDesign> parse_bodice_design(const std::string& text, const std::string& source) {
  auto j = parse_json(text, source);
  if (!j) return Error{j.error()};
  BodiceDesign d;
  const std::string w = source;
  for (const char* key : {"name", "form", "fabric"})
    if (j->contains(key) && !(*j)[key].is_string())
      return Error{w + "." + key + ": must be a string"};
  d.name = j->value("name", d.name);
  d.form = j->value("form", d.form);
  d.fabric = j->value("fabric", d.fabric);
  double ease_mm = 0, sa_mm = d.seam_allowance * 1000, ri = d.relax_iterations,
         si = d.sew_iterations;
  for (std::string e :
       {get_num(*j, "ease_mm", w, &ease_mm), get_num(*j, "seam_allowance_mm", w, &sa_mm),
        get_num(*j, "row_step", w, &d.row_step), get_num(*j, "column_step", w, &d.column_step),
        get_num(*j, "relax_iterations", w, &ri), get_num(*j, "sew_iterations", w, &si)})
    if (!e.empty()) return Error{e};
  if (!(ease_mm >= 0 && ease_mm <= 300)) return Error{w + ".ease_mm: not in [0, 300]"};
  if (!(sa_mm >= 0 && sa_mm <= 50)) return Error{w + ".seam_allowance_mm: not in [0, 50]"};
  if (!(d.row_step >= 0.001 && d.row_step <= 0.02))
    return Error{w + ".row_step: not in [0.001, 0.02] m"};
  if (!(d.column_step >= 0.002 && d.column_step <= 0.03))
    return Error{w + ".column_step: not in [0.002, 0.03] m"};
  if (!(ri >= 0 && ri <= 1e6) || !(si >= 0 && si <= 1e6))
    return Error{w + ".relax_iterations/sew_iterations: not in [0, 1e6]"};
  d.ease = ease_mm / 1000;
  d.seam_allowance = sa_mm / 1000;
  d.relax_iterations = static_cast<int>(ri);
  d.sew_iterations = static_cast<int>(si);
  if (!j->contains("pieces") || !(*j)["pieces"].is_array() || (*j)["pieces"].empty())
    return Error{w + ".pieces: missing or empty (a front and a back)"};
  for (size_t i = 0; i < (*j)["pieces"].size(); ++i) {
    BodicePieceDesign p;
    if (std::string e =
            parse_piece((*j)["pieces"][i], w + ".pieces[" + std::to_string(i) + "]", &p);
        !e.empty())
      return Error{e};
    d.pieces.push_back(p);
  }
  return d;
}

Result<std::string> design_type(const std::string& path) {
  std::ifstream f(path);
  if (!f) return Error{path + ": cannot open the design file"};
  std::stringstream ss;
  ss << f.rdbuf();
  auto j = parse_json(ss.str(), path);
  if (!j) return Error{j.error()};
  if (!j->contains("type")) return std::string("skirt");
  if (!(*j)["type"].is_string()) return Error{path + ".type: must be a string"};
  const std::string t = (*j)["type"].get<std::string>();
  if (t != "skirt" && t != "bodice" && t != "dress")
    return Error{path + ".type: '" + t + "' (known: skirt, bodice, dress)"};
  return t;
}

Result<DressDesign> parse_dress_design(const std::string& text, const std::string& source,
                                       const std::string& dir) {
  auto j = parse_json(text, source);
  if (!j) return Error{j.error()};
  DressDesign d;
  for (const char* key : {"name", "bodice", "skirt"})
    if (!j->contains(key) || !(*j)[key].is_string())
      return Error{source + "." + key + ": missing or not a string"};
  d.name = (*j)["name"].get<std::string>();
  const auto path_of = [&](const std::string& n) {
    return n.find('/') != std::string::npos || n.find(".json") != std::string::npos
               ? n
               : dir + "/" + n + ".json";
  };
  const std::string bp = path_of((*j)["bodice"].get<std::string>());
  std::ifstream bf(bp);
  if (!bf) return Error{source + ".bodice: " + bp + ": cannot open the design file"};
  std::stringstream bs;
  bs << bf.rdbuf();
  auto b = parse_bodice_design(bs.str(), bp);
  if (!b) return Error{source + ".bodice: " + b.error()};
  auto s = load_design(path_of((*j)["skirt"].get<std::string>()));
  if (!s) return Error{source + ".skirt: " + s.error()};
  d.bodice = *b;
  d.skirt = *s;
  return d;
}

Result<BodiceResult> drape_bodice(const BodiceDesign& d, const DressForm& form) {
  const auto t0 = std::chrono::steady_clock::now();
  const FormLandmarks& lm = form.landmarks();
  if (!(lm.armpit_y > lm.bust_y && lm.shoulder_y > lm.armpit_y && lm.neck_y > lm.shoulder_y))
    return Error{d.name + ": the form lacks the upper body's lines (armpit, shoulder, neck)"};
  const MappingSurface surf(form, d.ease, true);
  std::vector<PieceGeom> geoms;
  for (size_t i = 0; i < d.pieces.size(); ++i) {
    geoms.push_back(piece_geometry(d.pieces[i], form, surf));
    const PieceGeom& g = geoms.back();
    const std::string w = d.name + ": pieces[" + std::to_string(i) + "]";
    if (!(g.neck_centre_y > g.apex_y + 0.02))
      return Error{w + ".neck_depth: the neck point falls below the apex"};
    if (!(g.apex_phi < g.span - 0.05)) return Error{w + ".apex_angle_deg: apex beyond the side"};
    if (!(g.dart_top_y > g.apex_y + 0.02)) return Error{w + ": the apex is above the shoulder"};
  }
  const std::vector<double> ys = row_heights(geoms, d.row_step);
  BodiceResult R;
  std::vector<DrapedPiece> draped;
  BodiceReport& rep = R.report;
  rep.design = d.name;
  rep.form = d.form;
  rep.ease_mm = d.ease * 1000;
  for (size_t i = 0; i < d.pieces.size(); ++i) {
    draped.push_back(drape_piece(d, geoms[i], surf, ys));
    R.pieces.push_back(outline_of(draped.back(), d.pieces[i], d.form, 0.45 * d.row_step));
    rep.pieces.push_back(measure_piece(draped.back(), R.pieces.back(), surf, lm));
    rep.pattern_bust_girth_mm += 2 * rep.pieces.back().bust_width_mm;
    rep.pattern_waist_girth_mm += 2 * rep.pieces.back().waist_width_mm;
  }
  if (rep.pieces.size() >= 2) {
    rep.side_seam_mismatch_mm = rep.pieces[0].side_mm - rep.pieces[1].side_mm;
    rep.shoulder_seam_mismatch_mm = rep.pieces[0].shoulder_mm - rep.pieces[1].shoulder_mm;
  }
  rep.form_bust_girth_mm = form.girth_at(lm.bust_y) * 1000;
  rep.form_waist_girth_mm = form.girth_at(lm.waist_y) * 1000;
  std::vector<int> node_vertex;
  const Garment g =
      sew_bodice(draped, surf, surf.centre(lm.waist_y).x(), d.sew_iterations, &node_vertex);
  R.garment = bodice_cloth(draped, g, node_vertex, d);
  rep.sewn_bust_girth_mm = garment_girth(g, surf, lm.bust_y) * 1000;
  rep.sewn_waist_girth_mm = garment_girth(g, surf, lm.waist_y + 0.5 * d.row_step) * 1000;
  add_checks(rep, rep.form_bust_girth_mm + rep.ease_mm,
             surf.girth(lm.waist_y + 0.5 * d.row_step) * 1000);
  rep.pipeline_ms = ms_since(t0);
  return R;
}

std::string write_pattern_files(const std::string& out_dir, const std::vector<PatternPiece>& pieces,
                                const std::string& style, double seam_allowance,
                                const std::string& report_json, std::vector<std::string>* files) {
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return out_dir + ": cannot create the output directory: " + ec.message();
  const std::string o = out_dir + "/";
  ExportOptions xo;
  xo.seam_allowance = seam_allowance;
  xo.style = style;
  std::string e;
  const auto out = [&](const std::string& f, std::string err) {
    if (e.empty() && !err.empty()) e = err;
    files->push_back(f);
  };
  out("pattern.svg", write_svg(o + "pattern.svg", pieces, xo));
  out("pattern.dxf", write_dxf(o + "pattern.dxf", pieces, xo));
  out("pattern_a4.pdf", write_pdf(o + "pattern_a4.pdf", pieces, xo, Paper::a4()));
  out("pattern_letter.pdf", write_pdf(o + "pattern_letter.pdf", pieces, xo, Paper::letter()));
  if (!e.empty()) return e;
  std::ofstream f(o + "report.json");
  f << report_json << "\n";
  if (!f) return o + "report.json: write failed";
  files->push_back("report.json");
  return "";
}

std::string bodice_report_json(const BodiceReport& r, const std::vector<std::string>& files) {
  json j = bodice_json(r);
  j["files"] = files;
  return j.dump(2);
}

Result<Garment> dress_garment(const Garment& bodice, const Garment& skirt) {
  if (skirt.waist_vertices.size() < 4 || bodice.waist_vertices.size() < 4)
    return Error{"dress_garment: the bodice or the skirt has no waist seam"};
  // The waist seam: both waists as loops about the skirt waist's centre, each vertex of one
  // tied onto the other at the same place along the loop (WaistLoop).
  Vec3 centre = Vec3::Zero();
  for (int v : skirt.waist_vertices) centre += skirt.x[v];
  centre /= static_cast<double>(skirt.waist_vertices.size());
  const WaistLoop lb = waist_loop(bodice.x, bodice.waist_vertices, centre);
  const WaistLoop ls = waist_loop(skirt.x, skirt.waist_vertices, centre);
  Garment g = bodice;
  const int n = static_cast<int>(g.x.size());
  g.x.insert(g.x.end(), skirt.x.begin(), skirt.x.end());
  g.material.insert(g.material.end(), skirt.material.begin(), skirt.material.end());
  for (auto t : skirt.triangles) g.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  const int np = static_cast<int>(g.piece_names.size());
  for (int p : skirt.vertex_piece) g.vertex_piece.push_back(p + np);
  for (const std::string& s : skirt.piece_names) g.piece_names.push_back("Skirt " + s);
  for (const SeamTie& t : skirt.ties) g.ties.push_back({t.a + n, t.b0 + n, t.b1 + n, t.t});
  g.waist_vertices.clear();
  for (int v : skirt.waist_vertices) g.waist_vertices.push_back(v + n);
  tie_loops(lb, ls, 0, n, g.ties);
  tie_loops(ls, lb, n, 0, g.ties);
  g.merged_vertices = bodice.merged_vertices + skirt.merged_vertices;
  g.seams = bodice.seams;
  g.seams.insert(g.seams.end(), skirt.seams.begin(), skirt.seams.end());
  g.seams.push_back("waist seam: " + std::to_string(lb.v.size()) + " bodice and " +
                    std::to_string(ls.v.size()) + " skirt vertices tied at equal places");
  return g;
}

DressReport dress_report(const BodiceResult& bodice, const PipelineResult& skirt) {
  DressReport r;
  r.bodice = bodice.report;
  r.skirt = skirt.report;
  for (size_t i = 0; i < bodice.report.pieces.size() && i < skirt.report.pieces.size(); ++i) {
    const auto& b = bodice.report.pieces[i];
    const auto& s = skirt.report.pieces[i];
    r.waist_mismatch_mm.emplace_back(b.name + " / " + s.name, b.waist_width_mm - s.waist_seam_mm);
    r.checks.push_back(check(b.name + " waist seam vs " + s.name + " waist seam", "mm",
                             b.waist_width_mm, s.waist_seam_mm, 2.0, false));
  }
  // The skirt's own bounds, as `drape pattern --design` of the skirt reports them.
  const PipelineReport& k = skirt.report;
  const double hip = k.form_hip_girth_mm + k.ease_mm, waist = k.form_waist_girth_mm + k.ease_mm;
  r.checks.push_back(check("skirt hip widths", "mm", k.hip_width_sum_mm, hip, 2.0, false));
  r.checks.push_back(check("skirt waist widths - intakes", "mm", k.waist_width_minus_intakes_sum_mm,
                           waist, 2.0, false));
  for (const PieceReport& p : k.pieces)
    r.checks.push_back(check("Skirt " + p.name + " area vs draped", "%", p.area_piece_cm2,
                             p.area_draped_cm2, 1.0, true));
  if (k.flare == "none")
    r.checks.push_back(check("sewn skirt hip girth", "%", k.garment_hip_girth_mm, hip, 1.0, true));
  else  // a flared skirt stands away from the hip: its sewn hip line against the pattern's
    r.checks.push_back(check("sewn skirt hip line vs pattern", "%", k.garment_hip_line_mm,
                             k.pattern_hip_girth_mm, 1.0, true));
  r.checks.push_back(
      check("sewn skirt waist girth", "%", k.garment_waist_girth_mm, waist, 1.0, true));
  return r;
}

std::string dress_report_json(const DressReport& r, const std::vector<std::string>& files) {
  json j;
  j["bodice"] = bodice_json(r.bodice);
  j["skirt"] = json::parse(r.skirt.to_json());
  j["waist_mismatch_mm"] = json::object();
  for (const auto& [k, v] : r.waist_mismatch_mm) j["waist_mismatch_mm"][k] = v;
  j["checks"] = checks_json(r.checks);
  bool pass = r.bodice.all_pass();
  for (const FitCheck& c : r.checks) pass = pass && c.pass;
  j["all_pass"] = pass;
  j["files"] = files;
  return j.dump(2);
}

}  // namespace drape::sim
