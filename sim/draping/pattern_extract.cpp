// Pattern extraction by rays from the section centres and barycentric coordinates.
#include "sim/draping/pattern_extract.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <sstream>

#include "sim/form/dress_form.hpp"

namespace drape::sim {
namespace {
constexpr double kPi = 3.141592653589793;

double wrap_pi(double a) {
  a = std::fmod(a + kPi, 2 * kPi);
  if (a < 0) a += 2 * kPi;
  return a - kPi;
}

// Triangles binned by (height, angle from the centre line) for O(1) ray candidates.
class RayGrid {
 public:
  RayGrid(const Panel& panel, const MappingSurface& surf, const PieceMapping& pm) : pm_(pm) {
    const auto& x = panel.cloth.state.x;
    ylo_ = 1e9;
    double yhi = -1e9;
    for (const Vec3& p : x) {
      ylo_ = std::min(ylo_, p.y());
      yhi = std::max(yhi, p.y());
    }
    ylo_ -= 1e-3;
    ny_ = std::max(1, static_cast<int>((yhi - ylo_) / kDy) + 2);
    cells_.assign(static_cast<size_t>(ny_) * kNa, {});
    const auto& tris = panel.cloth.topo.triangles;
    for (int t = 0; t < static_cast<int>(tris.size()); ++t) {
      double y0 = 1e9, y1 = -1e9, a0 = 1e9, a1 = -1e9;
      for (int k = 0; k < 3; ++k) {
        const Vec3& p = x[tris[t][k]];
        const Vec2 c = surf.centre(p.y());
        const double a = angle(std::atan2(p.x() - c.x(), p.z() - c.y()));
        y0 = std::min(y0, p.y());
        y1 = std::max(y1, p.y());
        a0 = std::min(a0, a);
        a1 = std::max(a1, a);
      }
      if (a1 - a0 > kPi) continue;  // degenerate wrap: not on this piece
      for (int iy = ybin(y0); iy <= ybin(y1); ++iy)
        for (int ia = abin(a0); ia <= abin(a1); ++ia)
          cells_[static_cast<size_t>(iy) * kNa + ia].push_back(t);
    }
  }
  double angle(double theta) const { return wrap_pi(pm_.dir * (theta - pm_.theta_centre)); }
  const PieceMapping& mapping() const { return pm_; }
  const std::vector<int>& cell(double y, double theta) const {
    return cells_[static_cast<size_t>(ybin(y)) * kNa + abin(angle(theta))];
  }

 private:
  static constexpr double kDy = 0.01;
  static constexpr int kNa = 256;
  int ybin(double y) const { return std::clamp(static_cast<int>((y - ylo_) / kDy), 0, ny_ - 1); }
  int abin(double a) const {
    return std::clamp(static_cast<int>((a + kPi) / (2 * kPi) * kNa), 0, kNa - 1);
  }
  const PieceMapping& pm_;
  double ylo_ = 0;
  int ny_ = 1;
  std::vector<std::vector<int>> cells_;
};

// The cloth as a curved surface: the mapping M of a material point (eqs. 2-1..2-10) plus the
// displacement of the cloth nodes from their mapped positions, interpolated linearly over each
// triangle: X(m) = M(m) + sum_i b_i(m) (x_i - M(m_i)). Before relaxation the displacements are
// zero and X is the mapping itself, so extraction inverts the mapping exactly (not the planar
// triangles' chords of it); after relaxation only the small, smooth displacement is linear.
class CurvedCloth {
 public:
  CurvedCloth(const Panel& panel, const MappingSurface& surf, const PieceMapping& pm)
      : panel_(panel), surf_(surf), pm_(pm) {
    rows_.resize(panel.ny);
    for (int j = 0; j < panel.ny; ++j)
      rows_[j] = ArcTable::build(surf, pm.y_of_v(j * panel.dy), pm.theta_centre, pm.dir);
  }
  Vec3 mapped(const Vec2& m, int zone) const {
    const double y = pm_.y_of_v(m.y());
    return surf_.point(y, pm_.theta(zone, panel_.centre_distance(m.x()), y, table(m.y())));
  }
  // X(m) on the triangle of grid cell column ci (the row from m) that contains m best.
  Vec3 at_cell(int ci, const Vec2& m) const {
    const int cj = std::clamp(static_cast<int>(std::floor(m.y() / panel_.dy)), 0, panel_.ny - 2);
    int best = -1;
    Vec3 bb;
    double best_min = -1e300;
    for (int k = 0; k < 2; ++k) {
      const int t = panel_.cell_triangle(ci, cj, k);
      const Vec3 b = panel_.barycentric(t, m);
      if (b.minCoeff() > best_min) {
        best_min = b.minCoeff();
        best = t;
        bb = b;
      }
    }
    return at(best, bb, m);
  }
  Vec3 at(int tri, const Vec3& b, const Vec2& m) const {
    const auto& topo = panel_.cloth.topo;
    const auto& t = topo.triangles[tri];
    const int z = topo.triangle_zone[tri];
    Vec3 p = mapped(m, z);
    for (int k = 0; k < 3; ++k)
      p += b[k] * (panel_.cloth.state.x[t[k]] - mapped(topo.material[t[k]], z));
    return p;
  }

