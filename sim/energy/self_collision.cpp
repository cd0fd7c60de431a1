#include "sim/energy/self_collision.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/core/thread_pool.hpp"

namespace drape::sim {

namespace {

constexpr int kCellBits = 10;  // cell coordinates wrap at 1024 per axis (only used to hash)

uint32_t pack(int ix, int iy, int iz) {
  const uint32_t m = (1u << kCellBits) - 1;
  return (uint32_t(ix) & m) | ((uint32_t(iy) & m) << kCellBits) |
         ((uint32_t(iz) & m) << (2 * kCellBits));
}

uint32_t bucket(uint32_t cell, uint32_t mask) {
  return (cell * 2654435761u) >> 7 & mask;  // Knuth's multiplicative hash
}

// Side-signed distance of p to triangle (a, b, c)'s plane along its unit normal n, and the
// barycentric coordinates of p's projection; false for a degenerate triangle.
bool plane_coords(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Vec3& n, double& d,
                  double bary[3]) {
  const Vec3 e1 = b - a, e2 = c - a;
  n = e1.cross(e2);
  const double a2 = n.squaredNorm();
  if (a2 < 1e-24) return false;
  const Vec3 r = p - a;
  // Barycentric coordinates of the projection: areas of the sub-triangles against n.
  bary[1] = r.cross(e2).dot(n) / a2;
  bary[2] = e1.cross(r).dot(n) / a2;
  bary[0] = 1 - bary[1] - bary[2];
  n /= std::sqrt(a2);
  d = n.dot(r);
  return true;
}

// A region is flat when the normals of its triangles lie within this angle of their mean (the
// normals of two flat regions, or of a region and an adjacent one, then differ by at most twice
// it: a vertex of one is never over a triangle of the other within the reach).
constexpr double kFlatCone = 44.0 * 3.14159265358979323846 / 180.0;

// Regions are cells of this many edges on a side.
constexpr double kRegionEdges = 6.0;

int find_root(std::vector<int32_t>& parent, int32_t a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

}  // namespace

void SelfCollision::build_regions(const Cloth& cloth) {
  const auto& tris = cloth.topo.triangles;
  const auto& M = cloth.topo.material;
  const int nt = static_cast<int>(tris.size()), n = cloth.num_vertices();
  region_version_ = cloth.topology_version;
  region_tris_ = nt;
  // Grid cells 8 edges wide (an edge: the mean of each triangle's shortest material edge, the
  // grid spacing of a panel), from the lowest material coordinates: on a panel the cells' sides
  // run along grid lines, so that the regions of neighbouring cells share vertices, corners too.
  // A triangle belongs to the cell of its centroid.
  double edge = 0;
  Vec2 origin = Vec2::Constant(std::numeric_limits<double>::infinity());
  for (const auto& t : tris) {
    edge += std::min(
        {(M[t[1]] - M[t[0]]).norm(), (M[t[2]] - M[t[1]]).norm(), (M[t[0]] - M[t[2]]).norm()});
    for (const int v : t) origin = origin.cwiseMin(M[v]);
  }
  const double ic = 1.0 / std::max(kRegionEdges * edge / std::max(nt, 1), 1e-9);
  std::vector<int64_t> cell(nt);
  for (int t = 0; t < nt; ++t) {
    const Vec2 c = (M[tris[t][0]] + M[tris[t][1]] + M[tris[t][2]]) / 3.0 - origin;
    cell[t] = (static_cast<int64_t>(std::floor(c.x() * ic)) << 32) ^
              static_cast<int64_t>(static_cast<uint32_t>(std::floor(c.y() * ic)));
  }
  // Triangles of one cell that share a vertex are joined (union-find over each vertex's fan).
  std::vector<int32_t> fan_lo(n + 1, 0), fan, parent(nt);
  for (const auto& t : tris)
    for (const int v : t) ++fan_lo[v + 1];
  for (int v = 0; v < n; ++v) fan_lo[v + 1] += fan_lo[v];
  fan.resize(fan_lo[n]);
  std::vector<int32_t> at(fan_lo.begin(), fan_lo.end() - 1);
  for (int t = 0; t < nt; ++t)
    for (const int v : tris[t]) fan[at[v]++] = t;
  for (int t = 0; t < nt; ++t) parent[t] = t;
  for (int v = 0; v < n; ++v)
    for (int i = fan_lo[v]; i < fan_lo[v + 1]; ++i)
      for (int j = i + 1; j < fan_lo[v + 1]; ++j)
        if (cell[fan[i]] == cell[fan[j]])
          parent[find_root(parent, fan[j])] = find_root(parent, fan[i]);
  region_of_.assign(nt, -1);
  std::vector<int32_t> id(nt, -1);
  int regions = 0;
  for (int t = 0; t < nt; ++t) {
    const int r = find_root(parent, t);
    if (id[r] < 0) id[r] = regions++;
    region_of_[t] = id[r];
  }
  region_lo_.assign(regions + 1, 0);
  for (int t = 0; t < nt; ++t) ++region_lo_[region_of_[t] + 1];
  for (int r = 0; r < regions; ++r) region_lo_[r + 1] += region_lo_[r];
  region_tri_.resize(nt);
  std::vector<int32_t> fill(region_lo_.begin(), region_lo_.end() - 1);
  for (int t = 0; t < nt; ++t) region_tri_[fill[region_of_[t]]++] = t;
  // Adjacent regions: two regions with a common vertex, or with the two ends of one edge (a
  // region of a mesh that is not a grid can meet its diagonal neighbour across one triangle).
  region_adjacent_.clear();
  auto join = [&](int u, int v) {
    for (int i = fan_lo[u]; i < fan_lo[u + 1]; ++i)
      for (int j = fan_lo[v]; j < fan_lo[v + 1]; ++j) {
        const int a = region_of_[fan[i]], b = region_of_[fan[j]];
        if (a != b)
          region_adjacent_.push_back((uint64_t(std::min(a, b)) << 32) | uint64_t(std::max(a, b)));
      }
  };
  for (int v = 0; v < n; ++v) join(v, v);
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) join(t[k], t[(k + 1) % 3]);
  std::sort(region_adjacent_.begin(), region_adjacent_.end());
  region_adjacent_.erase(std::unique(region_adjacent_.begin(), region_adjacent_.end()),
                         region_adjacent_.end());
}

void SelfCollision::cull(const Cloth& cloth, const std::vector<Vec3>& x, double reach) {
  const auto& tris = cloth.topo.triangles;
  const int nt = static_cast<int>(tris.size()), n = cloth.num_vertices();
  if (!region_cull_) {
    tri_active_.assign(nt, 1);
    vertex_active_.assign(n, 1);
    active_regions_ = regions();
    active_tris_ = nt;
    return;
  }
  if (region_version_ != cloth.topology_version || region_tris_ != nt) build_regions(cloth);
  const int R = regions();
  struct Box {
    Vec3 lo, hi, axis;
    double cone;  // half-angle of the normals about the axis (pi: not flat)
  };
  std::vector<Box> box(R);
  region_n_.resize(region_tri_.size());
  for (int r = 0; r < R; ++r) {
    Box& b = box[r];
    b.lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    b.hi = -b.lo;
    Vec3 sum = Vec3::Zero();
    for (int k = region_lo_[r]; k < region_lo_[r + 1]; ++k) {
      const auto& T = tris[region_tri_[k]];
      for (const int v : T) {
        b.lo = b.lo.cwiseMin(x[v]);
        b.hi = b.hi.cwiseMax(x[v]);
      }
      region_n_[k] = (x[T[1]] - x[T[0]]).cross(x[T[2]] - x[T[0]]);
      sum += region_n_[k];
    }
    b.lo.array() -= reach;
    b.hi.array() += reach;
    b.cone = 3.14159265358979323846;
    const double len = sum.norm();
    if (!(len > 0)) continue;
    b.axis = sum / len;
    double cmin = 1;
    for (int k = region_lo_[r]; k < region_lo_[r + 1]; ++k) {
      const Vec3& N = region_n_[k];
      const double nn = N.norm();
      cmin = std::min(cmin, nn > 0 ? N.dot(b.axis) / nn : -1.0);
    }
    b.cone = std::acos(std::clamp(cmin, -1.0, 1.0));
  }
  std::vector<char> active(R);
  for (int r = 0; r < R; ++r) active[r] = !(box[r].cone < kFlatCone);
  // Sweep along x over the boxes sorted by their low end: each overlapping pair either is two
  // adjacent regions flat together (no pair between them) or makes both active.
  std::vector<int32_t> order(R);
  for (int r = 0; r < R; ++r) order[r] = r;
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return box[a].lo.x() < box[b].lo.x(); });
  for (int i = 0; i < R; ++i) {
    const Box& A = box[order[i]];
    for (int j = i + 1; j < R && box[order[j]].lo.x() <= A.hi.x(); ++j) {
      const Box& B = box[order[j]];
      if (B.lo.y() > A.hi.y() || A.lo.y() > B.hi.y() || B.lo.z() > A.hi.z() || A.lo.z() > B.hi.z())
        continue;
      const int a = std::min(order[i], order[j]), b = std::max(order[i], order[j]);
      const bool adjacent = std::binary_search(region_adjacent_.begin(), region_adjacent_.end(),
                                               (uint64_t(a) << 32) | uint64_t(b));
      if (adjacent && A.cone < kFlatCone && B.cone < kFlatCone) {
        const double between = std::acos(std::clamp(A.axis.dot(B.axis), -1.0, 1.0));
        if (std::max(A.cone, B.cone + between) < kFlatCone) continue;
      }
      active[a] = active[b] = 1;
    }
  }
  tri_active_.assign(nt, 0);
  vertex_active_.assign(n, 0);
  active_regions_ = active_tris_ = 0;
  for (int r = 0; r < R; ++r) {
    if (!active[r]) continue;
    ++active_regions_;
    for (int k = region_lo_[r]; k < region_lo_[r + 1]; ++k) {
      const int t = region_tri_[k];
      tri_active_[t] = 1;
      ++active_tris_;
      for (const int v : tris[t]) vertex_active_[v] = 1;
    }
  }
}

