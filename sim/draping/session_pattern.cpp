// Pattern pieces from the draped cloth of a session: boundary loops in material space, cut
// edges from the smoothed cut strokes, notches at the reference lines, export and report.
#include "sim/draping/session_pattern.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <utility>

#include "sim/draping/pattern_export.hpp"
#include "sim/draping/session_lines.hpp"

namespace drape::sim {
namespace {

int find_root(std::vector<int>& parent, int v) {
  while (parent[v] != v) v = parent[v] = parent[parent[v]];
  return v;
}

// Component label per vertex (vertices joined by triangle edges); -1 for unused vertices.
std::vector<int> vertex_components(const ClothTopology& topo) {
  std::vector<int> parent(topo.num_vertices());
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& t : topo.triangles)
    for (int k = 1; k < 3; ++k) parent[find_root(parent, t[k])] = find_root(parent, t[0]);
  std::vector<int> label(topo.num_vertices(), -1);
  for (const auto& t : topo.triangles)
    for (int k = 0; k < 3; ++k) label[t[k]] = find_root(parent, t[k]);
  return label;
}

// Closed boundary loops (vertex indices) in the triangles' counter-clockwise order: the outer
// boundary of a piece runs counter-clockwise, a hole clockwise.
std::vector<std::vector<int>> boundary_loops(const ClothTopology& topo) {
  std::map<std::pair<int, int>, int> uses;
  for (const auto& t : topo.triangles)
    for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
  std::multimap<int, int> next;  // directed boundary edges a -> b
  for (const auto& t : topo.triangles)
    for (int k = 0; k < 3; ++k)
      if (uses[std::minmax(t[k], t[(k + 1) % 3])] == 1) next.emplace(t[k], t[(k + 1) % 3]);
  std::vector<std::vector<int>> loops;
  while (!next.empty()) {
    std::vector<int> loop{next.begin()->first};
    for (;;) {
      auto it = next.find(loop.back());
      if (it == next.end()) break;  // an open chain (a malformed mesh): dropped below
      const int b = it->second;
      next.erase(it);
      if (b == loop.front()) break;
      loop.push_back(b);
    }
    if (loop.size() >= 3) loops.push_back(std::move(loop));
  }
  return loops;
}

double loop_area(const std::vector<Vec2>& p) {
  double a = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec2 &u = p[i], &v = p[(i + 1) % p.size()];
    a += u.x() * v.y() - u.y() * v.x();
  }
  return 0.5 * a;
}

// The nearest point of a polyline to p: distance, arc length along it and the point.
struct StrokeHit {
  double dist = 1e300, s = 0;
  Vec2 at{0, 0};
};
StrokeHit nearest_on(const std::vector<Vec2>& line, const Vec2& p) {
  StrokeHit h;
  double s0 = 0;
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    const Vec2 a = line[i], d = line[i + 1] - line[i];
    const double len2 = d.squaredNorm();
    const double t = len2 > 0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
    const Vec2 q = a + t * d;
    const double dist = (p - q).norm();
    if (dist < h.dist) h = {dist, s0 + t * std::sqrt(len2), q};
    s0 += std::sqrt(len2);
  }
  return h;
}

// Where a material point lies on the draped cloth: the triangle of `tris` that contains it
// best (largest smallest barycentric), its positions interpolated.
Vec3 draped_point(const Cloth& cloth, const std::vector<int>& tris, const Vec2& m) {
  const auto& mat = cloth.topo.material;
  double best = -1e300;
  Vec3 out = Vec3::Zero();
  for (int t : tris) {
    const auto& tri = cloth.topo.triangles[t];
    const Vec2 a = mat[tri[0]], e1 = mat[tri[1]] - a, e2 = mat[tri[2]] - a, r = m - a;
    const double det = e1.x() * e2.y() - e1.y() * e2.x();
    if (std::abs(det) < 1e-18) continue;
    const double b1 = (r.x() * e2.y() - r.y() * e2.x()) / det;
    const double b2 = (e1.x() * r.y() - e1.y() * r.x()) / det;
    const double lo = std::min({1 - b1 - b2, b1, b2});
    if (lo <= best) continue;
    best = lo;
    Vec3 b = Vec3(1 - b1 - b2, b1, b2).cwiseMax(0.0);
    b /= b.sum();
    out =
        b[0] * cloth.state.x[tri[0]] + b[1] * cloth.state.x[tri[1]] + b[2] * cloth.state.x[tri[2]];
  }
  return out;
}

