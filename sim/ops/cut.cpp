// The cut primitive: stroke → surface points → edge path → split by vertex duplication,
// on any triangulation. Works on the incidence kept with the cloth
// (Cloth::incidence), updated in place by each split, so a cut costs O(stroke + path + the
// pieces it separates) instead of O(cloth): no adjacency rebuild, no global component count,
// masses re-lumped only at the split vertices, scratch buffers reused (no per-vertex
// allocation in the hot path).
#include "sim/ops/cut.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <queue>

#include "sim/core/stopwatch.hpp"

namespace drape::sim {
namespace {

// ---------------------------------------------------------------- kept incidence ----------

bool incidence_valid(const Cloth& c) {
  const ClothIncidence& I = c.incidence;
  return I.built && I.version == c.topology_version &&
         I.start.size() == static_cast<size_t>(c.num_vertices()) &&
         I.count.size() == I.start.size() && I.component.size() == I.start.size() &&
         I.num_triangles == c.topo.num_triangles();
}

// Per-thread scratch: stamped marks (no clearing between uses), queues, split lists.
struct Scratch {
  std::vector<uint32_t> stamp;
  std::vector<int32_t> value;
  uint32_t cur = 0;
  std::vector<int32_t> queue, gparent, gactive, finished, newlabel;
  std::vector<int32_t> split_v, split_begin, split_tris, fan_parent, seeds, cand;
  // A fresh stamp over n vertices: stamp[i] == cur marks "visited in this pass".
  uint32_t next(size_t n) {
    if (stamp.size() < n) stamp.resize(n, 0), value.resize(n, 0);
    if (++cur == 0) {
      std::fill(stamp.begin(), stamp.end(), 0u);
      cur = 1;
    }
    return cur;
  }
};

Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

void build_incidence_into(const Cloth& c, ClothIncidence& I) {
  const int n = c.num_vertices();
  const auto& T = c.topo.triangles;
  I.start.assign(n, 0);
  I.count.assign(n, 0);
  for (const auto& t : T)
    for (int k = 0; k < 3; ++k) ++I.count[t[k]];
  int32_t s = 0;
  for (int i = 0; i < n; ++i) I.start[i] = s, s += I.count[i], I.count[i] = 0;
  I.tris.resize(s);
  for (int32_t ti = 0; ti < static_cast<int32_t>(T.size()); ++ti)
    for (int k = 0; k < 3; ++k) {
      const int32_t v = T[ti][k];
      I.tris[I.start[v] + I.count[v]++] = ti;  // ascending triangle order per vertex
    }
  // Component labels by breadth-first search over shared triangles.
  I.component.assign(n, -1);
  I.components = 0;
  std::vector<int32_t> queue;
  queue.reserve(n);
  for (int32_t r = 0; r < n; ++r) {
    if (I.component[r] >= 0 || I.count[r] == 0) continue;
    const int32_t label = I.components++;
    queue.clear();
    queue.push_back(r);
    I.component[r] = label;
    for (size_t h = 0; h < queue.size(); ++h) {
      const int32_t u = queue[h];
      for (int32_t q = I.start[u], e = q + I.count[u]; q < e; ++q)
        for (int32_t w : T[I.tris[q]])
          if (I.component[w] < 0) I.component[w] = label, queue.push_back(w);
    }
  }
  I.num_triangles = static_cast<int32_t>(T.size());
  I.version = c.topology_version;
  I.built = true;
}

// Calls f(w) for every vertex sharing a triangle with v (each usually twice).
template <class F>
void for_each_neighbour(const Cloth& c, const ClothIncidence& I, int32_t v, F&& f) {
  const auto& T = c.topo.triangles;
  for (int32_t q = I.start[v], e = q + I.count[v]; q < e; ++q) {
    const auto& t = T[I.tris[q]];
    for (int k = 0; k < 3; ++k)
      if (t[k] != v) f(t[k]);
  }
}

bool shares_edge(const Cloth& c, const ClothIncidence& I, int32_t u, int32_t w) {
  bool found = false;
  for_each_neighbour(c, I, u, [&](int32_t x) { found = found || x == w; });
  return found;
}

// The triangle other than `t` on edge (a, b); -1 on a boundary edge.
int32_t across(const Cloth& c, const ClothIncidence& I, int32_t t, int32_t a, int32_t b) {
  const auto& T = c.topo.triangles;
  for (int32_t q = I.start[a], e = q + I.count[a]; q < e; ++q) {
    const int32_t o = I.tris[q];
    if (o == t) continue;
    const auto& to = T[o];
    if (to[0] == b || to[1] == b || to[2] == b) return o;
  }
  return -1;
}

// True when v lies on a boundary edge (an edge with a single triangle).
bool boundary_vertex(const Cloth& c, const ClothIncidence& I, int32_t v) {
  const auto& T = c.topo.triangles;
  for (int32_t q = I.start[v], e = q + I.count[v]; q < e; ++q) {
    const auto& t = T[I.tris[q]];
    for (int k = 0; k < 3; ++k)
      if (t[k] != v && across(c, I, I.tris[q], v, t[k]) < 0) return true;
  }
  return false;
}

// A cut that has reached the cloth's edge ends there: anchors that go on along the edge after
// it (the edge anchor of an end extension next to a hit that already lies on the boundary, where
// the side line nearly meets the panel's edge) are dropped from both ends. A leg along boundary
// edges separates nothing and leaves the cut's end a slit tip.
void trim_boundary_runs(const Cloth& c, const ClothIncidence& I, std::vector<int32_t>& anchors) {
  const auto on_edge = [&](int32_t v) { return boundary_vertex(c, I, v); };
  while (anchors.size() > 2 && on_edge(anchors.back()) && on_edge(anchors[anchors.size() - 2]))
    anchors.pop_back();
  while (anchors.size() > 2 && on_edge(anchors[0]) && on_edge(anchors[1]))
    anchors.erase(anchors.begin());
}

// ---------------------------------------------------------------- surface queries --------

// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection, 5.1.5);
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

// Best surface point among the triangles around vertex v and its neighbours (each once).
SurfacePoint surface_near_vertex(const Cloth& cloth, const ClothIncidence& I, int32_t v,
                                 const Vec3& p) {
  SurfacePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  std::vector<int32_t>& cand = scratch().cand;
  cand.clear();
  auto add_fan = [&](int32_t u) {
    for (int32_t q = I.start[u], e = q + I.count[u]; q < e; ++q) cand.push_back(I.tris[q]);
  };
  add_fan(v);
  for_each_neighbour(cloth, I, v, add_fan);
  std::sort(cand.begin(), cand.end());
  cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
  for (int32_t ti : cand) {
    SurfacePoint sp = on_triangle(cloth, ti, p);
    if (sp.distance < best.distance) best = sp;
  }
  return best;
}

int32_t nearest_vertex_brute(const Cloth& cloth, const ClothIncidence& I, const Vec3& p) {
  int32_t best = -1;
  double bd = std::numeric_limits<double>::infinity();
  const auto& x = cloth.state.x;
  for (int32_t i = 0; i < cloth.num_vertices(); ++i) {
    if (I.count[i] == 0) continue;
    const double d = (x[i] - p).squaredNorm();
    if (d < bd) bd = d, best = i;
  }
  return best;
}

// Hill-climb over mesh neighbours from `start` toward p: keeps a stroke on the layer it began on.
int32_t nearest_vertex_walk(const Cloth& cloth, const ClothIncidence& I, int32_t start,
                            const Vec3& p) {
  const auto& x = cloth.state.x;
  int32_t cur = start;
  double cd = (x[cur] - p).squaredNorm();
  for (int guard = 0; guard < cloth.num_vertices(); ++guard) {
    int32_t next = cur;
    for_each_neighbour(cloth, I, cur, [&](int32_t w) {
      const double d = (x[w] - p).squaredNorm();
      if (d < cd) cd = d, next = w;
    });
    if (next == cur) break;
    cur = next;
  }
  return cur;
}

// True when the surface point lies on the cloth's boundary (on a boundary edge or vertex).
bool on_boundary(const Cloth& c, const ClothIncidence& I, const SurfacePoint& sp) {
  if (sp.triangle < 0) return false;
  const auto& t = c.topo.triangles[sp.triangle];
  constexpr double eps = 1e-9;
  for (int k = 0; k < 3; ++k) {
    if (sp.bary[k] >= 1 - eps && boundary_vertex(c, I, t[k])) return true;
    if (sp.bary[k] <= eps && across(c, I, sp.triangle, t[(k + 1) % 3], t[(k + 2) % 3]) < 0)
      return true;
  }
  return false;
}

// Where a straight line from material point p (inside triangle t) along d leaves the cloth:
// walks across triangles in material space to the first boundary edge.
struct EdgeExit {
  int32_t vertex = -1;  // the nearer end of the boundary edge reached (-1: none)
  double distance = 0;  // from p (m, material)
  Vec2 material{0, 0};
  Vec3 position{0, 0, 0};
};

EdgeExit walk_to_edge(const Cloth& c, const ClothIncidence& I, int32_t t, Vec2 p, Vec2 d) {
  EdgeExit out;
  const double dn = d.norm();
  if (!(dn > 0) || t < 0) return out;
  d /= dn;
  const auto& T = c.topo.triangles;
  const auto& m = c.topo.material;
  double travelled = 0;
  for (int guard = 0; guard < 4 * c.topo.num_triangles() + 16; ++guard) {
    const auto& tri = T[t];
    const Vec2 e1 = m[tri[1]] - m[tri[0]], e2 = m[tri[2]] - m[tri[0]];
    const double sg = e1.x() * e2.y() - e1.y() * e2.x() >= 0 ? 1.0 : -1.0;
    double best = std::numeric_limits<double>::infinity();
    int be = -1;
    for (int k = 0; k < 3; ++k) {
      const Vec2 P = m[tri[k]], e = m[tri[(k + 1) % 3]] - P;
      const Vec2 outward(sg * e.y(), -sg * e.x());
      const double nd = outward.dot(d);
      if (!(nd > 0)) continue;
      const double s = std::max(0.0, outward.dot(P - p) / nd);
      if (s < best) best = s, be = k;
    }
    if (be < 0) return out;  // degenerate triangle
    p += best * d;
    travelled += best;
    const int32_t a = tri[be], b = tri[(be + 1) % 3];
    const int32_t o = across(c, I, t, a, b);
    if (o >= 0) {
      t = o;
      continue;
    }
    const Vec2 ab = m[b] - m[a];
    const double l2 = ab.squaredNorm();
    const double lam = l2 > 0 ? std::clamp((p - m[a]).dot(ab) / l2, 0.0, 1.0) : 0.0;
    out.vertex = lam < 0.5 ? a : b;
    out.distance = travelled;
    out.material = m[a] + lam * ab;
    out.position = (1 - lam) * c.state.x[a] + lam * c.state.x[b];
    return out;
  }
  return out;
}

// ---------------------------------------------------------------- edge paths -------------

double dist_point_line(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double l2 = d.squaredNorm();
  if (l2 <= 0) return (p - a).norm();
  const double t = std::clamp((p - a).dot(d) / l2, 0.0, 1.0);
  return (a + t * d - p).norm();
}

// Shortest edge path from s to t (material edge lengths); empty if unreachable. Only when the
// greedy walk is blocked (a boundary in the way), so O(V) storage is acceptable here.
std::vector<int32_t> dijkstra(const Cloth& cloth, const ClothIncidence& I, int32_t s, int32_t t) {
  const int n = cloth.num_vertices();
  const auto& m = cloth.topo.material;
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::vector<int32_t> prev(n, -1);
  using Item = std::pair<double, int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> q;
  dist[s] = 0;
  q.push({0, s});
  while (!q.empty()) {
    // Plain variables, not a structured binding: clang 14 (the fuzz build) cannot capture
    // structured bindings in the lambda below.
    const double d = q.top().first;
    const int32_t u = q.top().second;
    q.pop();
    if (d > dist[u]) continue;
    if (u == t) break;
    for_each_neighbour(cloth, I, u, [&](int32_t w) {
      const double nd = d + (m[w] - m[u]).norm();
      if (nd < dist[w]) dist[w] = nd, prev[w] = u, q.push({nd, w});
    });
  }
  if (!std::isfinite(dist[t])) return {};
  std::vector<int32_t> path;
  for (int32_t u = t; u != -1; u = prev[u]) path.push_back(u);
  std::reverse(path.begin(), path.end());
  return path;
}

// One leg, appended to `path` (which ends at s): greedy walk from s toward t along edges, each
// step strictly closer to t, preferring edges that stay near the straight line s–t; Dijkstra
// if stuck. False when t is unreachable.
bool leg(const Cloth& cloth, const ClothIncidence& I, int32_t s, int32_t t,
         std::vector<int32_t>& path) {
  const auto& m = cloth.topo.material;
  const auto& T = cloth.topo.triangles;
  int32_t cur = s;
  const Vec2 ms = m[s], mt = m[t];
  for (int guard = 0; cur != t && guard < cloth.num_vertices(); ++guard) {
    const double dcur = (m[cur] - mt).norm();
    int32_t best = -1;
    double bscore = std::numeric_limits<double>::infinity();
    for (int32_t q = I.start[cur], e = q + I.count[cur]; q < e && best != t; ++q) {
      for (int32_t w : T[I.tris[q]]) {
        if (w == cur) continue;
        if (w == t) {
          best = t;
          break;
        }
        const double dw = (m[w] - mt).norm();
        if (dw >= dcur - 1e-12) continue;
        const double score = dw + dist_point_line(m[w], ms, mt);
        if (score < bscore) bscore = score, best = w;
      }
    }
    if (best < 0) {
      auto rest = dijkstra(cloth, I, cur, t);
      if (rest.empty()) return false;
      path.insert(path.end(), rest.begin() + 1, rest.end());
      return true;
    }
    path.push_back(best);
    cur = best;
  }
  return cur == t;
}

std::vector<int32_t> edge_path_impl(const Cloth& cloth, const ClothIncidence& I,
                                    const std::vector<int32_t>& anchors) {
  std::vector<int32_t> path;
  for (size_t i = 0; i < anchors.size(); ++i) {
    if (anchors[i] < 0 || anchors[i] >= cloth.num_vertices()) return {};
    if (path.empty()) {
      path.push_back(anchors[i]);
      continue;
    }
    if (anchors[i] == path.back()) continue;
    if (!leg(cloth, I, path.back(), anchors[i], path)) return {};
  }
  // Remove loops: a vertex met again cuts the path back to its first visit (stamped positions
  // in the scratch instead of an O(V) array per call).
  Scratch& sc = scratch();
  const uint32_t st = sc.next(cloth.num_vertices());
  std::vector<int32_t> out;
  out.reserve(path.size());
  for (int32_t v : path) {
    if (sc.stamp[v] == st) {
      const size_t keep = static_cast<size_t>(sc.value[v]) + 1;
      for (size_t k = keep; k < out.size(); ++k) sc.stamp[out[k]] = 0;
      out.resize(keep);
      continue;
    }
    sc.stamp[v] = st;
    sc.value[v] = static_cast<int32_t>(out.size());
    out.push_back(v);
  }
  return out;
}

// ---------------------------------------------------------------- split ------------------

// Lumped mass of v from its incident triangles, summed in ascending triangle order exactly as
// Cloth::relump_masses() does (so the result is bit-identical to a full re-lump).
void relump_vertex(Cloth& c, int32_t v) {
  const ClothIncidence& I = c.incidence;
  const auto& T = c.topo.triangles;
  const auto& m = c.topo.material;
  double mass = 0.0;
  for (int32_t q = I.start[v], e = q + I.count[v]; q < e; ++q) {
    const auto& t = T[I.tris[q]];
    const Vec2 e1 = m[t[1]] - m[t[0]];
    const Vec2 e2 = m[t[2]] - m[t[0]];
    const double area = 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    mass += area * c.fabric.areal_density / 3.0;
  }
  c.state.mass[v] = mass;
  c.state.inv_mass[v] = (c.is_free(v) && mass > 0) ? 1.0 / mass : 0.0;
}

// After a split: a breadth-first search from both sides of the cut at once (one group per
// seed, groups merging where they meet). A group whose front empties is a whole component;
// the search stops as soon as at most one group is still growing, so it visits about twice the
// smaller side (a slit stops at once: both sides meet at its tip). Finished groups get new
// labels. Returns the number of components added.
int split_components(Cloth& c, const std::vector<int32_t>& seeds) {
  ClothIncidence& I = c.incidence;
  Scratch& sc = scratch();
  const int n = c.num_vertices();
  const uint32_t st = sc.next(n);
  if (sc.queue.size() < static_cast<size_t>(n)) sc.queue.resize(n);
  sc.gparent.clear(), sc.gactive.clear(), sc.finished.clear();
  // Raw views: the loop below is the hot part of a separating cut.
  uint32_t* S = sc.stamp.data();
  int32_t* val = sc.value.data();
  int32_t* Q = sc.queue.data();
  size_t tail = 0;
  for (int32_t x : seeds) {
    if (I.count[x] == 0 || S[x] == st) continue;
    const int32_t g = static_cast<int32_t>(sc.gparent.size());
    sc.gparent.push_back(g), sc.gactive.push_back(1);
    S[x] = st, val[x] = g, Q[tail++] = x;
  }
  int32_t* gp = sc.gparent.data();
  int32_t* ga = sc.gactive.data();
  auto find = [gp](int32_t g) {
    while (gp[g] != g) g = gp[g] = gp[gp[g]];
    return g;
  };
  int open = static_cast<int>(sc.gparent.size());
  const int32_t* fs = I.start.data();
  const int32_t* fc = I.count.data();
  const int32_t* ft = I.tris.data();
  const auto* T = c.topo.triangles.data();
  for (size_t head = 0; head < tail && open > 1; ++head) {
    const int32_t u = Q[head];
    const int32_t g = find(val[u]);
    for (int32_t q = fs[u], e = q + fc[u]; q < e; ++q) {
      const auto& t = T[ft[q]];
      for (int k = 0; k < 3; ++k) {
        const int32_t w = t[k];
        if (S[w] != st) {
          S[w] = st, val[w] = g, ++ga[g], Q[tail++] = w;
        } else if (val[w] != g) {
          const int32_t h = find(val[w]);
          if (h != g) gp[h] = g, ga[g] += ga[h], --open;  // the fronts met: one piece
          val[w] = g;
        }
      }
    }
    if (--ga[g] == 0) sc.finished.push_back(g), --open;
  }
  if (open == 0 && !sc.finished.empty()) sc.finished.pop_back();  // keeps the old label
  if (sc.finished.empty()) return 0;
  sc.newlabel.assign(sc.gparent.size(), -1);
  for (int32_t g : sc.finished) sc.newlabel[g] = I.components++;
  for (size_t i = 0; i < tail; ++i) {
    const int32_t l = sc.newlabel[find(val[Q[i]])];
    if (l >= 0) I.component[Q[i]] = l;
  }
  return static_cast<int>(sc.finished.size());
}

// Splits along `path` (unique vertices, consecutive ones sharing an edge) using the cloth's
// kept incidence, which must be valid, and keeps it valid.
CutResult cut_path_impl(Cloth& cloth, const std::vector<int32_t>& path) {
  CutResult r;
  r.path = path;
  ClothIncidence& I = cloth.incidence;
  r.components_before = r.components_after = I.components;
  if (path.size() < 2) {
    r.reason = "cut path has fewer than 2 vertices";
    return r;
  }
  auto& T = cloth.topo.triangles;
  Scratch& sc = scratch();
  // Decide every split on the unmodified topology, then apply them all.
  sc.split_v.clear(), sc.split_begin.clear(), sc.split_tris.clear();
  for (size_t j = 0; j < path.size(); ++j) {
    const int32_t v = path[j];
    const int32_t prev = j > 0 ? path[j - 1] : -1;
    const int32_t next = j + 1 < path.size() ? path[j + 1] : -1;
    const int32_t b = I.start[v], nf = I.count[v];
    if (nf == 0) continue;
    auto& fp = sc.fan_parent;
    fp.resize(nf);
    std::iota(fp.begin(), fp.end(), 0);
    auto find = [&](int32_t i) {
      while (fp[i] != i) i = fp[i] = fp[fp[i]];
      return i;
    };
    // Join fan triangles across shared edges (v, w) that are not cut edges.
    for (int f = 0; f < nf; ++f)
      for (int g = f + 1; g < nf; ++g) {
        const auto& tf = T[I.tris[b + f]];
        const auto& tg = T[I.tris[b + g]];
        for (int k = 0; k < 3; ++k) {
          const int32_t w = tf[k];
          if (w == v || w == prev || w == next) continue;
          if (tg[0] == w || tg[1] == w || tg[2] == w) fp[find(f)] = find(g);
        }
      }
    int left = -1;
    for (int f = 0; f < nf && left < 0; ++f) {
      const auto& t = T[I.tris[b + f]];
      for (int k = 0; k < 3; ++k) {
        if (t[k] != v) continue;
        // Left of v→next: CCW triangle (v, next, c). Left of prev→v: (prev, v, c).
        if (next >= 0 && t[(k + 1) % 3] == next) left = f;
        if (next < 0 && prev >= 0 && t[(k + 2) % 3] == prev) left = f;
      }
    }
    if (left < 0) continue;  // the cut edge is already a boundary on the left
    const int lroot = find(left);
    const size_t begin = sc.split_tris.size();
    bool other = false;
    for (int f = 0; f < nf; ++f) {
      if (find(f) == lroot)
        sc.split_tris.push_back(I.tris[b + f]);  // ascending, as the fan is
      else
        other = true;
    }
    if (!other) {  // one side only: a slit tip, not duplicated
      sc.split_tris.resize(begin);
      continue;
    }
    sc.split_v.push_back(v);
    sc.split_begin.push_back(static_cast<int32_t>(begin));
  }
  if (sc.split_v.empty()) {
    r.reason = "the path separates nothing (along a boundary or ends only)";
    return r;
  }
  sc.split_begin.push_back(static_cast<int32_t>(sc.split_tris.size()));
  sc.seeds.clear();
  for (size_t i = 0; i < sc.split_v.size(); ++i) {
    const int32_t v = sc.split_v[i];
    const int32_t* L = sc.split_tris.data() + sc.split_begin[i];
    const int32_t k = sc.split_begin[i + 1] - sc.split_begin[i];
    const int32_t nv = cloth.duplicate_vertex(v);
    r.new_vertices.push_back(nv);
    for (int32_t q = 0; q < k; ++q)
      for (int c = 0; c < 3; ++c)
        if (T[L[q]][c] == v) T[L[q]][c] = nv;
    // v keeps the triangles not moved (order kept); nv gets the moved ones, appended.
    int32_t w = I.start[v];
    for (int32_t q = I.start[v], e = q + I.count[v]; q < e; ++q)
      if (!std::binary_search(L, L + k, I.tris[q])) I.tris[w++] = I.tris[q];
    I.count[v] = w - I.start[v];
    I.start.push_back(static_cast<int32_t>(I.tris.size()));
    I.count.push_back(k);
    I.component.push_back(I.component[v]);
    I.tris.insert(I.tris.end(), L, L + k);
    sc.seeds.push_back(v);
    sc.seeds.push_back(nv);
  }
  // Only the split vertices' triangle sets changed: re-lump just them (total mass unchanged).
  for (int32_t x : sc.seeds) relump_vertex(cloth, x);
  const int added = split_components(cloth, sc.seeds);
  cloth.topology_changed();
  I.version = cloth.topology_version;
  // The moved lists leave slack behind; compact once it exceeds the live size.
  if (I.tris.size() > 6 * T.size() + 4096) build_incidence_into(cloth, I);
  r.components_after = r.components_before + added;
  r.ok = true;
  return r;
}

// Anchors in different pieces (a stroke crossing an earlier full cut) cannot be joined by one
// edge path: cut each run of anchors that lie in one piece separately, merging the results.
CutResult cut_runs(Cloth& cloth, const std::vector<int32_t>& anchors) {
  const ClothIncidence& I = cloth.incidence;
  const auto& labels = I.component;
  CutResult total;
  total.components_before = I.components;
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
  std::string why;
  for (const auto& run : runs) {
    if (run.size() < 2) continue;
    auto path = edge_path_impl(cloth, I, run);
    if (path.size() < 2) {
      why = "cut: no edge path joins the stroke's particles";
      continue;
    }
    CutResult r = cut_path_impl(cloth, path);
    if (!r.ok) {
      why = r.reason;
      continue;
    }
    total.ok = true;
    total.path.insert(total.path.end(), r.path.begin(), r.path.end());
    total.new_vertices.insert(total.new_vertices.end(), r.new_vertices.begin(),
                              r.new_vertices.end());
  }
  total.components_after = I.components;
  if (!total.ok) total.reason = why.empty() ? "cut: stroke covers a single particle" : why;
  return total;
}

}  // namespace

bool ensure_incidence(Cloth& cloth) {
  if (incidence_valid(cloth)) return false;
  build_incidence_into(cloth, cloth.incidence);
  return true;
}

bool prepare_for_cuts(Cloth& cloth) {
  bool changed = ensure_incidence(cloth);
  const size_t n = static_cast<size_t>(cloth.num_vertices());
  const size_t room = std::max<size_t>(1024, n / 8);
  auto reserve = [&](auto& vec, size_t size, size_t extra) {
    if (vec.capacity() < size + extra / 2) vec.reserve(size + extra), changed = true;
  };
  auto& tp = cloth.topo;
  auto& st = cloth.state;
  auto& I = cloth.incidence;
  reserve(tp.material, n, room), reserve(tp.vertex_zone, n, room);
  reserve(tp.vertex_origin, n, room), reserve(st.x, n, room), reserve(st.x_prev, n, room);
  reserve(st.v, n, room), reserve(st.mass, n, room), reserve(st.inv_mass, n, room);
  reserve(st.flags, n, room), reserve(I.start, n, room), reserve(I.count, n, room);
  reserve(I.component, n, room), reserve(I.tris, I.tris.size(), 8 * room);
  // This thread's scratch, sized for the cloth (the cut runs on the thread that prepares).
  Scratch& sc = scratch();
  sc.next(n + room);
  if (sc.queue.size() < n + room) sc.queue.resize(n + room);
  return changed;
}

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
  if (incidence_valid(cloth)) return edge_path_impl(cloth, cloth.incidence, anchors);
  ClothIncidence local;
  build_incidence_into(cloth, local);
  return edge_path_impl(cloth, local, anchors);
}