int SelfCollision::detect(const Cloth& cloth, const std::vector<Vec3>& x, double thickness,
                          double margin, ThreadPool* pool) {
  pairs_.clear();
  const auto& tris = cloth.topo.triangles;
  const int nt = static_cast<int>(tris.size());
  const int n = cloth.num_vertices();
  if (nt == 0) return 0;
  const auto& flags = cloth.state.flags;
  const double reach = thickness + margin;
  cull(cloth, x, reach);
  if (active_tris_ == 0) return 0;
  // Cell size: the mean edge length plus twice the reach, so that a triangle's grown box spans
  // at most two cells per axis. On fine meshes the reach dominates the cell, so a vertex's
  // bucket holds ~170 triangles at 128^2; the bounding-sphere test below rejects most of them
  // from the entry alone (18.5 -> 11.2 ms at 128^2).
  double edge = 0;
  for (int t = 0; t < nt; ++t)
    if (tri_active_[t]) edge += (x[tris[t][1]] - x[tris[t][0]]).norm();
  const double cell = edge / active_tris_ + 2 * reach;
  const double ic = 1.0 / cell;
  auto coord = [&](double v) { return static_cast<int>(std::floor(v * ic)); };
  // Table size: a power of two >= 2 x the tested triangles' count.
  uint32_t size = 1;
  while (size < 2u * static_cast<uint32_t>(active_tris_)) size <<= 1;
  const uint32_t mask = size - 1;
  table_start_.assign(size + 1, 0);
  // Calls fn(cell key) for each cell triangle t's bounding box, grown by the reach, overlaps
  // (at most 3 per axis when the cell is >= the mean edge plus twice the reach; a triangle
  // stretched beyond 8 cells per axis is entered in the first 8 only, a listed limit).
  auto for_cells = [&](int t, auto&& fn) {
    const Vec3& a = x[tris[t][0]];
    const Vec3& b = x[tris[t][1]];
    const Vec3& c = x[tris[t][2]];
    const Vec3 lo = a.cwiseMin(b).cwiseMin(c).array() - reach;
    const Vec3 hi = a.cwiseMax(b).cwiseMax(c).array() + reach;
    const int x0 = coord(lo.x()), y0 = coord(lo.y()), z0 = coord(lo.z());
    const int ex = std::min(coord(hi.x()) - x0, 7), ey = std::min(coord(hi.y()) - y0, 7),
              ez = std::min(coord(hi.z()) - z0, 7);
    for (int i = 0; i <= ex; ++i)
      for (int j = 0; j <= ey; ++j)
        for (int k = 0; k <= ez; ++k) fn(pack(x0 + i, y0 + j, z0 + k));
  };
  // Counting sort of (bucket, triangle): counts, prefix sums, fill.
  for (int t = 0; t < nt; ++t)
    if (tri_active_[t])
      for_cells(t, [&](uint32_t cell) { ++table_start_[bucket(cell, mask) + 1]; });
  for (uint32_t b = 0; b < size; ++b) table_start_[b + 1] += table_start_[b];
  entries_.resize(table_start_[size]);
  fill_.assign(table_start_.begin(), table_start_.end() - 1);
  // Each entry also carries its triangle's bounding sphere (centre, radius + reach) inline, so
  // a vertex rejects the triangles of its bucket that are out of reach without touching the
  // triangle (most of a bucket's ~170 candidates at 128^2: the bucket spans 18 mm, the reach
  // sphere 7 mm + the triangle).
  spheres_.resize(entries_.size());
  for (int t = 0; t < nt; ++t) {
    if (!tri_active_[t]) continue;
    const Vec3& a = x[tris[t][0]];
    const Vec3& b = x[tris[t][1]];
    const Vec3& c = x[tris[t][2]];
    const Vec3 m = (a + b + c) / 3;
    const double r =
        std::sqrt(std::max({(a - m).squaredNorm(), (b - m).squaredNorm(), (c - m).squaredNorm()}));
    const Sphere sp{float(m.x()), float(m.y()), float(m.z()), float(r + reach) * 1.0001f + 1e-6f};
    for_cells(t, [&](uint32_t cell) {
      const int32_t q = fill_[bucket(cell, mask)]++;
      entries_[q] = t;
      spheres_[q] = sp;
    });
  }
  // Per triangle its first corner a, unit normal n and the vectors g1, g2 with barycentric
  // coordinates b1 = g1 . (p - a), b2 = g2 . (p - a) of p's projection (g = 0: degenerate):
  // each candidate then costs three dot products.
  pre_.resize(nt);
  auto frames = [&](int b, int e, int) {
    for (int t = b; t < e; ++t) {
      if (!tri_active_[t]) continue;
      TriFrame& f = pre_[t];
      f.a = x[tris[t][0]];
      const Vec3 e1 = x[tris[t][1]] - f.a, e2 = x[tris[t][2]] - f.a, N = e1.cross(e2);
      const double n2 = N.squaredNorm();
      if (n2 < 1e-24) {
        f.n = f.g1 = f.g2 = Vec3::Zero();
        continue;
      }
      f.n = N / std::sqrt(n2);
      f.g1 = e2.cross(N) / n2;
      f.g2 = N.cross(e1) / n2;
    }
  };
  if (pool)
    pool->parallel_for(nt, frames);
  else
    frames(0, nt, 0);
  // Pass 2: each vertex against the triangles of its cell's bucket. With a pool the vertices run
  // in one contiguous part per thread, each into its own list, joined in part order: the pairs
  // of one thread in the same order.
  auto fixed = [&](int v) {
    return (flags[v] & (kFlagPinned | kFlagPinched | kFlagKinematic)) != 0;
  };
  auto test = [&](int vb, int ve, std::vector<SelfContact>& out) {
    for (int v = vb; v < ve; ++v) {
      if (!vertex_active_[v] || (flags[v] & (kFlagNoCollide | kFlagKinematic))) continue;
      const Vec3& p = x[v];
      const uint32_t bk = bucket(pack(coord(p.x()), coord(p.y()), coord(p.z())), mask);
      const int32_t* e = entries_.data();
      const Sphere* sph = spheres_.data();
      const float px = float(p.x()), py = float(p.y()), pz = float(p.z());
      for (int32_t q = table_start_[bk]; q < table_start_[bk + 1]; ++q) {
        const Sphere& sq = sph[q];
        const float dx = px - sq.x, dy = py - sq.y, dz = pz - sq.z;
        if (sphere_test_ && dx * dx + dy * dy + dz * dz > sq.r * sq.r) continue;  // out of reach
        const int t = e[q];
        const auto& T = tris[t];
        if (T[0] == v || T[1] == v || T[2] == v) continue;
        const TriFrame& f = pre_[t];
        const Vec3 r = p - f.a;
        const double d = f.n.dot(r);
        if (std::abs(d) >= reach || f.n.isZero()) continue;  // far from the plane (or degenerate)
        const double b1 = f.g1.dot(r), b2 = f.g2.dot(r);
        if (b1 < 0 || b2 < 0 || b1 + b2 > 1) continue;  // projects outside the triangle
        if (fixed(v) && fixed(T[0]) && fixed(T[1]) && fixed(T[2])) continue;
        // Skip duplicates (a triangle can sit in the bucket twice via two cells hashing alike).
        bool dup = false;
        for (int k = static_cast<int>(out.size()) - 1; k >= 0 && out[k].vertex == v; --k)
          if (out[k].triangle == t) dup = true;
        if (!dup) out.push_back({v, t, d >= 0 ? 1.0 : -1.0});
      }
    }
  };
  if (!pool || pool->size() < 2) {
    test(0, n, pairs_);
  } else {
    part_pairs_.resize(pool->size());
    pool->parallel_parts(n, [&](int vb, int ve, int part) {
      part_pairs_[part].clear();
      test(vb, ve, part_pairs_[part]);
    });
    for (const auto& part : part_pairs_) pairs_.insert(pairs_.end(), part.begin(), part.end());
  }
  return static_cast<int>(pairs_.size());
}