 private:
  const ArcTable& table(double v) const {
    const double f = v / panel_.dy;
    const int j = static_cast<int>(std::lround(f));
    if (j >= 0 && j < panel_.ny && std::abs(f - j) < 1e-9) return rows_[j];
    auto it = cache_.find(v);
    if (it != cache_.end()) return it->second;
    if (cache_.size() > 4096) cache_.clear();
    return cache_.emplace(v, ArcTable::build(surf_, pm_.y_of_v(v), pm_.theta_centre, pm_.dir))
        .first->second;
  }
  const Panel& panel_;
  const MappingSurface& surf_;
  const PieceMapping& pm_;
  std::vector<ArcTable> rows_;
  mutable std::map<double, ArcTable> cache_;
};

struct Hit {
  bool ok = false;
  int tri = -1;
  Vec3 bary;
  Vec2 flat;
  Vec3 world;
};

// Ray from the section centre at height y toward angle theta against the cloth triangles of the
// allowed zone (-1: any). Tolerant: the least-violating triangle within 4 mm counts as hit
// (near a dart tip the relaxed layers may part by a little: the point is clamped onto the edge).
Hit cast(const Panel& panel, const MappingSurface& surf, const RayGrid& grid,
         const CurvedCloth& curved, double y, double theta, int zone) {
  const auto& x = panel.cloth.state.x;
  const auto& topo = panel.cloth.topo;
  const Vec2 c2 = surf.centre(y);
  const Vec3 o(c2.x(), y, c2.y());
  const Vec3 d(std::sin(theta), 0, std::cos(theta));
  Hit best;
  double best_viol = 1e9;
  for (int t : grid.cell(y, theta)) {
    if (zone >= 0 && topo.triangle_zone[t] != zone) continue;
    const auto& tri = topo.triangles[t];
    const Vec3 &a = x[tri[0]], &b = x[tri[1]], &cc = x[tri[2]];
    const Vec3 e1 = b - a, e2 = cc - a;
    const Vec3 pv = d.cross(e2);
    const double det = e1.dot(pv);
    if (std::abs(det) < 1e-14) continue;
    const Vec3 tv = o - a;
    const double u = tv.dot(pv) / det;
    const Vec3 qv = tv.cross(e1);
    const double v = d.dot(qv) / det;
    const double tt = e2.dot(qv) / det;  // Moller-Trumbore
    if (tt <= 0) continue;
    const Vec3 bc(1 - u - v, u, v);
    const double viol = std::max(0.0, -bc.minCoeff()) * (e1.norm() + e2.norm());
    if (viol < best_viol) {
      best_viol = viol;
      best.tri = t;
      best.bary = bc;
    }
  }
  if (best.tri < 0 || best_viol > 4e-3) return best;
  Vec3 bc = best.bary.cwiseMax(0.0);
  bc /= bc.sum();
  const auto& tri = topo.triangles[best.tri];
  best.ok = true;
  best.bary = bc;
  best.flat = bc[0] * topo.material[tri[0]] + bc[1] * topo.material[tri[1]] +
              bc[2] * topo.material[tri[2]];  // barycentrics do not depend on the deformation
  best.world = bc[0] * x[tri[0]] + bc[1] * x[tri[1]] + bc[2] * x[tri[2]];
  if (best_viol > 1e-4) return best;  // clamped onto an edge: keep the planar hit
  // Refine on the curved cloth (Newton in material space, the planar triangle's Jacobian):
  // find m with X(m) on the ray, i.e. height y and angle theta about the section centre.
  const auto& mat = topo.material;
  Eigen::Matrix<double, 3, 2> A;
  {
    Eigen::Matrix2d M;
    M << (mat[tri[1]] - mat[tri[0]]).x(), (mat[tri[2]] - mat[tri[0]]).x(),
        (mat[tri[1]] - mat[tri[0]]).y(), (mat[tri[2]] - mat[tri[0]]).y();
    Eigen::Matrix<double, 3, 2> E;
    E.col(0) = x[tri[1]] - x[tri[0]];
    E.col(1) = x[tri[2]] - x[tri[0]];
    A = E * M.inverse();
  }
  Vec2 m = best.flat;
  Vec3 X = curved.at(best.tri, panel.barycentric(best.tri, m), m);
  for (int it = 0; it < 8; ++it) {
    const Vec2 c = surf.centre(X.y());
    const double dx = X.x() - c.x(), dz = X.z() - c.y(), rho2 = dx * dx + dz * dz;
    if (rho2 < 1e-12) break;
    Eigen::Matrix<double, 2, 3> G;
    G << 0, 1, 0, dz / rho2, 0, -dx / rho2;
    const Eigen::Matrix2d J = G * A;
    const Eigen::Vector2d r(X.y() - y, wrap_pi(std::atan2(dx, dz) - theta));
    if (std::abs(J.determinant()) < 1e-14) break;
    const Eigen::Vector2d dm = J.inverse() * r;
    m -= Vec2(dm.x(), dm.y());
    X = curved.at(best.tri, panel.barycentric(best.tri, m), m);
    if (dm.norm() < 1e-11) break;
  }
  if ((m - best.flat).norm() < 0.5 * (mat[tri[1]] - mat[tri[0]]).norm()) {
    best.flat = m;
    best.world = X;
    best.bary = panel.barycentric(best.tri, m);
  }
  return best;
}

struct RefPoint {
  double y, theta;
  int zone;
};

int steps_for(double len, double step) {
  return std::max(2, static_cast<int>(std::ceil(len / step)));
}

}  // namespace

// Removes self-intersection loops of the outline (a relaxed cloth may fold a few outline points
// back over a seam near a dart tip or a corner): where segment i properly crosses a later,
// non-adjacent segment j, the points between them (the shorter way round) are dropped and the
// crossing point is inserted. Notch indices follow. Returns the number of loops removed.
int remove_outline_loops(PatternPiece& pc) {
  int loops = 0;
  for (int guard = 0; guard < 1000; ++guard) {
    const int n = static_cast<int>(pc.outline.size());
    if (n < 4) break;
    int fi = -1, fj = -1;
    double fs = 0;
    for (int i = 0; i < n && fi < 0; ++i) {
      const Vec2 a = pc.outline[i], b = pc.outline[(i + 1) % n];
      for (int k = 2; k <= n / 2 && fi < 0; ++k) {
        const int j = (i + k) % n;
        if ((j + 1) % n == i) continue;
        const Vec2 c = pc.outline[j], d = pc.outline[(j + 1) % n];
        const Vec2 r = b - a, q = d - c;
        const double den = r.x() * q.y() - r.y() * q.x();
        if (std::abs(den) < 1e-20) continue;
        const Vec2 w = c - a;
        const double s = (w.x() * q.y() - w.y() * q.x()) / den;
        const double t = (w.x() * r.y() - w.y() * r.x()) / den;
        if (s > 1e-9 && s < 1 - 1e-9 && t > 1e-9 && t < 1 - 1e-9) {
          fi = i;
          fj = j;
          fs = s;
        }
      }
    }
    if (fi < 0) break;
    ++loops;
    const int i1 = (fi + 1) % n;
    const auto removed = [&](int m) {  // cyclic range i + 1 .. j
      return ((m - i1 + n) % n) <= ((fj - i1 + n) % n);
    };
    PatternPiece out = pc;
    out.outline.clear();
    out.outline3d.clear();
    out.ref.clear();
    out.seg_label.clear();
    std::vector<int> map(n, -1);
    int at_cross = -1;
    for (int m = 0; m < n; ++m) {
      if (removed(m)) continue;
      map[m] = static_cast<int>(out.outline.size());
      out.outline.push_back(pc.outline[m]);
      out.outline3d.push_back(pc.outline3d[m]);
      out.ref.push_back(pc.ref[m]);
      out.seg_label.push_back(pc.seg_label[m]);
      if (m == fi) {
        at_cross = static_cast<int>(out.outline.size());
        out.outline.push_back(pc.outline[fi] + fs * (pc.outline[i1] - pc.outline[fi]));
        out.outline3d.push_back(pc.outline3d[fi] + fs * (pc.outline3d[i1] - pc.outline3d[fi]));
        out.ref.push_back(pc.ref[fi] + fs * (pc.ref[i1] - pc.ref[fi]));
        out.ref.back().z() = pc.ref[fi].z();
        out.seg_label.push_back(pc.seg_label[fj]);
      }
    }
    out.notches.clear();
    for (int v : pc.notches) out.notches.push_back(map[v] >= 0 ? map[v] : at_cross);
    pc = std::move(out);
  }
  return loops;
}

int PatternPiece::label_index(const std::string& n) const {
  for (size_t i = 0; i < labels.size(); ++i)
    if (labels[i] == n) return static_cast<int>(i);
  return -1;
}

double PatternPiece::area() const {
  double a = 0;
  for (size_t i = 0; i < outline.size(); ++i) {
    const Vec2 &p = outline[i], &q = outline[(i + 1) % outline.size()];
    a += p.x() * q.y() - p.y() * q.x();
  }
  return 0.5 * a;
}

double PatternPiece::seam_length(const std::string& label) const {
  const int li = label_index(label);
  double s = 0;
  for (size_t i = 0; i < outline.size(); ++i)
    if (seg_label[i] == li) s += (outline[(i + 1) % outline.size()] - outline[i]).norm();
  return s;
}

double PatternPiece::hip_width() const {
  double s = 0;
  for (size_t i = 1; i < hip_line.size(); ++i) s += (hip_line[i] - hip_line[i - 1]).norm();
  return s;
}

std::vector<int> PatternPiece::seam_points(const std::string& label) const {
  const int li = label_index(label);
  const int n = static_cast<int>(outline.size());
  std::vector<int> pts;
  if (li < 0) return pts;
  // Start at a segment whose predecessor has another label.
  int start = -1;
  for (int i = 0; i < n; ++i)
    if (seg_label[i] == li && seg_label[(i + n - 1) % n] != li) start = i;
  if (start < 0) return pts;
  for (int i = start; seg_label[i % n] == li && static_cast<int>(pts.size()) < n; ++i)
    pts.push_back(i % n);
  pts.push_back((start + static_cast<int>(pts.size())) % n);
  return pts;
}

double polyline_fairness(const std::vector<Vec2>& pts) {
  constexpr double kDegPerRad = 180.0 / kPi;
  double worst = 0;
  for (size_t i = 1; i + 1 < pts.size(); ++i) {
    const Vec2 a = pts[i] - pts[i - 1], b = pts[i + 1] - pts[i];
    const double la = a.norm(), lb = b.norm();
    if (la < 1e-9 || lb < 1e-9) continue;  // a repeated point turns nothing
    const double turn = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
    worst = std::max(worst, std::abs(turn) * kDegPerRad / (0.5 * (la + lb) * 1000.0));
  }
  return worst;
}

double seam_fairness(const PatternPiece& piece, const std::string& label) {
  const int li = piece.label_index(label), n = static_cast<int>(piece.outline.size());
  double worst = 0;
  for (int i = 0; li >= 0 && i < n; ++i) {
    if (piece.seg_label[i] != li || piece.seg_label[(i + n - 1) % n] == li) continue;
    std::vector<Vec2> run{piece.outline[i]};  // one run of the label, from its first point
    for (int k = i; piece.seg_label[k % n] == li && static_cast<int>(run.size()) <= n; ++k)
      run.push_back(piece.outline[(k + 1) % n]);
    worst = std::max(worst, polyline_fairness(run));
  }
  if (li >= 0 && n >= 3 &&
      std::all_of(piece.seg_label.begin(), piece.seg_label.end(), [&](int l) { return l == li; })) {
    std::vector<Vec2> loop = piece.outline;  // the whole closed outline: every point counts
    loop.push_back(piece.outline[0]);
    loop.push_back(piece.outline[1]);
    loop.insert(loop.begin(), piece.outline[n - 1]);
    worst = polyline_fairness(loop);
  }
  return worst;
}

bool inside_polygon(const std::vector<Vec2>& poly, const Vec2& p) {
  bool in = false;
  const size_t n = poly.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2 &a = poly[i], &b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      in = !in;
  }
  return in;
}