CutResult cut_path(Cloth& cloth, const std::vector<int32_t>& path) {
  const auto t0 = std::chrono::steady_clock::now();
  CutResult bad;
  for (int32_t v : path) {
    if (v < 0 || v >= cloth.num_vertices()) {
      bad.reason = "cut path: vertex index out of range";
      return bad;
    }
  }
  ensure_incidence(cloth);
  const ClothIncidence& I = cloth.incidence;
  Scratch& sc = scratch();
  const uint32_t st = sc.next(cloth.num_vertices());
  for (size_t j = 0; j < path.size(); ++j) {
    if (sc.stamp[path[j]] == st) {
      bad.reason = "cut path: vertex " + std::to_string(path[j]) + " repeats";
      return bad;
    }
    sc.stamp[path[j]] = st;
    if (j + 1 < path.size() && !shares_edge(cloth, I, path[j], path[j + 1])) {
      bad.reason = "cut path: vertices " + std::to_string(path[j]) + " and " +
                   std::to_string(path[j + 1]) + " share no edge";
      return bad;
    }
  }
  CutResult r = cut_path_impl(cloth, path);
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
  s.reserve(stroke_points.size());
  for (const Vec3& p : stroke_points) {
    if (!p.allFinite()) continue;
    if (!s.empty() && (p - s.back()).norm() < options.min_sample_spacing) continue;
    s.push_back(p);
  }
  if (s.size() < 2) {
    r.reason = "cut: stroke has fewer than 2 usable samples";
    return r;
  }
  // Laplacian smoothing, end points kept (a tracked stroke shakes with tracking noise).
  std::vector<Vec3> t(s.size());
  for (int pass = 0; pass < options.smoothing_passes; ++pass) {
    t.front() = s.front(), t.back() = s.back();
    for (size_t i = 1; i + 1 < s.size(); ++i) t[i] = 0.25 * s[i - 1] + 0.5 * s[i] + 0.25 * s[i + 1];
    s.swap(t);
  }
  ensure_incidence(cloth);
  const ClothIncidence& I = cloth.incidence;
  // Samples farther than max_distance from the cloth's bounding box need no search.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int32_t i = 0; i < cloth.num_vertices(); ++i)
    if (I.count[i]) lo = lo.cwiseMin(cloth.state.x[i]), hi = hi.cwiseMax(cloth.state.x[i]);
  auto box_distance = [&](const Vec3& p) { return (p - p.cwiseMax(lo).cwiseMin(hi)).norm(); };
  std::vector<int32_t> anchors;
  std::vector<int32_t> hit_tri;  // triangle of each kept sample
  int first_hit = -1, last_hit = -1;
  int32_t walk = -1;
  for (size_t i = 0; i < s.size(); ++i) {
    const Vec3& p = s[i];
    if (box_distance(p) > options.max_distance) continue;  // off the cloth
    int32_t v = walk < 0 ? -1 : nearest_vertex_walk(cloth, I, walk, p);
    SurfacePoint sp;
    if (v >= 0) sp = surface_near_vertex(cloth, I, v, p);
    if (v < 0 || sp.distance > options.max_distance) {
      // First sample, or the walk lost the surface: global search.
      v = nearest_vertex_brute(cloth, I, p);
      if (v < 0) continue;
      sp = surface_near_vertex(cloth, I, v, p);
    }
    if (sp.triangle < 0 || sp.distance > options.max_distance) continue;  // off the cloth
    walk = v;
    const auto& tri = cloth.topo.triangles[sp.triangle];
    int k = 0;
    sp.bary.maxCoeff(&k);
    anchors.push_back(tri[k]);
    hit_tri.push_back(sp.triangle);
    r.smooth_stroke.push_back(sp.position);
    r.smooth_stroke_uv.push_back(sp.material);
    if (first_hit < 0) first_hit = static_cast<int>(i);
    last_hit = static_cast<int>(i);
  }
  if (r.smooth_stroke.size() < 2) {
    r.reason = "cut: stroke is off the cloth (fewer than 2 samples within " +
               std::to_string(options.max_distance) + " m of the surface)";
    return r;
  }
  // Ends on, near or beyond the cloth's edge reach the edge (a stroke drawn across the cloth
  // separates it): continue the stroke's direction on the cloth (material space) to the edge.
  const double snap = std::max(options.edge_snap, cloth.topo.spacing);
  std::array<EdgeExit, 2> exits{};
  for (int end = 0; end < 2; ++end) {
    const auto& uv = r.smooth_stroke_uv;
    const int nh = static_cast<int>(uv.size());
    const int i0 = end == 0 ? 0 : nh - 1, step = end == 0 ? 1 : -1;
    int j = i0 + step;
    while (j + step >= 0 && j + step < nh && (uv[j] - uv[i0]).norm() < 2 * cloth.topo.spacing)
      j += step;
    const EdgeExit ex = walk_to_edge(cloth, I, hit_tri[i0], uv[i0], uv[i0] - uv[j]);
    if (ex.vertex < 0) continue;
    bool extend = ex.distance <= snap;
    // The stroke began (ended) off the cloth, beyond its edge: the first (last) sample's
    // nearest cloth point lies on the boundary.
    const int outer = end == 0 ? 0 : static_cast<int>(s.size()) - 1;
    if (!extend && (end == 0 ? first_hit > 0 : last_hit < outer)) {
      const int32_t v = nearest_vertex_brute(cloth, I, s[outer]);
      if (v >= 0)
        extend = boundary_vertex(cloth, I, v) ||
                 on_boundary(cloth, I, surface_near_vertex(cloth, I, v, s[outer]));
    }
    if (extend) exits[end] = ex, r.extended[end] = true;
  }
  if (r.extended[0]) {
    anchors.insert(anchors.begin(), exits[0].vertex);
    r.smooth_stroke.insert(r.smooth_stroke.begin(), exits[0].position);
    r.smooth_stroke_uv.insert(r.smooth_stroke_uv.begin(), exits[0].material);
  }
  if (r.extended[1]) {
    anchors.push_back(exits[1].vertex);
    r.smooth_stroke.push_back(exits[1].position);
    r.smooth_stroke_uv.push_back(exits[1].material);
  }
  anchors.erase(std::unique(anchors.begin(), anchors.end()), anchors.end());
  trim_boundary_runs(cloth, I, anchors);
  if (anchors.size() < 2) {
    r.reason = "cut: stroke covers a single particle";
    return r;
  }
  auto stroke3 = std::move(r.smooth_stroke);
  auto stroke_uv = std::move(r.smooth_stroke_uv);
  const auto extended = r.extended;
  r = cut_runs(cloth, anchors);
  r.smooth_stroke = std::move(stroke3);
  r.smooth_stroke_uv = std::move(stroke_uv);
  r.extended = extended;
  r.ms = ms_since(t0);
  return r;
}