double SelfCollision::project(const Cloth& cloth, std::vector<Vec3>& x, const double* w,
                              double thickness, std::vector<int>* moved) const {
  const auto& tris = cloth.topo.triangles;
  double biggest = 0;
  for (const SelfContact& c : pairs_) {
    const auto& T = tris[c.triangle];
    Vec3 nrm;
    double d, b[3];
    if (!plane_coords(x[c.vertex], x[T[0]], x[T[1]], x[T[2]], nrm, d, b)) continue;
    const double C = c.side * d - thickness;
    if (C >= 0) continue;
    // Outside the triangle now (slid off its edge): the neighbouring triangle's pair, if any,
    // holds the vertex; clamp the weights so the correction stays on this triangle.
    for (double& bk : b) bk = std::clamp(bk, 0.0, 1.0);
    const double s = b[0] + b[1] + b[2];
    for (double& bk : b) bk /= s;
    const double wv = w[c.vertex];
    const double den = wv + b[0] * b[0] * w[T[0]] + b[1] * b[1] * w[T[1]] + b[2] * b[2] * w[T[2]];
    if (den <= 0) continue;
    const double dl = -C / den;
    const Vec3 g = c.side * nrm;  // direction that increases C at the vertex
    x[c.vertex] += (wv * dl) * g;
    for (int k = 0; k < 3; ++k) x[T[k]] -= (w[T[k]] * b[k] * dl) * g;
    if (moved) moved->insert(moved->end(), {c.vertex, T[0], T[1], T[2]});
    biggest = std::max(biggest, -C);
  }
  return biggest;
}

double SelfCollision::min_clearance(const Cloth& cloth, const std::vector<Vec3>& x,
                                    double thickness) const {
  const auto& tris = cloth.topo.triangles;
  double m = std::numeric_limits<double>::infinity();
  for (const SelfContact& c : pairs_) {
    const auto& T = tris[c.triangle];
    Vec3 nrm;
    double d, b[3];
    if (!plane_coords(x[c.vertex], x[T[0]], x[T[1]], x[T[2]], nrm, d, b)) continue;
    if (b[0] < 0 || b[1] < 0 || b[2] < 0) continue;  // slid off: no longer over this triangle
    m = std::min(m, c.side * d - thickness);
  }
  return m;
}

}  // namespace drape::sim