Result<PatternPiece> extract_piece(const Panel& panel, const MappingSurface& surf,
                                   const PieceMapping& pm, const PieceLines& L,
                                   const ExtractOptions& opt) {
  const int nz = panel.num_zones();
  const double span = std::abs(wrap_pi(pm.dir * (pm.theta_side - pm.theta_centre)));
  const double r_avg = surf.girth(L.hip_y) / (2 * kPi);
  const auto theta_at = [&](double f) { return pm.theta_centre + pm.dir * span * f; };
  PatternPiece piece;
  struct Run {
    std::string label;
    std::vector<RefPoint> pts;
    int slit = -1;     // dart legs: the slit whose edge bounds this leg
    bool near = true;  // leg on the slit's near (centre-side) edge
  };
  std::vector<Run> runs;
  const auto vertical = [&](double th, int zone, double y0, double y1) {
    std::vector<RefPoint> v;
    const int n = steps_for(std::abs(y1 - y0), opt.step);
    for (int k = 0; k <= n; ++k) v.push_back({y0 + (y1 - y0) * k / n, th, zone});
    return v;
  };
  const auto horizontal = [&](double y, double f0, double f1, int zone) {
    std::vector<RefPoint> v;
    const int n = steps_for(std::abs(f1 - f0) * span * r_avg, opt.step);
    for (int k = 0; k <= n; ++k) v.push_back({y, theta_at(f0 + (f1 - f0) * k / n), zone});
    return v;
  };
  const RayGrid grid(panel, surf, pm);
  const CurvedCloth curved(panel, surf, pm);
  // Dart lines from the slit ends: the 3D line of each slit's far edge (zone z + 1's boundary).
  const auto& x = panel.cloth.state.x;
  std::vector<std::vector<RefPoint>> dart_line(panel.slits.size());
  std::vector<double> dart_f_waist(panel.slits.size());
  for (size_t s = 0; s < panel.slits.size(); ++s) {
    const PanelSlit& ps = panel.slits[s];
    std::vector<Vec3> edge{x[ps.tip_node]};
    for (int v : ps.far_nodes) edge.push_back(x[v]);
    if (edge.front().y() >= L.waist_y || edge.back().y() <= L.waist_y)
      return Error{"pieces." + piece.name + ".darts[" + std::to_string(s) +
                   "]: the dart must cross the waist line (slit end below it, top above it)"};
    const double y_tip = edge.front().y();
    const int n = steps_for(L.waist_y - y_tip, opt.step);
    size_t seg = 0;
    for (int k = 0; k <= n; ++k) {
      const double y = y_tip + (L.waist_y - y_tip) * k / n;
      while (seg + 2 < edge.size() && edge[seg + 1].y() < y) ++seg;
      const double f =
          std::clamp((y - edge[seg].y()) / (edge[seg + 1].y() - edge[seg].y()), 0.0, 1.0);
      Vec3 p = edge[seg] + f * (edge[seg + 1] - edge[seg]);
      // On the curved cloth: the point of the slit's far edge at height y (secant on v from
      // the polyline's guess; the chord polyline itself lies inside the curved surface).
      if (k > 0 && k < n) {
        const int far_cell = panel.design.centre_edge_left ? ps.column : ps.column - 1;
        const double u = panel.cloth.topo.material[ps.tip_node].x();
        double v0 = ps.v_tip + (seg + f) * panel.dy, v1 = v0 + 1e-4;
        const auto at = [&](double v) { return curved.at_cell(far_cell, Vec2(u, v)); };
        Vec3 p0 = at(v0), p1 = at(v1);
        for (int it = 0; it < 8 && std::abs(p1.y() - y) > 1e-12 && p1.y() != p0.y(); ++it) {
          const double v2 = v1 - (p1.y() - y) * (v1 - v0) / (p1.y() - p0.y());
          v0 = v1;
          p0 = p1;
          v1 = v2;
          p1 = at(v1);
        }
        if (std::abs(p1.y() - y) < 1e-7) p = p1;
      }
      const Vec2 c = surf.centre(y);
      dart_line[s].push_back({y, std::atan2(p.x() - c.x(), p.z() - c.y()), 0});
    }
    dart_f_waist[s] =
        std::abs(wrap_pi(pm.dir * (dart_line[s].back().theta - pm.theta_centre))) / span;
  }
  // Runs in counter-clockwise order for a centre-left panel: hem, side, waist with darts, centre.
  runs.push_back({"hem", horizontal(L.hem_y, 0, 1, -1)});
  {
    Run side{"side", vertical(pm.theta_side, nz - 1, L.hem_y, L.hip_y)};
    auto up = vertical(pm.theta_side, nz - 1, L.hip_y, L.waist_y);
    side.pts.insert(side.pts.end(), up.begin() + 1, up.end());
    runs.push_back(side);
  }
  double f_prev = 1.0;
  for (int z = nz - 1; z >= 0; --z) {
    const double f_end = z > 0 ? dart_f_waist[z - 1] : 0.0;
    runs.push_back({"waist", horizontal(L.waist_y, f_prev, f_end, z)});
    if (z > 0) {
      const std::string dn = "dart" + std::to_string(z);
      Run leg2{dn + "_leg2", {}}, leg1{dn + "_leg1", {}};
      for (auto it = dart_line[z - 1].rbegin(); it != dart_line[z - 1].rend(); ++it)
        leg2.pts.push_back({it->y, it->theta, z});
      for (const RefPoint& r : dart_line[z - 1]) leg1.pts.push_back({r.y, r.theta, z - 1});
      leg2.slit = leg1.slit = z - 1;
      leg2.near = false;
      runs.push_back(leg2);
      runs.push_back(leg1);
    }
    f_prev = f_end;
  }
  {
    Run centre{L.centre_label, vertical(pm.theta_centre, 0, L.waist_y, L.hip_y)};
    auto down = vertical(pm.theta_centre, 0, L.hip_y, L.hem_y);
    centre.pts.insert(centre.pts.end(), down.begin() + 1, down.end());
    runs.push_back(centre);
  }
  // Cast the rays; consecutive runs share their corner point.
  std::vector<int> notch_ref;
  int skipped_leg_points = 0;
  for (size_t r = 0; r < runs.size(); ++r) {
    int li = piece.label_index(runs[r].label);
    if (li < 0) {
      piece.labels.push_back(runs[r].label);
      li = static_cast<int>(piece.labels.size()) - 1;
    }
    skipped_leg_points = 0;
    const size_t first = r == 0 ? 0 : 1;
    const size_t last = r + 1 == runs.size() ? runs[r].pts.size() - 1 : runs[r].pts.size();
    for (size_t k = first; k < last; ++k) {
      const RefPoint& rp = runs[r].pts[k];
      Hit h = cast(panel, surf, grid, curved, rp.y, rp.theta, rp.zone);
      // Near a dart tip the relaxed layers may part: where the overlapping layer (leg 1) does
      // not reach the dart line, the dart has no width yet (its two legs are the same slit edge
      // there); such points are left out, leg 1 runs straight from the tip to its first hit.
      // At most half of a leg may be left out.
      // A leg-1 hit clamped onto the slit column itself lies on leg 2 (the same flat line):
      // the layers have parted there, count it as a miss.
      if (h.ok && runs[r].slit >= 0 && runs[r].near && k + 1 < last) {
        const int tip = panel.slits[static_cast<size_t>(runs[r].slit)].tip_node;
        if (std::abs(h.flat.x() - panel.cloth.topo.material[tip].x()) < 2e-4) h.ok = false;
      }
      if (!h.ok && runs[r].slit >= 0 && runs[r].near && k + 1 < last &&
          ++skipped_leg_points <= static_cast<int>(runs[r].pts.size()) / 2)
        continue;
      if (!h.ok) {
        std::ostringstream e;
        e << "line '" << runs[r].label << "': no cloth in zone " << rp.zone << " at height "
          << rp.y * 1000 << " mm, angle " << rp.theta * 180 / kPi
          << " deg (is the panel wide/long enough?)";
        return Error{e.str()};
      }
      piece.outline.push_back(h.flat);
      piece.outline3d.push_back(h.world);
      piece.ref.emplace_back(rp.y, rp.theta, rp.zone);
      piece.seg_label.push_back(li);
      if (std::abs(rp.y - L.hip_y) < 1e-9 &&
          (runs[r].label == "side" || runs[r].label == L.centre_label))
        piece.notches.push_back(static_cast<int>(piece.outline.size()) - 1);
    }
  }
  // Segment labels: the segment leaving point i belongs to the run of point i + 1 except at run
  // starts, so shift: a point's label is the run that contains the segment after it.
  {
    const int n0 = static_cast<int>(piece.outline.size());
    std::vector<int> lab(n0);
    for (int i = 0; i + 1 < n0; ++i) lab[i] = piece.seg_label[i + 1];
    lab[n0 - 1] = piece.seg_label[n0 - 1];  // the closing segment belongs to the last run
    piece.seg_label = lab;
  }
  // A simple polygon for cutting and remeshing: no self-crossings.
  piece.loops_removed = remove_outline_loops(piece);
  const int n = static_cast<int>(piece.outline.size());
  // Darts: tip and leg tops from the labels.
  for (int z = 1; z < nz; ++z) {
    const std::string dn = "dart" + std::to_string(z);
    const std::vector<int> l2 = piece.seam_points(dn + "_leg2"),
                           l1 = piece.seam_points(dn + "_leg1");
    if (l2.empty() || l1.empty()) continue;
    PatternPiece::Dart d;
    d.leg2_top = l2.front();
    d.tip = l2.back();
    d.leg1_top = l1.back();
    d.intake = (piece.outline[d.leg1_top] - piece.outline[d.leg2_top]).norm();
    piece.darts.push_back(d);
    piece.notches.push_back(d.leg1_top);
    piece.notches.push_back(d.leg2_top);
  }
  // Hip line (for the width measurement) and the grain line.
  for (const RefPoint& rp : horizontal(L.hip_y, 0, 1, -1)) {
    Hit h = cast(panel, surf, grid, curved, rp.y, rp.theta, -1);
    if (!h.ok) return Error{"line 'hip': no cloth at angle " + std::to_string(rp.theta)};
    piece.hip_line.push_back(h.flat);
  }
  const double gu = 0.5 * (piece.hip_line.front().x() + piece.hip_line.back().x());
  piece.grain_a = Vec2(gu, pm.v_of_y(L.hem_y) + 0.05);
  piece.grain_b = Vec2(gu, pm.v_of_y(L.hip_y));
  // Counter-clockwise orientation in material space.
  if (piece.area() < 0) {
    std::reverse(piece.outline.begin(), piece.outline.end());
    std::reverse(piece.outline3d.begin(), piece.outline3d.end());
    std::reverse(piece.ref.begin(), piece.ref.end());
    std::vector<int> lab(n);
    for (int k = 0; k < n; ++k) lab[k] = piece.seg_label[((n - 2 - k) % n + n) % n];
    piece.seg_label = lab;
    for (int& i : piece.notches) i = n - 1 - i;
    for (auto& d : piece.darts) {
      d.tip = n - 1 - d.tip;
      d.leg1_top = n - 1 - d.leg1_top;
      d.leg2_top = n - 1 - d.leg2_top;
    }
  }
  return piece;
}

