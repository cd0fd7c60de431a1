// The baseline's mass-spring network (structural and diagonal springs) derived from the triangle
// mesh.
#include "sim/energy/springs.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace drape::sim {

int Springs::count(SpringKind kd) const {
  return static_cast<int>(std::count(kind.begin(), kind.end(), kd));
}

namespace {

struct EdgeInfo {
  int32_t opposite[2] = {-1, -1};  // vertex opposite the edge in up to two triangles
  double area = 0;                 // sum of the adjacent triangles' material areas
  int tris = 0;
};

uint64_t edge_key(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

bool is_structural(const Vec2& d) {
  // Within 22.5 degrees of an axis: the smaller component is below tan(22.5) of the larger.
  const double ax = std::abs(d.x()), ay = std::abs(d.y());
  return std::min(ax, ay) < 0.41421356237 * std::max(ax, ay);
}

}  // namespace

Springs build_springs(const Cloth& cloth, double stiffness_scale) {
  const auto& topo = cloth.topo;
  const auto& mat = topo.material;
  const FabricParams& f = cloth.fabric;
  std::unordered_map<uint64_t, EdgeInfo> edges;
  edges.reserve(topo.triangles.size() * 2);
  for (const auto& t : topo.triangles) {
    const Vec2 e1 = mat[t[1]] - mat[t[0]], e2 = mat[t[2]] - mat[t[0]];
    const double area = 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    for (int k = 0; k < 3; ++k) {
      EdgeInfo& e = edges[edge_key(t[k], t[(k + 1) % 3])];
      if (e.tris < 2) e.opposite[e.tris] = t[(k + 2) % 3];
      ++e.tris;
      e.area += area;
    }
  }
  // Deterministic order: sort the edge keys.
  std::vector<uint64_t> keys;
  keys.reserve(edges.size());
  for (const auto& [key, info] : edges) keys.push_back(key);
  std::sort(keys.begin(), keys.end());

  Springs s;
  s.topology_version = cloth.topology_version;
  auto add = [&](int32_t a, int32_t b, double area_for_diag, double width_area) {
    const Vec2 d = mat[b] - mat[a];
    const double L = d.norm();
    if (L <= 0) return;
    double k;
    SpringKind kind;
    if (is_structural(d)) {
      const double c2 = d.x() * d.x() / (L * L), s2 = 1.0 - c2;
      const double stretch = f.stretch_weft * c2 + f.stretch_warp * s2;
      k = stretch * (width_area / L) / L;
      kind = SpringKind::kStructural;
    } else {
      const double sc = std::abs(d.x() * d.y()) / (L * L);  // sin t cos t
      k = f.shear * area_for_diag / (2.0 * L * L * sc * sc);
      kind = SpringKind::kDiagonal;
    }
    s.a.push_back(a);
    s.b.push_back(b);
    s.rest.push_back(L);
    s.k.push_back(k * stiffness_scale);
    s.kind.push_back(kind);
  };
  for (uint64_t key : keys) {
    const EdgeInfo& e = edges.at(key);
    const auto a = static_cast<int32_t>(key >> 32), b = static_cast<int32_t>(key & 0xffffffffu);
    const bool diag = !is_structural(mat[b] - mat[a]);
    // A cell's area: both triangles inside; twice the one triangle on a border.
    const double cell_area = e.tris >= 2 ? e.area : 2.0 * e.area;
    add(a, b, cell_area, e.area);
    if (diag && e.tris == 2 && e.opposite[0] != e.opposite[1]) {
      const int32_t c = std::min(e.opposite[0], e.opposite[1]);
      const int32_t d = std::max(e.opposite[0], e.opposite[1]);
      add(c, d, cell_area, e.area);
    }
  }
  return s;
}

double max_eigenvalue_bound(const Cloth& cloth, const Springs& springs) {
  std::vector<double> ksum(cloth.num_vertices(), 0.0);
  for (int s = 0; s < springs.size(); ++s) {
    ksum[springs.a[s]] += springs.k[s];
    ksum[springs.b[s]] += springs.k[s];
  }
  double bound = 0;
  for (int i = 0; i < cloth.num_vertices(); ++i) {
    if (cloth.state.inv_mass[i] > 0)
      bound = std::max(bound, 2.0 * ksum[i] * cloth.state.inv_mass[i]);
  }
  return bound;
}

}  // namespace drape::sim
