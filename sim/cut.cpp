// The cut primitive: stroke → surface points → edge path → split by vertex duplication
// (method §3.5), on any triangulation.
#include "sim/cut.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <queue>

namespace drape::sim {
namespace {

// Vertex → incident triangles and vertex → neighbour vertices, in CSR form.
struct Adjacency {
  std::vector<int32_t> tri_start, tris;
  std::vector<int32_t> nb_start, nbs;
};

Adjacency build_adjacency(const Cloth& cloth) {
  const int n = cloth.num_vertices();
  const auto& T = cloth.topo.triangles;
  Adjacency a;
  a.tri_start.assign(n + 1, 0);
  for (const auto& t : T)
    for (int k = 0; k < 3; ++k) ++a.tri_start[t[k] + 1];
  for (int i = 0; i < n; ++i) a.tri_start[i + 1] += a.tri_start[i];
  a.tris.resize(a.tri_start[n]);
  std::vector<int32_t> fill(a.tri_start.begin(), a.tri_start.end() - 1);
  for (int32_t ti = 0; ti < static_cast<int32_t>(T.size()); ++ti)
    for (int k = 0; k < 3; ++k) a.tris[fill[T[ti][k]]++] = ti;
  // Neighbours: the other corners of incident triangles, deduplicated.
  a.nb_start.assign(n + 1, 0);
  a.nbs.reserve(a.tris.size() * 2);
  std::vector<int32_t> mark(n, -1);  // mark[w] == i: w already listed for i
  for (int i = 0; i < n; ++i) {
    for (int32_t s = a.tri_start[i]; s < a.tri_start[i + 1]; ++s) {
      const auto& t = T[a.tris[s]];
      for (int k = 0; k < 3; ++k)
        if (t[k] != i && mark[t[k]] != i) mark[t[k]] = i, a.nbs.push_back(t[k]);
    }
    a.nb_start[i + 1] = static_cast<int32_t>(a.nbs.size());
  }
  return a;
}

// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection §5.1.5);
// returns barycentric coordinates.
Vec3 closest_bary(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0)) return {1, 0, 0};  // degenerate triangle
  const double v = vb / denom, w = vc / denom;
  return {1 - v - w, v, w};
}

SurfacePoint on_triangle(const Cloth& cloth, int32_t ti, const Vec3& p) {
  const auto& t = cloth.topo.triangles[ti];
  const auto& x = cloth.state.x;
  SurfacePoint sp;
  sp.triangle = ti;
  sp.bary = closest_bary(p, x[t[0]], x[t[1]], x[t[2]]);
  sp.position = sp.bary[0] * x[t[0]] + sp.bary[1] * x[t[1]] + sp.bary[2] * x[t[2]];
  const auto& m = cloth.topo.material;
  sp.material = sp.bary[0] * m[t[0]] + sp.bary[1] * m[t[1]] + sp.bary[2] * m[t[2]];
  sp.distance = (sp.position - p).norm();
  return sp;
}

// Best surface point among the triangles incident to vertex v and its neighbours.
SurfacePoint surface_near_vertex(const Cloth& cloth, const Adjacency& a, int32_t v, const Vec3& p) {
  SurfacePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  auto consider_vertex = [&](int32_t u) {
    for (int32_t s = a.tri_start[u]; s < a.tri_start[u + 1]; ++s) {
      SurfacePoint sp = on_triangle(cloth, a.tris[s], p);
      if (sp.distance < best.distance) best = sp;
    }
  };
  consider_vertex(v);
  for (int32_t s = a.nb_start[v]; s < a.nb_start[v + 1]; ++s) consider_vertex(a.nbs[s]);
  return best;
}

int32_t nearest_vertex_brute(const Cloth& cloth, const Vec3& p) {
  int32_t best = -1;
  double bd = std::numeric_limits<double>::infinity();
  const auto& x = cloth.state.x;
  for (int32_t i = 0; i < cloth.num_vertices(); ++i) {
    const double d = (x[i] - p).squaredNorm();
    if (d < bd) bd = d, best = i;
  }
  return best;
}

// Hill-climb over mesh neighbours from `start` toward p: keeps a stroke on the layer it began on.
int32_t nearest_vertex_walk(const Cloth& cloth, const Adjacency& a, int32_t start, const Vec3& p) {
  const auto& x = cloth.state.x;
  int32_t cur = start;
  double cd = (x[cur] - p).squaredNorm();
  for (int guard = 0; guard < cloth.num_vertices(); ++guard) {
    int32_t next = cur;
    for (int32_t s = a.nb_start[cur]; s < a.nb_start[cur + 1]; ++s) {
      const double d = (x[a.nbs[s]] - p).squaredNorm();
      if (d < cd) cd = d, next = a.nbs[s];
    }
    if (next == cur) break;
    cur = next;
  }
  return cur;
}