namespace {

// The vertices that lie in a triangle, bucketed by material position (cells of the grid's
// spacing): the nearest vertex to a material point in O(vertices of a few cells) instead of
// O(vertices).
class MaterialBuckets {
 public:
  MaterialBuckets(const Cloth& cloth, const ClothIncidence& inc) : m_(cloth.topo.material) {
    h_ = std::max(cloth.topo.spacing, 1e-4);
    lo_ = Vec2::Constant(std::numeric_limits<double>::infinity());
    Vec2 hi = -lo_;
    const int n = cloth.num_vertices();
    for (int32_t i = 0; i < n; ++i)
      if (inc.count[i] > 0) lo_ = lo_.cwiseMin(m_[i]), hi = hi.cwiseMax(m_[i]);
    if (!(hi.x() >= lo_.x())) return;  // no vertex in a triangle
    nx_ = std::min(4096, static_cast<int>((hi.x() - lo_.x()) / h_) + 1);
    ny_ = std::min(4096, static_cast<int>((hi.y() - lo_.y()) / h_) + 1);
    start_.assign(static_cast<size_t>(nx_) * ny_ + 1, 0);
    for (int32_t i = 0; i < n; ++i)
      if (inc.count[i] > 0) ++start_[cell(m_[i]) + 1];
    for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    items_.resize(start_.back());
    std::vector<int32_t> fill(start_.begin(), start_.end() - 1);
    for (int32_t i = 0; i < n; ++i)
      if (inc.count[i] > 0) items_[fill[cell(m_[i])]++] = i;
  }
  // The vertex `better` prefers among the nearest (better(i, d, best, d_best): i at squared
  // distance d replaces best), or -1 when there is none. Rings of cells around q's are searched
  // until no cell further out can hold a nearer vertex.
  template <class Better>
  int32_t nearest(const Vec2& q, Better better) const {
    if (nx_ == 0) return -1;
    const int cx = std::clamp(static_cast<int>(std::floor((q.x() - lo_.x()) / h_)), 0, nx_ - 1);
    const int cy = std::clamp(static_cast<int>(std::floor((q.y() - lo_.y()) / h_)), 0, ny_ - 1);
    int32_t best = -1;
    double bd = std::numeric_limits<double>::infinity();
    for (int r = 0; r <= std::max(nx_, ny_); ++r) {
      for (int y = cy - r; y <= cy + r; ++y) {
        if (y < 0 || y >= ny_) continue;
        const bool edge_row = y == cy - r || y == cy + r;
        for (int x = cx - r; x <= cx + r; x += edge_row ? 1 : 2 * std::max(r, 1)) {
          if (x < 0 || x >= nx_) continue;
          const size_t c = static_cast<size_t>(y) * nx_ + x;
          for (int32_t k = start_[c]; k < start_[c + 1]; ++k) {
            const int32_t i = items_[k];
            const double d = (m_[i] - q).squaredNorm();
            if (best < 0 || better(i, d, best, bd)) best = i, bd = d;
          }
        }
      }
      // Every vertex of ring r + 1 lies at least r cells from q.
      const double reach = r * h_;
      if (best >= 0 && bd < reach * reach - 1e-18) break;
    }
    return best;
  }

