// Reference lines of a session's pattern piece: the draped cloth's crossing of a height, flat,
// clipped to the piece's outline.
#include "sim/draping/session_lines.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace drape::sim {
namespace {

using EdgeKey = std::pair<int, int>;

// The crossing graph: one node per crossed edge (its flat point), one link per triangle.
struct Crossings {
  std::map<EdgeKey, Vec2> point;
  std::map<EdgeKey, std::vector<EdgeKey>> links;
};

Crossings crossings(const Cloth& cloth, const std::vector<int>& tris, double y) {
  Crossings g;
  const auto& x = cloth.state.x;
  const auto& m = cloth.topo.material;
  for (int t : tris) {
    const auto& tri = cloth.topo.triangles[t];
    std::vector<EdgeKey> hit;
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      const double ya = x[a].y() - y, yb = x[b].y() - y;
      if ((ya >= 0) == (yb >= 0)) continue;
      const EdgeKey key = std::minmax(a, b);
      const double f = ya / (ya - yb);
      g.point[key] = m[a] + f * (m[b] - m[a]);
      hit.push_back(key);
    }
    if (hit.size() != 2) continue;
    g.links[hit[0]].push_back(hit[1]);
    g.links[hit[1]].push_back(hit[0]);
  }
  return g;
}

// The runs of the crossing graph as polylines, each walked from an end (or, for a closed
// loop, from any node).
std::vector<std::vector<Vec2>> runs(const Crossings& g) {
  std::vector<std::vector<Vec2>> out;
  std::map<EdgeKey, bool> seen;
  const auto walk = [&](EdgeKey k) {
    std::vector<Vec2> line;
    EdgeKey prev{-1, -1};
    for (;;) {
      seen[k] = true;
      const Vec2 q = g.point.at(k);
      if (line.empty() || (q - line.back()).norm() > 1e-12) line.push_back(q);
      const auto& nb = g.links.at(k);
      auto it = std::find_if(nb.begin(), nb.end(),
                             [&](const EdgeKey& n) { return n != prev && !seen[n]; });
      if (it == nb.end()) break;
      prev = k;
      k = *it;
    }
    if (line.size() >= 2) out.push_back(std::move(line));
  };
  for (const auto& [k, nb] : g.links)
    if (nb.size() == 1 && !seen[k]) walk(k);
  for (const auto& [k, nb] : g.links)
    if (!seen[k]) walk(k);
  return out;
}

bool inside(const std::vector<Vec2>& poly, const Vec2& p) {
  bool in = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2 &a = poly[i], &b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < a.x() + (p.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x()))
      in = !in;
  }
  return in;
}

// Parameters in (0, 1) where segment p -> q crosses the polygon's edges.
std::vector<double> cuts_of(const std::vector<Vec2>& poly, const Vec2& p, const Vec2& q) {
  std::vector<double> ts;
  const Vec2 d = q - p;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec2 a = poly[i], e = poly[(i + 1) % poly.size()] - a;
    const double den = d.x() * e.y() - d.y() * e.x();
    if (std::abs(den) < 1e-18) continue;
    const Vec2 r = a - p;
    const double t = (r.x() * e.y() - r.y() * e.x()) / den;
    const double s = (r.x() * d.y() - r.y() * d.x()) / den;
    if (t > 0 && t < 1 && s >= 0 && s <= 1) ts.push_back(t);
  }
  std::sort(ts.begin(), ts.end());
  return ts;
}

// The longest part of `line` inside the polygon.
std::vector<Vec2> clip_longest(const std::vector<Vec2>& line, const std::vector<Vec2>& poly) {
  std::vector<Vec2> best, cur;
  const auto close_run = [&] {
    if (cur.size() >= 2 && polyline_length(cur) > polyline_length(best)) best = cur;
    cur.clear();
  };
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    const Vec2 p = line[i], q = line[i + 1];
    std::vector<double> ts = cuts_of(poly, p, q);
    ts.insert(ts.begin(), 0.0);
    ts.push_back(1.0);
    for (size_t k = 0; k + 1 < ts.size(); ++k) {
      const Vec2 a = p + ts[k] * (q - p), b = p + ts[k + 1] * (q - p);
      if (!inside(poly, 0.5 * (a + b))) {
        close_run();
        continue;
      }
      if (cur.empty()) cur.push_back(a);
      cur.push_back(b);
    }
  }
  close_run();
  return best;
}

// The run continued straight past both ends by `reach`.
std::vector<Vec2> extended(std::vector<Vec2> line, double reach) {
  if (line.size() < 2) return line;
  const Vec2 d0 = (line[0] - line[1]).normalized();
  const Vec2 d1 = (line.back() - line[line.size() - 2]).normalized();
  line.insert(line.begin(), line[0] + reach * d0);
  line.push_back(line.back() + reach * d1);
  return line;
}

}  // namespace

double polyline_length(const std::vector<Vec2>& line) {
  double s = 0;
  for (size_t i = 1; i < line.size(); ++i) s += (line[i] - line[i - 1]).norm();
  return s;
}

std::vector<Vec2> session_reference_line(const Cloth& cloth, const std::vector<int>& tris,
                                         const std::vector<Vec2>& outline, double y, double reach) {
  std::vector<Vec2> best;
  if (outline.size() < 3) return best;
  for (const auto& run : runs(crossings(cloth, tris, y))) {
    std::vector<Vec2> clipped = clip_longest(extended(run, reach), outline);
    if (polyline_length(clipped) > polyline_length(best)) best = std::move(clipped);
  }
  // Centre -> side is not known here; the line runs from smaller to larger u (weft).
  if (best.size() >= 2 && best.front().x() > best.back().x())
    std::reverse(best.begin(), best.end());
  return best;
}

}  // namespace drape::sim