double dist_point_line(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double l2 = d.squaredNorm();
  if (l2 <= 0) return (p - a).norm();
  const double t = std::clamp((p - a).dot(d) / l2, 0.0, 1.0);
  return (a + t * d - p).norm();
}

// Shortest edge path from s to t (material edge lengths); empty if unreachable.
std::vector<int32_t> dijkstra(const Cloth& cloth, const Adjacency& a, int32_t s, int32_t t) {
  const int n = cloth.num_vertices();
  const auto& m = cloth.topo.material;
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::vector<int32_t> prev(n, -1);
  using Item = std::pair<double, int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> q;
  dist[s] = 0;
  q.push({0, s});
  while (!q.empty()) {
    auto [d, u] = q.top();
    q.pop();
    if (d > dist[u]) continue;
    if (u == t) break;
    for (int32_t k = a.nb_start[u]; k < a.nb_start[u + 1]; ++k) {
      const int32_t w = a.nbs[k];
      const double nd = d + (m[w] - m[u]).norm();
      if (nd < dist[w]) dist[w] = nd, prev[w] = u, q.push({nd, w});
    }
  }
  if (!std::isfinite(dist[t])) return {};
  std::vector<int32_t> path;
  for (int32_t u = t; u != -1; u = prev[u]) path.push_back(u);
  std::reverse(path.begin(), path.end());
  return path;
}

// One leg: greedy walk from s toward t along edges, each step strictly closer to t, preferring
// edges that stay near the straight line s–t (method §3.5 step 2); Dijkstra if stuck.
std::vector<int32_t> leg(const Cloth& cloth, const Adjacency& a, int32_t s, int32_t t) {
  const auto& m = cloth.topo.material;
  std::vector<int32_t> path{s};
  int32_t cur = s;
  const Vec2 ms = m[s], mt = m[t];
  for (int guard = 0; cur != t && guard < cloth.num_vertices(); ++guard) {
    const double dcur = (m[cur] - mt).norm();
    int32_t best = -1;
    double bscore = std::numeric_limits<double>::infinity();
    for (int32_t k = a.nb_start[cur]; k < a.nb_start[cur + 1]; ++k) {
      const int32_t w = a.nbs[k];
      if (w == t) {
        best = t;
        break;
      }
      const double dw = (m[w] - mt).norm();
      if (dw >= dcur - 1e-12) continue;
      const double score = dw + dist_point_line(m[w], ms, mt);
      if (score < bscore) bscore = score, best = w;
    }
    if (best < 0) {
      auto rest = dijkstra(cloth, a, cur, t);
      if (rest.empty()) return {};
      path.insert(path.end(), rest.begin() + 1, rest.end());
      return path;
    }
    path.push_back(best);
    cur = best;
  }
  if (cur != t) return {};
  return path;
}

std::vector<int32_t> edge_path_impl(const Cloth& cloth, const Adjacency& a,
                                    const std::vector<int32_t>& anchors) {
  std::vector<int32_t> path;
  for (size_t i = 0; i < anchors.size(); ++i) {
    if (anchors[i] < 0 || anchors[i] >= cloth.num_vertices()) return {};
    if (path.empty()) {
      path.push_back(anchors[i]);
      continue;
    }
    if (anchors[i] == path.back()) continue;
    auto l = leg(cloth, a, path.back(), anchors[i]);
    if (l.empty()) return {};
    path.insert(path.end(), l.begin() + 1, l.end());
  }
  // Remove loops: a vertex met again cuts the path back to its first visit.
  std::vector<int32_t> out;
  std::vector<int32_t> pos(cloth.num_vertices(), -1);
  for (int32_t v : path) {
    if (pos[v] >= 0) {
      for (size_t k = pos[v] + 1; k < out.size(); ++k) pos[out[k]] = -1;
      out.resize(pos[v] + 1);
      continue;
    }
    pos[v] = static_cast<int32_t>(out.size());
    out.push_back(v);
  }
  return out;
}

int find(std::vector<int32_t>& p, int32_t i) {
  while (p[i] != i) i = p[i] = p[p[i]];
  return i;
}

