// The only translation unit that includes CGAL (header-only, slow to compile): constrained
// Delaunay triangulation of a pattern piece refined by Ruppert/Shewchuk-style Delaunay_mesher_2.
#include "sim/draping/remesh.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <map>

namespace drape::sim {
namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Delaunay_mesh_vertex_base_2<K>;
using Fb = CGAL::Delaunay_mesh_face_base_2<K>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using CDT = CGAL::Constrained_Delaunay_triangulation_2<K, Tds>;
using Criteria = CGAL::Delaunay_mesh_size_criteria_2<CDT>;

double seg_param(const Vec2& a, const Vec2& b, const Vec2& p, double* dist) {
  const Vec2 d = b - a;
  const double t = std::clamp((p - a).dot(d) / std::max(d.squaredNorm(), 1e-30), 0.0, 1.0);
  *dist = (a + t * d - p).norm();
  return t;
}
}  // namespace

std::vector<int> RemeshedPiece::seam_vertices(const PatternPiece& piece,
                                              const std::string& label) const {
  std::vector<int> out;
  const std::vector<int> pts = piece.seam_points(label);
  if (pts.size() < 2) return out;
  const int n = static_cast<int>(piece.outline.size());
  const double s0 = pts.front(), len = static_cast<double>(pts.size() - 1);
  std::vector<std::pair<double, int>> found;
  for (size_t v = 0; v < boundary_param.size(); ++v) {
    if (boundary_param[v] < 0) continue;
    double s = boundary_param[v] - s0;
    if (s < -1e-9) s += n;
    if (s > n - 1e-9) s -= n;
    if (s <= len + 1e-9) found.emplace_back(s, static_cast<int>(v));
  }
  std::sort(found.begin(), found.end());
  for (const auto& f : found) out.push_back(f.second);
  return out;
}

Result<RemeshedPiece> remesh_piece(const PatternPiece& piece, const RemeshOptions& opt) {
  const int n = static_cast<int>(piece.outline.size());
  if (n < 3) return Error{"remesh: piece '" + piece.name + "' has fewer than 3 outline points"};
  if (!(opt.max_edge > 0) || !(opt.shape_bound > 0))
    return Error{"remesh: max_edge and shape_bound must be positive"};
  CDT cdt;
  // Outline points closer than min_sep to the previously kept one are left out of the input
  // (near-duplicates make the refinement chase sub-micrometre features); seam labels below are
  // still taken from the full outline.
  const double min_sep = 0.05 * opt.max_edge;
  std::vector<CDT::Vertex_handle> vh;
  Vec2 last_kept(1e30, 1e30);
  for (int i = 0; i < n; ++i) {
    if ((piece.outline[i] - last_kept).norm() < min_sep) continue;
    if (!vh.empty() && i == n - 1 && (piece.outline[i] - piece.outline[0]).norm() < min_sep)
      continue;
    vh.push_back(cdt.insert(CDT::Point(piece.outline[i].x(), piece.outline[i].y())));
    last_kept = piece.outline[i];
  }
  const int nk = static_cast<int>(vh.size());
  if (nk < 3) return Error{"remesh: piece '" + piece.name + "' outline collapses to < 3 points"};
  try {  // CGAL throws on crossing constraints (a self-intersecting outline)
    for (int i = 0; i < nk; ++i)
      if (vh[i] != vh[(i + 1) % nk]) cdt.insert_constraint(vh[i], vh[(i + 1) % nk]);
    // Step by step with a cap, so that a pathological outline gives an error, never a hang.
    CGAL::Delaunay_mesher_2<CDT, Criteria> mesher(cdt, Criteria(opt.shape_bound, opt.max_edge));
    mesher.init();
    const double a = std::abs(piece.area());
    const long cap = 10000 + static_cast<long>(50 * a / (opt.max_edge * opt.max_edge));
    long steps = 0;
    while (!mesher.is_refinement_done() && steps < cap) {
      mesher.step_by_step_refine_mesh();
      ++steps;
    }
    if (!mesher.is_refinement_done())
      return Error{"remesh: piece '" + piece.name + "': refinement did not finish in " +
                   std::to_string(cap) + " steps (degenerate outline?)"};
  } catch (const std::exception& e) {
    return Error{"remesh: piece '" + piece.name +
                 "': outline is not a simple polygon (CGAL: " + e.what() + ")"};
  }

  RemeshedPiece out;
  std::map<CDT::Vertex_handle, int> index;
  const auto id_of = [&](CDT::Vertex_handle v) {
    auto it = index.find(v);
    if (it != index.end()) return it->second;
    const int id = static_cast<int>(out.material.size());
    index.emplace(v, id);
    out.material.emplace_back(v->point().x(), v->point().y());
    return id;
  };
  out.min_angle_deg = 180;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!f->is_in_domain()) continue;
    std::array<int32_t, 3> t{id_of(f->vertex(0)), id_of(f->vertex(1)), id_of(f->vertex(2))};
    const Vec2 a = out.material[t[0]], b = out.material[t[1]], c = out.material[t[2]];
    const double cr = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (cr < 0) std::swap(t[1], t[2]);
    out.triangles.push_back(t);
    out.area += 0.5 * std::abs(cr);
    const Vec2 p[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      const Vec2 e1 = p[(k + 1) % 3] - p[k], e2 = p[(k + 2) % 3] - p[k];
      out.max_edge = std::max(out.max_edge, e1.norm());
      const double ang = std::acos(std::clamp(e1.dot(e2) / (e1.norm() * e2.norm()), -1.0, 1.0));
      out.min_angle_deg = std::min(out.min_angle_deg, ang * 180 / 3.141592653589793);
    }
  }
  if (out.triangles.empty())
    return Error{"remesh: piece '" + piece.name + "' produced no triangles"};
  // Seam labels: boundary vertices lie on an outline segment.
  const double tol = 1e-7;
  out.boundary_param.assign(out.material.size(), -1.0);
  out.vertex_label.assign(out.material.size(), -1);
  for (size_t v = 0; v < out.material.size(); ++v) {
    double best = 1e9, best_s = -1;
    int best_i = -1;
    for (int i = 0; i < n; ++i) {
      double d;
      const double t = seg_param(piece.outline[i], piece.outline[(i + 1) % n], out.material[v], &d);
      if (d < best - 1e-12) {
        best = d;
        best_i = i;
        best_s = i + t;
      }
    }
    if (best < tol) {
      if (best_s >= n) best_s -= n;
      out.boundary_param[v] = best_s;
      out.vertex_label[v] = piece.seg_label[best_i];
    }
  }
  return out;
}

}  // namespace drape::sim