 private:
  size_t cell(const Vec2& p) const {
    const int x = std::clamp(static_cast<int>((p.x() - lo_.x()) / h_), 0, nx_ - 1);
    const int y = std::clamp(static_cast<int>((p.y() - lo_.y()) / h_), 0, ny_ - 1);
    return static_cast<size_t>(y) * nx_ + x;
  }
  const std::vector<Vec2>& m_;
  double h_ = 0;
  Vec2 lo_;
  int nx_ = 0, ny_ = 0;
  std::vector<int32_t> start_, items_;
};

}  // namespace

CutResult cut_along_material(Cloth& cloth, const std::vector<Vec2>& stroke_uv) {
  const auto t0 = std::chrono::steady_clock::now();
  CutResult r;
  ensure_incidence(cloth);
  const ClothIncidence& I = cloth.incidence;
  std::vector<int32_t> anchors;
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
  const auto& labels = I.component;
  const MaterialBuckets buckets(cloth, I);
  for (const Vec2& q : dense) {
    const int32_t prev_label = anchors.empty() ? -2 : labels[anchors.back()];
    const int32_t best = buckets.nearest(q, [&](int32_t i, double d, int32_t b, double bd) {
      // Among duplicates (same material point, after earlier cuts) stay in the current piece;
      // else the lowest index.
      if (d < bd - 1e-18) return true;
      if (d > bd + 1e-18) return false;
      const bool in = labels[i] == prev_label, best_in = labels[b] == prev_label;
      return in != best_in ? in : i < b;
    });
    if (best >= 0) anchors.push_back(best);
    r.smooth_stroke_uv.push_back(q);
  }
  anchors.erase(std::unique(anchors.begin(), anchors.end()), anchors.end());
  if (anchors.size() < 2) {
    r.reason = "cut: material stroke has fewer than 2 distinct particles";
    return r;
  }
  auto uv = std::move(r.smooth_stroke_uv);
  r = cut_runs(cloth, anchors);
  r.smooth_stroke_uv = std::move(uv);
  for (int32_t v : r.path) r.smooth_stroke.push_back(cloth.state.x[v]);
  r.ms = ms_since(t0);
  return r;
}