CutResult cut_path_impl(Cloth& cloth, const Adjacency& a, const std::vector<int32_t>& path) {
  CutResult r;
  r.path = path;
  if (path.size() < 2) {
    r.reason = "cut path has fewer than 2 vertices";
    return r;
  }
  auto& T = cloth.topo.triangles;
  // Decide every split on the unmodified topology, then apply them all.
  struct Split {
    int32_t v;
    std::vector<int32_t> left;
  };
  std::vector<Split> splits;
  std::vector<int32_t> parent;
  for (size_t j = 0; j < path.size(); ++j) {
    const int32_t v = path[j];
    const int32_t prev = j > 0 ? path[j - 1] : -1;
    const int32_t next = j + 1 < path.size() ? path[j + 1] : -1;
    const int32_t b = a.tri_start[v], e = a.tri_start[v + 1];
    const int nf = e - b;
    if (nf == 0) continue;
    parent.resize(nf);
    std::iota(parent.begin(), parent.end(), 0);
    // Join fan triangles across shared edges (v, w) that are not cut edges.
    for (int f = 0; f < nf; ++f)
      for (int g = f + 1; g < nf; ++g) {
        const auto& tf = T[a.tris[b + f]];
        const auto& tg = T[a.tris[b + g]];
        for (int k = 0; k < 3; ++k) {
          const int32_t w = tf[k];
          if (w == v || w == prev || w == next) continue;
          if (tg[0] == w || tg[1] == w || tg[2] == w) parent[find(parent, f)] = find(parent, g);
        }
      }
    int left = -1;
    for (int f = 0; f < nf && left < 0; ++f) {
      const auto& t = T[a.tris[b + f]];
      for (int k = 0; k < 3; ++k) {
        if (t[k] != v) continue;
        // Left of v→next: CCW triangle (v, next, c). Left of prev→v: (prev, v, c).
        if (next >= 0 && t[(k + 1) % 3] == next) left = f;
        if (next < 0 && prev >= 0 && t[(k + 2) % 3] == prev) left = f;
      }
    }
    if (left < 0) continue;  // the cut edge is already a boundary on the left
    const int lroot = find(parent, left);
    Split s{v, {}};
    bool other = false;
    for (int f = 0; f < nf; ++f) {
      if (find(parent, f) == lroot)
        s.left.push_back(a.tris[b + f]);
      else
        other = true;
    }
    if (!other) continue;  // one side only: a slit tip, not duplicated
    splits.push_back(std::move(s));
  }
  if (splits.empty()) {
    r.reason = "the path separates nothing (along a boundary or ends only)";
    return r;
  }
  for (const Split& s : splits) {
    const int32_t nv = cloth.duplicate_vertex(s.v);
    r.new_vertices.push_back(nv);
    for (int32_t ti : s.left)
      for (int k = 0; k < 3; ++k)
        if (T[ti][k] == s.v) T[ti][k] = nv;
  }
  cloth.relump_masses();
  cloth.topology_changed();
  r.ok = true;
  return r;
}