// The outline of one boundary loop, the runs along a cut stroke replaced by the stroke.
void build_outline(const Cloth& cloth, const std::vector<int>& loop,
                   const std::vector<std::vector<Vec2>>& strokes, double tol,
                   const std::vector<int>& tris, PatternPiece& pc) {
  const auto& mat = cloth.topo.material;
  const int n = static_cast<int>(loop.size());
  std::vector<int> stroke_of(n, -1);
  std::vector<StrokeHit> hit(n);
  for (int i = 0; i < n; ++i)
    for (size_t s = 0; s < strokes.size(); ++s) {
      const StrokeHit h = nearest_on(strokes[s], mat[loop[i]]);
      if (h.dist < tol && h.dist < hit[i].dist) {
        hit[i] = h;
        stroke_of[i] = static_cast<int>(s);
      }
    }
  // Start where no cut runs (a loop entirely along cuts keeps its grid edges).
  int start = 0;
  while (start < n && stroke_of[start] >= 0) ++start;
  if (start == n) {
    std::fill(stroke_of.begin(), stroke_of.end(), -1);
    start = 0;
  }
  pc.labels = {kSessionEdgeLabel, kSessionCutLabel};
  const auto push = [&](const Vec2& m, const Vec3& x, int label) {
    pc.outline.push_back(m);
    pc.outline3d.push_back(x);
    pc.ref.emplace_back(x.y(), 0.0, -1.0);
    pc.seg_label.push_back(label);
  };
  for (int k = 0; k < n;) {
    const int i = (start + k) % n;
    int len = 1;
    while (stroke_of[i] >= 0 && k + len < n && stroke_of[(start + k + len) % n] == stroke_of[i])
      ++len;
    if (stroke_of[i] < 0 || len < 2) {  // a panel edge vertex (or a lone touch of a stroke)
      push(mat[loop[i]], cloth.state.x[loop[i]], 0);
      ++k;
      continue;
    }
    // The run i .. j follows stroke s from s_i to s_j: the stroke's own points in between.
    const int j = (start + k + len - 1) % n;
    const auto& line = strokes[static_cast<size_t>(stroke_of[i])];
    const double si = hit[i].s, sj = hit[j].s;
    push(hit[i].at, cloth.state.x[loop[i]], 1);
    std::vector<std::pair<double, Vec2>> inner;
    double s = 0;
    for (size_t q = 0; q < line.size(); ++q) {
      if (q > 0) s += (line[q] - line[q - 1]).norm();
      if (s > std::min(si, sj) + 1e-9 && s < std::max(si, sj) - 1e-9)
        inner.emplace_back(s, line[q]);
    }
    if (sj < si) std::reverse(inner.begin(), inner.end());
    for (const auto& [sq, m] : inner) push(m, draped_point(cloth, tris, m), 1);
    push(hit[j].at, cloth.state.x[loop[j]], 0);
    k += len;
  }
}

void add_notches(PatternPiece& pc, double line_y) {
  if (line_y < 0) return;
  const int n = static_cast<int>(pc.outline.size());
  for (int i = 0; i < n; ++i) {
    const double a = pc.outline3d[i].y() - line_y, b = pc.outline3d[(i + 1) % n].y() - line_y;
    if ((a < 0) != (b < 0)) pc.notches.push_back(std::abs(a) <= std::abs(b) ? i : (i + 1) % n);
  }
}

}  // namespace