CutResult cut_across_material(Cloth& cloth, double at) {
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec2& m : cloth.topo.material) lo = lo.cwiseMin(m), hi = hi.cwiseMax(m);
  const double v = lo.y() + at * (hi.y() - lo.y());
  return cut_along_material(cloth, {Vec2(lo.x() - 0.01, v), Vec2(hi.x() + 0.01, v)});
}

namespace {
int find_root(std::vector<int32_t>& p, int32_t i) {
  while (p[i] != i) i = p[i] = p[p[i]];
  return i;
}
}  // namespace

// Full recomputation (independent of the kept incidence: tests compare the two).
std::vector<int32_t> component_labels(const Cloth& cloth, int* count) {
  const int n = cloth.num_vertices();
  std::vector<int32_t> p(n);
  std::iota(p.begin(), p.end(), 0);
  std::vector<char> used(n, 0);
  for (const auto& t : cloth.topo.triangles) {
    for (int k = 0; k < 3; ++k) used[t[k]] = 1;
    p[find_root(p, t[0])] = find_root(p, t[1]);
    p[find_root(p, t[1])] = find_root(p, t[2]);
  }
  std::vector<int32_t> label(n, -1), root_label(n, -1);
  int c = 0;
  for (int i = 0; i < n; ++i) {
    if (!used[i]) continue;
    const int r = find_root(p, i);
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