// Anchors in different pieces (a stroke crossing an earlier full cut) cannot be joined by one
// edge path: cut each run of anchors that lie in one piece separately, merging the results.
CutResult cut_runs(Cloth& cloth, const std::vector<int32_t>& anchors, const Adjacency* pre) {
  CutResult total;
  int pieces = 0;
  std::vector<int32_t> labels = component_labels(cloth, &pieces);
  std::vector<std::vector<int32_t>> runs;
  // The vertex of piece `label` nearest to material point q.
  auto nearest_in = [&](int32_t label, const Vec2& q) {
    int32_t best = -1;
    double bd = std::numeric_limits<double>::infinity();
    for (int32_t i = 0; i < cloth.num_vertices(); ++i) {
      if (labels[i] != label) continue;
      const double d = (cloth.topo.material[i] - q).squaredNorm();
      if (d < bd) bd = d, best = i;
    }
    return best;
  };
  const auto& m = cloth.topo.material;
  for (int32_t a : anchors) {
    if (!runs.empty() && labels[a] != labels[runs.back().back()]) {
      // Crossing into another piece: both runs are extended to meet at the earlier cut.
      const int32_t last = runs.back().back();
      const int32_t tail = nearest_in(labels[last], m[a]);
      if (tail >= 0 && tail != last) runs.back().push_back(tail);
      const int32_t head = nearest_in(labels[a], m[runs.back().back()]);
      runs.push_back({});
      if (head >= 0 && head != a) runs.back().push_back(head);
    }
    if (runs.empty()) runs.push_back({});
    if (runs.back().empty() || runs.back().back() != a) runs.back().push_back(a);
  }
  total.components_before = pieces;
  std::string why;
  for (const auto& run : runs) {
    if (run.size() < 2) continue;
    Adjacency fresh;
    if (!pre || total.ok) fresh = build_adjacency(cloth);  // rebuilt after a run has cut
    const Adjacency& a = (!pre || total.ok) ? fresh : *pre;
    auto path = edge_path_impl(cloth, a, run);
    if (path.size() < 2) {
      why = "cut: no edge path joins the stroke's particles";
      continue;
    }
    CutResult r = cut_path_impl(cloth, a, path);
    if (!r.ok) {
      why = r.reason;
      continue;
    }
    total.ok = true;
    total.path.insert(total.path.end(), r.path.begin(), r.path.end());
    total.new_vertices.insert(total.new_vertices.end(), r.new_vertices.begin(),
                              r.new_vertices.end());
  }
  total.components_after = count_components(cloth);
  if (!total.ok) total.reason = why.empty() ? "cut: stroke covers a single particle" : why;
  return total;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

SurfacePoint nearest_surface_point(const Cloth& cloth, const Vec3& p) {
  SurfacePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  for (int32_t ti = 0; ti < cloth.topo.num_triangles(); ++ti) {
    SurfacePoint sp = on_triangle(cloth, ti, p);
    if (sp.distance < best.distance) best = sp;
  }
  return best;
}

std::vector<int32_t> edge_path(const Cloth& cloth, const std::vector<int32_t>& anchors) {
  return edge_path_impl(cloth, build_adjacency(cloth), anchors);
}

CutResult cut_path(Cloth& cloth, const std::vector<int32_t>& path) {
  const auto t0 = std::chrono::steady_clock::now();
  for (size_t j = 0; j + 1 < path.size(); ++j) {
    if (path[j] < 0 || path[j] >= cloth.num_vertices() || path[j + 1] < 0 ||
        path[j + 1] >= cloth.num_vertices()) {
      CutResult r;
      r.reason = "cut path: vertex index out of range";
      return r;
    }
  }
  const Adjacency a = build_adjacency(cloth);
  for (size_t j = 0; j + 1 < path.size(); ++j) {
    const int32_t u = path[j], w = path[j + 1];
    if (std::find(a.nbs.begin() + a.nb_start[u], a.nbs.begin() + a.nb_start[u + 1], w) ==
        a.nbs.begin() + a.nb_start[u + 1]) {
      CutResult r;
      r.reason = "cut path: vertices " + std::to_string(u) + " and " + std::to_string(w) +
                 " share no edge";
      return r;
    }
  }
  const int before = count_components(cloth);
  CutResult r = cut_path_impl(cloth, a, path);
  r.components_before = before;
  r.components_after = r.ok ? count_components(cloth) : before;
  r.ms = ms_since(t0);
  return r;
}

CutResult cut_along(Cloth& cloth, const std::vector<Vec3>& stroke_points,
                    const CutOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  CutResult r;
  if (cloth.num_vertices() == 0 || cloth.topo.num_triangles() == 0) {
    r.reason = "cut: the cloth is empty";
    return r;
  }
  // Clean the stroke: finite samples, merged when closer than the minimum spacing.
  std::vector<Vec3> s;
  for (const Vec3& p : stroke_points) {
    if (!p.allFinite()) continue;
    if (!s.empty() && (p - s.back()).norm() < options.min_sample_spacing) continue;
    s.push_back(p);
  }
  if (s.size() < 2) {
    r.reason = "cut: stroke has fewer than 2 usable samples";
    return r;
  }
  // Laplacian smoothing, end points kept (the study's trajectory was shaken by tracking noise).
  for (int pass = 0; pass < options.smoothing_passes; ++pass) {
    std::vector<Vec3> t = s;
    for (size_t i = 1; i + 1 < s.size(); ++i) t[i] = 0.25 * s[i - 1] + 0.5 * s[i] + 0.25 * s[i + 1];
    s.swap(t);
  }
  const Adjacency a = build_adjacency(cloth);
  std::vector<int32_t> anchors;
  int32_t walk = -1;
  for (const Vec3& p : s) {
    int32_t v = walk < 0 ? -1 : nearest_vertex_walk(cloth, a, walk, p);
    SurfacePoint sp;
    if (v >= 0) sp = surface_near_vertex(cloth, a, v, p);
    if (v < 0 || sp.distance > options.max_distance) {
      // First sample, or the walk lost the surface: global search.
      v = nearest_vertex_brute(cloth, p);
      sp = surface_near_vertex(cloth, a, v, p);
    }
    if (sp.triangle < 0 || sp.distance > options.max_distance) continue;  // off the cloth
    walk = v;
    const auto& t = cloth.topo.triangles[sp.triangle];
    int k = 0;
    sp.bary.maxCoeff(&k);
    anchors.push_back(t[k]);
    r.smooth_stroke.push_back(sp.position);
    r.smooth_stroke_uv.push_back(sp.material);
  }
  if (r.smooth_stroke.size() < 2) {
    r.reason = "cut: stroke is off the cloth (fewer than 2 samples within " +
               std::to_string(options.max_distance) + " m of the surface)";
    return r;
  }
  anchors.erase(std::unique(anchors.begin(), anchors.end()), anchors.end());
  if (anchors.size() < 2) {
    r.reason = "cut: stroke covers a single particle";
    return r;
  }
  auto stroke3 = std::move(r.smooth_stroke);
  auto stroke_uv = std::move(r.smooth_stroke_uv);
  r = cut_runs(cloth, anchors, &a);
  r.smooth_stroke = std::move(stroke3);
  r.smooth_stroke_uv = std::move(stroke_uv);
  r.ms = ms_since(t0);
  return r;
}

CutResult cut_along_material(Cloth& cloth, const std::vector<Vec2>& stroke_uv) {
  const auto t0 = std::chrono::steady_clock::now();
  CutResult r;
  std::vector<int32_t> anchors;
  const auto& m = cloth.topo.material;
  // Densify to half the grid spacing so a stroke crossing an earlier cut has anchors on both
  // sides of it.
  std::vector<Vec2> dense;
  const double step = 0.5 * std::max(cloth.topo.spacing, 1e-4);
  for (size_t i = 0; i < stroke_uv.size(); ++i) {
    if (!stroke_uv[i].allFinite()) continue;
    if (!dense.empty()) {
      const Vec2 a = dense.back(), b = stroke_uv[i];
      const int k = std::min(100000, static_cast<int>((b - a).norm() / step));
      for (int j = 1; j < k; ++j) dense.push_back(a + (b - a) * (double(j) / k));
    }
    dense.push_back(stroke_uv[i]);
  }
  std::vector<char> used(cloth.num_vertices(), 0);
  for (const auto& t : cloth.topo.triangles)
    for (int k = 0; k < 3; ++k) used[t[k]] = 1;
  const std::vector<int32_t> labels = component_labels(cloth);
  for (const Vec2& q : dense) {
    int32_t best = -1;
    double bd = std::numeric_limits<double>::infinity();
    const int32_t prev_label = anchors.empty() ? -2 : labels[anchors.back()];
    for (int32_t i = 0; i < cloth.num_vertices(); ++i) {
      if (!used[i]) continue;
      const double d = (m[i] - q).squaredNorm();
      // Among duplicates (same material point, after earlier cuts) stay in the current piece.
      if (d < bd - 1e-18 ||
          (d <= bd + 1e-18 && labels[i] == prev_label && labels[best] != prev_label))
        bd = d, best = i;
    }
    if (best >= 0) anchors.push_back(best);
    r.smooth_stroke_uv.push_back(q);
  }
  anchors.erase(std::unique(anchors.begin(), anchors.end()), anchors.end());
  if (anchors.size() < 2) {
    r.reason = "cut: material stroke has fewer than 2 distinct particles";
    return r;
  }
  auto uv = std::move(r.smooth_stroke_uv);
  r = cut_runs(cloth, anchors, nullptr);
  r.smooth_stroke_uv = std::move(uv);
  for (int32_t v : r.path) r.smooth_stroke.push_back(cloth.state.x[v]);
  r.ms = ms_since(t0);
  return r;
}

std::vector<int32_t> component_labels(const Cloth& cloth, int* count) {
  const int n = cloth.num_vertices();
  std::vector<int32_t> p(n);
  std::iota(p.begin(), p.end(), 0);
  std::vector<char> used(n, 0);
  for (const auto& t : cloth.topo.triangles) {
    for (int k = 0; k < 3; ++k) used[t[k]] = 1;
    p[find(p, t[0])] = find(p, t[1]);
    p[find(p, t[1])] = find(p, t[2]);
  }
  std::vector<int32_t> label(n, -1), root_label(n, -1);
  int c = 0;
  for (int i = 0; i < n; ++i) {
    if (!used[i]) continue;
    const int r = find(p, i);
    if (root_label[r] < 0) root_label[r] = c++;
    label[i] = root_label[r];
  }
  if (count) *count = c;
  return label;
}

int count_components(const Cloth& cloth, bool count_isolated) {
  int c = 0;
  auto labels = component_labels(cloth, &c);
  if (count_isolated)
    for (int32_t l : labels)
      if (l < 0) ++c;
  return c;
}

}  // namespace drape::sim