Result<std::vector<PatternPiece>> extract_session_pieces(
    const Cloth& cloth, const std::vector<std::vector<Vec2>>& strokes,
    const SessionPatternOptions& opt) {
  const ClothTopology& topo = cloth.topo;
  if (topo.triangles.empty()) return Error{"session pattern: the cloth has no triangles"};
  if (cloth.state.x.size() != topo.material.size())
    return Error{"session pattern: the cloth has " + std::to_string(cloth.state.x.size()) +
                 " positions for " + std::to_string(topo.material.size()) + " material points"};
  for (const auto& t : topo.triangles)
    for (int v : t)
      if (v < 0 || v >= topo.num_vertices())
        return Error{"session pattern: a triangle names vertex " + std::to_string(v) + " of " +
                     std::to_string(topo.num_vertices())};
  const double tol = opt.cut_tolerance > 0 ? opt.cut_tolerance : 0.75 * topo.spacing;
  const std::vector<int> comp = vertex_components(topo);
  std::map<int, std::vector<int>> tris_of;
  for (int t = 0; t < topo.num_triangles(); ++t) tris_of[comp[topo.triangles[t][0]]].push_back(t);
  // Per component its outer loop: the boundary loop of the largest positive area.
  std::map<int, std::pair<double, std::vector<int>>> outer;
  for (auto& loop : boundary_loops(topo)) {
    std::vector<Vec2> p;
    for (int v : loop) p.push_back(topo.material[v]);
    const double a = loop_area(p);
    auto& o = outer[comp[loop[0]]];
    if (a > o.first) o = {a, std::move(loop)};
  }
  std::vector<PatternPiece> pieces;
  for (auto& [c, o] : outer) {
    if (o.first < opt.min_piece_area) continue;
    PatternPiece pc;
    pc.name = "Piece " + std::to_string(pieces.size() + 1);
    pc.size = opt.size;
    pc.quantity = 1;
    build_outline(cloth, o.second, strokes, tol, tris_of[c], pc);
    pc.loops_removed = remove_outline_loops(pc);
    if (pc.area() < 0) continue;  // a stroke folded the outline over itself: not a piece
    add_notches(pc, opt.waist_y);
    add_notches(pc, opt.hip_y);
    // The widths along the hip and waist lines (the line from edge to edge on the flat piece,
    // its ends on the smoothed cut edges: continued by up to three cut tolerances).
    if (opt.hip_y >= 0)
      pc.hip_line = session_reference_line(cloth, tris_of[c], pc.outline, opt.hip_y, 3 * tol);
    if (opt.waist_y >= 0)
      pc.waist_line = session_reference_line(cloth, tris_of[c], pc.outline, opt.waist_y, 3 * tol);
    Vec2 lo = pc.outline[0], hi = pc.outline[0];
    for (const Vec2& m : pc.outline) {
      lo = lo.cwiseMin(m);
      hi = hi.cwiseMax(m);
    }
    const double gu = 0.5 * (lo.x() + hi.x()), h = hi.y() - lo.y();
    pc.grain_a = Vec2(gu, lo.y() + 0.15 * h);
    pc.grain_b = Vec2(gu, hi.y() - 0.15 * h);
    pieces.push_back(std::move(pc));
  }
  if (pieces.empty()) return Error{"session pattern: no piece larger than the minimum area"};
  return pieces;
}

std::string SessionPatternReport::to_json(const std::vector<PatternPiece>& pieces) const {
  nlohmann::json j;
  j["files"] = files;
  j["pieces"] = nlohmann::json::array();
  for (const PatternPiece& pc : pieces) {
    nlohmann::json pj;
    pj["name"] = pc.name;
    pj["size"] = pc.size;
    pj["area_cm2"] = pc.area() * 1e4;
    pj["outline_points"] = pc.outline.size();
    pj["notches"] = pc.notches.size();
    pj["loops_removed"] = pc.loops_removed;
    // Widths along the reference lines, flat, edge to edge (absent: the piece does not cross).
    if (!pc.hip_line.empty()) pj["hip_width_mm"] = pc.hip_width() * 1000;
    if (!pc.waist_line.empty()) pj["waist_width_mm"] = polyline_length(pc.waist_line) * 1000;
    for (size_t l = 0; l < pc.labels.size(); ++l) {
      pj["seam_length_mm"][pc.labels[l]] = pc.seam_length(pc.labels[l]) * 1000;
      pj["fairness_deg_per_mm"][pc.labels[l]] = seam_fairness(pc, pc.labels[l]);
    }
    j["pieces"].push_back(pj);
  }
  return j.dump(2);
}

Result<SessionPatternReport> write_session_pattern(const std::string& dir,
                                                   const std::vector<PatternPiece>& pieces,
                                                   double seam_allowance,
                                                   const std::string& style) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Error{dir + ": cannot create the pattern directory: " + ec.message()};
  ExportOptions xo;
  xo.seam_allowance = seam_allowance;
  xo.style = style;
  SessionPatternReport rep;
  const std::string o = dir + "/";
  const auto step = [&](const std::string& name, const std::string& err) -> std::string {
    if (!err.empty()) return err;
    rep.files.push_back(name);
    return "";
  };
  for (const std::string& e :
       {step("pattern.svg", write_svg(o + "pattern.svg", pieces, xo)),
        step("pattern.dxf", write_dxf(o + "pattern.dxf", pieces, xo)),
        step("pattern_a4.pdf", write_pdf(o + "pattern_a4.pdf", pieces, xo, Paper::a4())),
        step("pattern_letter.pdf",
             write_pdf(o + "pattern_letter.pdf", pieces, xo, Paper::letter()))})
    if (!e.empty()) return Error{e};
  rep.files.push_back("report.json");
  std::ofstream f(o + "report.json");
  f << rep.to_json(pieces) << "\n";
  if (!f) return Error{o + "report.json: write failed"};
  return rep;
}

}  // namespace drape::sim