double outline_error_vs_mapping(const PatternPiece& piece, const Panel& panel,
                                const MappingSurface& surf, const PieceMapping& pm) {
  double err = 0;
  for (size_t i = 0; i < piece.outline.size(); ++i) {
    const double y = piece.ref[i].x(), th = piece.ref[i].y();
    const int zone = static_cast<int>(piece.ref[i].z());
    const ArcTable T = ArcTable::build(surf, y, pm.theta_centre, pm.dir);
    // Zone -1 (any): the zone of the flat point found.
    int z = zone;
    if (z < 0) {
      Vec3 b;
      const int t = panel.locate(piece.outline[i], &b);
      z = t >= 0 ? panel.cloth.topo.triangle_zone[t] : 0;
    }
    const Vec2 analytic(panel.u_of_distance(pm.l_at(z, y, th, T)), pm.v_of_y(y));
    err = std::max(err, (analytic - piece.outline[i]).norm());
  }
  return err;
}

double draped_area(const PatternPiece& piece, const Panel& panel) {
  const auto& topo = panel.cloth.topo;
  const auto& x = panel.cloth.state.x;
  // Seven sample points per triangle decide how much of it lies inside the outline.
  static const double w[7][3] = {
      {1.0 / 3, 1.0 / 3, 1.0 / 3}, {0.6, 0.2, 0.2},   {0.2, 0.6, 0.2},  {0.2, 0.2, 0.6},
      {0.45, 0.45, 0.1},           {0.1, 0.45, 0.45}, {0.45, 0.1, 0.45}};
  double a3 = 0, a2 = 0;
  for (int t = 0; t < topo.num_triangles(); ++t) {
    const auto& tri = topo.triangles[t];
    int in = 0;
    for (const auto& ww : w) {
      const Vec2 p = ww[0] * topo.material[tri[0]] + ww[1] * topo.material[tri[1]] +
                     ww[2] * topo.material[tri[2]];
      in += inside_polygon(piece.outline, p) ? 1 : 0;
    }
    if (!in) continue;
    // In the dart overlap, only the triangles of the layer the piece keeps count: the piece
    // never contains flat points of the intake wedge, so the parity test already excludes them.
    const Vec2 e1 = topo.material[tri[1]] - topo.material[tri[0]];
    const Vec2 e2 = topo.material[tri[2]] - topo.material[tri[0]];
    const double af = 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    const double a3d = 0.5 * (x[tri[1]] - x[tri[0]]).cross(x[tri[2]] - x[tri[0]]).norm();
    a2 += af * in / 7.0;
    a3 += a3d * in / 7.0;
  }
  return a2 > 0 ? a3 / a2 * std::abs(piece.area()) : 0;
}

}  // namespace drape::sim
