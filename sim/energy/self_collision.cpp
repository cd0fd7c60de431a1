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

constexpr double kDegree = 3.14159265358979323846 / 180.0;

// A vertex whose projection falls outside a triangle (over an edge or a corner of it: a convex
// layer has such gaps between its triangles' prisms) pairs with it when the nearest point of the
// triangle lies within this angle of the normal through the vertex (and within the reach): a
// vertex over a ridge whose two triangles turn by up to twice it is held by both. Wider angles
// ask for a narrower flat cone (below), which culls less.
constexpr double kOverEdgeTan = 0.26794919243112270;  // tan 15 deg

// A region is flat when the normals of its triangles lie within this angle of their mean (the
// normals of two flat regions, or of a region and an adjacent one, then differ by at most twice
// it). Along such a surface a chord leans at least 90 - 37 deg from the mean and 90 - 74 = 16 deg
// from any triangle's normal: more than the 15 deg over an edge (kOverEdgeTan), so no vertex of
// one is within a pair's angle of a triangle of the other. (Pairs inside the prisms alone would
// allow 44 deg, which in the app's scene tests half the regions 37 deg does at 64^2.)
constexpr double kFlatCone = 37.0 * kDegree;

// Whether triangles a and b have a vertex in common.
bool shares_corner(const std::array<int32_t, 3>& a, const std::array<int32_t, 3>& b) {
  for (const int32_t u : a)
    if (u == b[0] || u == b[1] || u == b[2]) return true;
  return false;
}

// Distance from q, in the plane of triangle (a, b, c) and outside it, to the triangle: to the
// nearest of the edges whose opposite barycentric coordinate (bary) is negative.
double outside_distance(const Vec3& q, const Vec3 (&corner)[3], const double (&bary)[3]) {
  double best2 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (bary[k] >= 0) continue;
    const Vec3& p0 = corner[(k + 1) % 3];
    const Vec3 e = corner[(k + 2) % 3] - p0;
    const double ee = e.squaredNorm();
    const double t = ee > 0 ? std::clamp((q - p0).dot(e) / ee, 0.0, 1.0) : 0.0;
    best2 = std::min(best2, (q - p0 - t * e).squaredNorm());
  }
  return std::sqrt(best2);
}

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
  ++region_builds_;
  shapes_found_ = false;
  // Grid cells kRegionEdges edges wide (an edge: the mean of each triangle's shortest material
  // edge, the grid spacing of a panel), from the lowest material coordinates: on a panel the cells'
  // sides run along grid lines, so that the regions of neighbouring cells share vertices, corners
  // too. A triangle belongs to the cell of its centroid.
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
  // (A cook ahead builds the regions on a worker: pause points between the parts, TickGate.)
  pause_point();
  // Triangles of one cell that share a vertex are joined (union-find over each vertex's fan).
  build_fans(cloth);
  const std::vector<int32_t>&fan_lo = fan_lo_, &fan = fan_;
  std::vector<int32_t> parent(nt);
  for (int t = 0; t < nt; ++t) parent[t] = t;
  pause_point();
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
  vertex_region_.assign(n, -1);
  for (int v = 0; v < n; ++v)
    if (fan_lo[v] < fan_lo[v + 1]) vertex_region_[v] = region_of_[fan[fan_lo[v]]];
  region_lo_.assign(regions + 1, 0);
  for (int t = 0; t < nt; ++t) ++region_lo_[region_of_[t] + 1];
  for (int r = 0; r < regions; ++r) region_lo_[r + 1] += region_lo_[r];
  region_tri_.resize(nt);
  std::vector<int32_t> fill(region_lo_.begin(), region_lo_.end() - 1);
  for (int t = 0; t < nt; ++t) region_tri_[fill[region_of_[t]]++] = t;
  // Adjacent regions: two regions with a common vertex, or with the two ends of one edge (a
  // region of a mesh that is not a grid can meet its diagonal neighbour across one triangle).
  // Each vertex's distinct regions first (one inside a region, a few on its border), so that a
  // vertex or an edge pairs a handful of regions rather than every two triangles of its fans.
  pause_point();
  std::vector<int32_t> vreg_lo(n + 1, 0), vreg;
  vreg.reserve(fan.size());
  for (int v = 0; v < n; ++v) {
    const size_t first = vreg.size();
    for (int i = fan_lo[v]; i < fan_lo[v + 1]; ++i) {
      const int r = region_of_[fan[i]];
      if (std::find(vreg.begin() + first, vreg.end(), r) == vreg.end()) vreg.push_back(r);
    }
    vreg_lo[v + 1] = static_cast<int32_t>(vreg.size());
  }
  // Each region's vertices (those of its triangles, once each: CSR region_vlo_, region_vert_).
  region_vlo_.assign(regions + 1, 0);
  for (const int32_t r : vreg) ++region_vlo_[r + 1];
  for (int r = 0; r < regions; ++r) region_vlo_[r + 1] += region_vlo_[r];
  region_vert_.resize(vreg.size());
  {
    std::vector<int32_t> put(region_vlo_.begin(), region_vlo_.end() - 1);
    for (int v = 0; v < n; ++v)
      for (int i = vreg_lo[v]; i < vreg_lo[v + 1]; ++i) region_vert_[put[vreg[i]]++] = v;
  }
  std::vector<uint64_t> adjacent;  // (a << 32 | b), a < b: regions sharing a vertex
  auto join = [&](int u, int v) {
    for (int i = vreg_lo[u]; i < vreg_lo[u + 1]; ++i)
      for (int j = vreg_lo[v]; j < vreg_lo[v + 1]; ++j) {
        const int a = vreg[i], b = vreg[j];
        if (a != b) adjacent.push_back((uint64_t(std::min(a, b)) << 32) | uint64_t(std::max(a, b)));
      }
  };
  pause_point();
  for (int v = 0; v < n; ++v) join(v, v);
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) join(t[k], t[(k + 1) % 3]);
  pause_point();
  std::sort(adjacent.begin(), adjacent.end());
  adjacent.erase(std::unique(adjacent.begin(), adjacent.end()), adjacent.end());
  // The same both ways, per region (CSR: adj_lo_, adj_).
  adj_lo_.assign(regions + 1, 0);
  for (const uint64_t p : adjacent) {
    ++adj_lo_[(p >> 32) + 1];
    ++adj_lo_[(p & 0xffffffffu) + 1];
  }
  for (int r = 0; r < regions; ++r) adj_lo_[r + 1] += adj_lo_[r];
  adj_.resize(adj_lo_[regions]);
  std::vector<int32_t> put(adj_lo_.begin(), adj_lo_.end() - 1);
  for (const uint64_t p : adjacent) {
    const int a = static_cast<int>(p >> 32), b = static_cast<int>(p & 0xffffffffu);
    adj_[put[a]++] = b;
    adj_[put[b]++] = a;
  }
  adj_together_.assign(adj_.size(), 0);
}

void SelfCollision::build_fans(const Cloth& cloth) {
  const auto& tris = cloth.topo.triangles;
  const int nt = static_cast<int>(tris.size()), n = cloth.num_vertices();
  if (fans_version_ == cloth.topology_version && fans_tris_ == nt &&
      static_cast<int>(fan_lo_.size()) == n + 1)
    return;
  fans_version_ = cloth.topology_version;
  fans_tris_ = nt;
  fan_lo_.assign(n + 1, 0);
  for (const auto& t : tris)
    for (const int v : t) ++fan_lo_[v + 1];
  for (int v = 0; v < n; ++v) fan_lo_[v + 1] += fan_lo_[v];
  fan_.resize(fan_lo_[n]);
  std::vector<int32_t> at(fan_lo_.begin(), fan_lo_.end() - 1);
  for (int t = 0; t < nt; ++t)
    for (const int v : tris[t]) fan_[at[v]++] = t;
}

bool SelfCollision::near_in_mesh(const Cloth& cloth, int v, int t) const {
  const auto& tris = cloth.topo.triangles;
  for (int i = fan_lo_[v]; i < fan_lo_[v + 1]; ++i)
    if (shares_corner(tris[fan_[i]], tris[t])) return true;
  return false;
}

void SelfCollision::prepare(const Cloth& cloth) {
  if (region_cull_ && (region_version_ != cloth.topology_version ||
                       region_tris_ != static_cast<int>(cloth.topo.triangles.size())))
    build_regions(cloth);
  // The detection's arrays per triangle and per vertex, sized and written here (on a cook-ahead
  // worker) rather than page-faulted in the first detection on the topology (3 MB at 128^2).
  const size_t nt = cloth.topo.triangles.size(), n = static_cast<size_t>(cloth.num_vertices());
  if (pre_.size() != nt) pre_.assign(nt, {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()});
  if (region_n_.size() != region_tri_.size()) region_n_.assign(region_tri_.size(), Vec3::Zero());
  active_tri_.reserve(nt);
  active_vert_.reserve(n);
}

// Region r's box (its vertices' bounds grown by the reach) and the cone of its triangles'
// normals about their mean (box_[r]; pi: not flat). Each region writes only its own entries.
void SelfCollision::region_box(const Cloth& cloth, const std::vector<Vec3>& x, double reach,
                               int r) {
  const auto& tris = cloth.topo.triangles;
  Box& b = box_[r];
  double lo[3], hi[3];  // (plain arrays: the loop keeps them in registers)
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<double>::infinity();
    hi[a] = -lo[a];
  }
  for (int k = region_vlo_[r]; k < region_vlo_[r + 1]; ++k) {
    const Vec3& p = x[region_vert_[k]];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }
  for (int a = 0; a < 3; ++a) {
    b.lo[a] = lo[a] - reach;
    b.hi[a] = hi[a] + reach;
  }
  Vec3 sum = Vec3::Zero();
  for (int k = region_lo_[r]; k < region_lo_[r + 1]; ++k) {
    const auto& T = tris[region_tri_[k]];
    region_n_[k] = (x[T[1]] - x[T[0]]).cross(x[T[2]] - x[T[0]]);
    sum += region_n_[k];
  }
  b.cone = 3.14159265358979323846;
  const double len = sum.norm();
  if (!(len > 0)) return;
  b.axis = sum / len;
  // The smallest cosine of a normal to the axis, as the signed square c |c| = d |d| / |N|^2
  // (d = N . axis), kept as a fraction num / den: no root or division per triangle.
  double num = 1, den = 1;
  for (int k = region_lo_[r]; k < region_lo_[r + 1]; ++k) {
    const Vec3& N = region_n_[k];
    const double nn = N.squaredNorm(), d = N.dot(b.axis);
    const double sq = nn > 0 ? d * std::abs(d) : -1.0;
    const double q = nn > 0 ? nn : 1.0;
    if (sq * den < num * q) {
      num = sq;
      den = q;
    }
  }
  const double c2 = num / den;
  const double cmin = c2 >= 0 ? std::sqrt(c2) : -std::sqrt(-c2);
  b.cone = std::acos(std::clamp(cmin, -1.0, 1.0));
}

// Regions a and b are adjacent and flat together (at the last cull).
bool SelfCollision::flat_together(int a, int b) const {
  for (int k = adj_lo_[a]; k < adj_lo_[a + 1]; ++k)
    if (adj_[k] == b) return adj_together_[k] != 0;
  return false;
}

// Every region's box and cone (region_box), whether it is flat, and which of its adjacent
// regions are flat together with it, on the pool.
void SelfCollision::region_shapes(const Cloth& cloth, const std::vector<Vec3>& x, double reach,
                                  ThreadPool* pool) {
  const int R = regions();
  box_.resize(R);
  region_flat_.resize(R);
  region_n_.resize(region_tri_.size());
  auto boxes = [&](int rb, int re, int) {
    for (int r = rb; r < re; ++r) region_box(cloth, x, reach, r);
  };
  // Adjacent regions flat together: the smallest cone about one axis that holds both regions'
  // cones (its axis on the arc between theirs, as far from each: half the sum of both cones and
  // the angle between the axes; or the wider cone when that holds the other) is flat.
  auto together = [&](int rb, int re, int) {
    for (int a = rb; a < re; ++a) {
      const Box& A = box_[a];
      region_flat_[a] = A.cone < kFlatCone;
      for (int k = adj_lo_[a]; k < adj_lo_[a + 1]; ++k) {
        const Box& B = box_[adj_[k]];
        adj_together_[k] = 0;
        if (!(A.cone < kFlatCone && B.cone < kFlatCone)) continue;
        const double between = std::acos(std::clamp(A.axis.dot(B.axis), -1.0, 1.0));
        adj_together_[k] =
            std::max({A.cone, B.cone, 0.5 * (A.cone + B.cone + between)}) < kFlatCone;
      }
    }
  };
  if (pool) {
    pool->parallel_for(R, boxes);
    pool->parallel_for(R, together);
  } else {
    boxes(0, R, 0);
    together(0, R, 0);
  }
}

// Sweep along x over the boxes sorted by their low end: each overlapping pair either is two
// adjacent regions flat together (no pair between them) or makes both active and is listed
// both ways (conflict_, with its CSR conflict_lo_). A region that is not flat is active too.
void SelfCollision::find_conflicts(std::vector<char>& active) {
  const int R = regions();
  const std::vector<Box>& box = box_;
  active.assign(R, 0);
  for (int r = 0; r < R; ++r) active[r] = !region_flat_[r];
  // The sweep runs along the axis of the boxes' widest spread, over (low end, region) pairs
  // sorted by low end.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int r = 0; r < R; ++r) {
    lo = lo.cwiseMin(box[r].lo);
    hi = hi.cwiseMax(box[r].hi);
  }
  int ax = 0;
  for (int a = 1; a < 3; ++a)
    if (hi[a] - lo[a] > hi[ax] - lo[ax]) ax = a;
  const int ay = (ax + 1) % 3, az = (ax + 2) % 3;
  order_.resize(R);
  for (int r = 0; r < R; ++r) order_[r] = {box[r].lo[ax], r};
  std::sort(order_.begin(), order_.end());
  // The boxes in that order, their sweep axis first (the inner loop reads them in sequence).
  sweep_.resize(R);
  for (int i = 0; i < R; ++i) {
    const Box& B = box[order_[i].second];
    sweep_[i] = {{B.lo[ax], B.hi[ax], B.lo[ay], B.hi[ay], B.lo[az], B.hi[az]}, order_[i].second};
  }
  conflict_.clear();
  for (int i = 0; i < R; ++i) {
    const SweepBox& A = sweep_[i];
    for (int j = i + 1; j < R && sweep_[j].b[0] <= A.b[1]; ++j) {
      const SweepBox& B = sweep_[j];
      if (B.b[2] > A.b[3] || A.b[2] > B.b[3] || B.b[4] > A.b[5] || A.b[4] > B.b[5]) continue;
      const int a = A.r, b = B.r;
      if (flat_together(a, b)) continue;
      active[a] = active[b] = 1;
      conflict_.push_back((uint64_t(a) << 32) | uint64_t(b));
      conflict_.push_back((uint64_t(b) << 32) | uint64_t(a));
    }
  }
  std::sort(conflict_.begin(), conflict_.end());
  conflict_lo_.assign(R + 1, 0);
  for (const uint64_t p : conflict_) ++conflict_lo_[(p >> 32) + 1];
  for (int r = 0; r < R; ++r) conflict_lo_[r + 1] += conflict_lo_[r];
}

// A point (or box lo..hi) of flat region r can be within reach of another region's triangle
// only inside the box of a region r meets otherwise (those boxes are grown by the reach).
bool SelfCollision::meets(int r, const Vec3& lo, const Vec3& hi) const {
  for (int k = conflict_lo_[r]; k < conflict_lo_[r + 1]; ++k) {
    const Box& B = box_[conflict_[k] & 0xffffffffu];
    if ((lo.array() <= B.hi.array()).all() && (B.lo.array() <= hi.array()).all()) return true;
  }
  return false;
}

void SelfCollision::cull(const Cloth& cloth, const std::vector<Vec3>& x, double reach,
                         ThreadPool* pool) {
  const auto& tris = cloth.topo.triangles;
  const int nt = static_cast<int>(tris.size()), n = cloth.num_vertices();
  if (!region_cull_) {
    build_fans(cloth);
    active_tri_.resize(nt);
    for (int t = 0; t < nt; ++t) active_tri_[t] = t;
    active_vert_.resize(n);
    for (int v = 0; v < n; ++v) active_vert_[v] = v;
    active_regions_ = regions();
    active_tris_ = nt;
    region_flat_.assign(regions(), 0);
    adj_together_.assign(adj_.size(), 0);
    conflict_.clear();
    conflict_lo_.assign(regions() + 1, 0);
    return;
  }
  prepare(cloth);
  region_shapes(cloth, x, reach, pool);
  pause_point();
  std::vector<char> active;
  find_conflicts(active);
  // Tested: the triangles of a folded region, and those of a flat one within reach of a region
  // it meets (no vertex of its own or of a region flat together with it pairs with them); the
  // vertices whose home region is folded, or flat and inside such a box (a vertex pairs only
  // with a triangle of a region its home meets otherwise: see the tests' skip in detect()).
  // Both lists in ascending order, as the hash and the tests take them (the pairs' order).
  active_tri_.clear();
  active_vert_.clear();
  active_regions_ = 0;
  for (int r = 0; r < regions(); ++r) {
    if (!active[r]) continue;
    ++active_regions_;
    for (int k = region_lo_[r]; k < region_lo_[r + 1]; ++k) {
      const int t = region_tri_[k];
      if (region_flat_[r]) {
        const Vec3& a = x[tris[t][0]];
        const Vec3& b = x[tris[t][1]];
        const Vec3& c = x[tris[t][2]];
        if (!meets(r, a.cwiseMin(b).cwiseMin(c).array() - reach,
                   a.cwiseMax(b).cwiseMax(c).array() + reach))
          continue;
      }
      active_tri_.push_back(t);
    }
    for (int k = region_vlo_[r]; k < region_vlo_[r + 1]; ++k) {
      const int v = region_vert_[k];
      if (vertex_region_[v] == r && (!region_flat_[r] || meets(r, x[v], x[v])))
        active_vert_.push_back(v);
    }
  }
  std::sort(active_tri_.begin(), active_tri_.end());
  std::sort(active_vert_.begin(), active_vert_.end());
  active_tris_ = static_cast<int>(active_tri_.size());
}

// The hash of the tested triangles' grown boxes (table_start_, entries_, spheres_; cells of
// 1 / hash_ic_, buckets masked by hash_mask_).
void SelfCollision::build_hash(const Cloth& cloth, const std::vector<Vec3>& x, double reach) {
  const auto& tris = cloth.topo.triangles;
  // Cell size: the mean edge length plus twice the reach, so that a triangle's grown box spans
  // at most two cells per axis. On fine meshes the reach dominates the cell, so where a whole
  // sheet is hashed a vertex's bucket holds ~190 triangles at 128^2 (18 mm cells); the
  // bounding-sphere test below rejects most of them from the entry alone.
  double edge = 0;
  for (const int t : active_tri_) edge += (x[tris[t][1]] - x[tris[t][0]]).norm();
  const double cell = edge / active_tris_ + 2 * reach;
  const double ic = hash_ic_ = 1.0 / cell;
  auto coord = [&](double v) { return static_cast<int>(std::floor(v * ic)); };
  // Table size: a power of two >= 2 x the tested triangles' count.
  uint32_t size = 1;
  while (size < 2u * static_cast<uint32_t>(active_tris_)) size <<= 1;
  const uint32_t mask = hash_mask_ = size - 1;
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
  for (const int t : active_tri_)
    for_cells(t, [&](uint32_t cell) { ++table_start_[bucket(cell, mask) + 1]; });
  for (uint32_t b = 0; b < size; ++b) table_start_[b + 1] += table_start_[b];
  entries_.resize(table_start_[size]);
  fill_.assign(table_start_.begin(), table_start_.end() - 1);
  // Each entry also carries its triangle's bounding sphere (centre, radius + reach) inline, so
  // a vertex rejects the triangles of its bucket that are out of reach without touching the
  // triangle (most of a bucket's candidates: the bucket spans 18 mm at 128^2, the reach sphere
  // 7 mm + the triangle).
  spheres_.resize(entries_.size());
  for (const int t : active_tri_) {
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
}

int SelfCollision::detect(const Cloth& cloth, const std::vector<Vec3>& x, double thickness,
                          double margin, ThreadPool* pool) {
  pairs_.clear();
  shapes_found_ = false;
  const auto& tris = cloth.topo.triangles;
  const int nt = static_cast<int>(tris.size());
  if (nt == 0) return 0;
  const auto& flags = cloth.state.flags;
  const double reach = thickness + margin;
  cull(cloth, x, reach, pool);
  shapes_found_ = region_cull_;
  if (active_tris_ == 0) return 0;
  pause_point();  // (a detection on a cook-ahead worker waits here while a tick runs)
  build_hash(cloth, x, reach);
  pause_point();
  const double ic = hash_ic_;
  const uint32_t mask = hash_mask_;
  auto coord = [&](double v) { return static_cast<int>(std::floor(v * ic)); };
  // Per triangle its first corner a, unit normal n and the vectors g1, g2 with barycentric
  // coordinates b1 = g1 . (p - a), b2 = g2 . (p - a) of p's projection (g = 0: degenerate):
  // each candidate then costs three dot products.
  pre_.resize(nt);
  auto frames = [&](int b, int e, int) {
    for (int i = b; i < e; ++i) {
      const int t = active_tri_[i];
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
    pool->parallel_for(active_tris_, frames);
  else
    frames(0, active_tris_, 0);
  pause_point();
  // Pass 2: each vertex against the triangles of its cell's bucket. With a pool the vertices run
  // in one contiguous part per thread, each into its own list, joined in part order: the pairs
  // of one thread in the same order.
  auto fixed = [&](int v) {
    return (flags[v] & (kFlagPinned | kFlagPinched | kFlagKinematic)) != 0;
  };
  // A vertex of a flat region skips the triangles of that region and of the regions it is flat
  // together with (the cull's reason: no pair lies there).
  const int32_t* origin =
      cloth.topo.vertex_origin.size() == x.size() ? cloth.topo.vertex_origin.data() : nullptr;
  auto test = [&](int ib, int ie, std::vector<SelfContact>& out) {
    // One vertex's pairs: whether each projects inside its triangle.
    std::vector<std::pair<SelfContact, bool>> mine;
    for (int i = ib; i < ie; ++i) {
      mine.clear();
      const int v = active_vert_[i];
      if (flags[v] & (kFlagNoCollide | kFlagKinematic)) continue;
      const int home = region_cull_ ? vertex_region_[v] : -1;
      const bool flat = home >= 0 && region_flat_[home];
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
        if (flat && (home == region_of_[t] || flat_together(home, region_of_[t]))) continue;
        const auto& T = tris[t];
        if (T[0] == v || T[1] == v || T[2] == v) continue;
        // A vertex and a corner made from one vertex (the two sides of a cut or slit, which
        // coincide where it was made): they are one point of the cloth, with no side to keep.
        if (origin &&
            (origin[T[0]] == origin[v] || origin[T[1]] == origin[v] || origin[T[2]] == origin[v]))
          continue;
        const TriFrame& f = pre_[t];
        const Vec3 r = p - f.a;
        const double d = f.n.dot(r);
        if (std::abs(d) >= reach || f.n.isZero()) continue;  // far from the plane (or degenerate)
        const double b1 = f.g1.dot(r), b2 = f.g2.dot(r);
        const bool inside = b1 >= 0 && b2 >= 0 && b1 + b2 <= 1;
        if (!inside) {
          // Over an edge or a corner: kept within kOverEdgeTan of the normal and the reach, and
          // not across a crease of the vertex's own sheet (a corner of the triangle is one of
          // its neighbours). First the distance to the line of an edge it is beyond, -b_k / |g_k|
          // (the barycentric gradients g0 = -g1 - g2, g1, g2): a lower bound, without a root.
          const double lim2 = kOverEdgeTan * kOverEdgeTan * d * d;
          if ((b1 < 0 && b1 * b1 > lim2 * f.g1.squaredNorm()) ||
              (b2 < 0 && b2 * b2 > lim2 * f.g2.squaredNorm()) ||
              (b1 + b2 > 1 && (b1 + b2 - 1) * (b1 + b2 - 1) > lim2 * (f.g1 + f.g2).squaredNorm()))
            continue;
          const double bary[3] = {1 - b1 - b2, b1, b2};
          const Vec3 corner[3] = {f.a, x[T[1]], x[T[2]]};
          const double s = outside_distance(p - d * f.n, corner, bary);
          if (s > kOverEdgeTan * std::abs(d) || s * s + d * d >= reach * reach) continue;
          if (near_in_mesh(cloth, v, t)) continue;
        }
        if (fixed(v) && fixed(T[0]) && fixed(T[1]) && fixed(T[2])) continue;
        // Skip duplicates (a triangle can sit in the bucket twice via two cells hashing alike).
        bool dup = false;
        for (const auto& m : mine)
          if (m.first.triangle == t) dup = true;
        if (!dup) mine.push_back({{v, t, d >= 0 ? 1.0 : -1.0}, inside});
      }
      // A pair over an edge is left out where a triangle that shares a corner with its own holds
      // the vertex inside its prism (a flat layer: the neighbours of the triangle below).
      for (const auto& [pair, inside] : mine) {
        bool held = false;
        for (const auto& o : mine)
          held = held || (!inside && o.second &&
                          shares_corner(tris[pair.triangle], tris[o.first.triangle]));
        if (!held) out.push_back(pair);
      }
    }
  };
  if (!pool || pool->size() < 2) {
    test(0, static_cast<int>(active_vert_.size()), pairs_);
  } else {
    part_pairs_.resize(pool->size());
    pool->parallel_parts(static_cast<int>(active_vert_.size()), [&](int vb, int ve, int part) {
      part_pairs_[part].clear();
      test(vb, ve, part_pairs_[part]);
    });
    for (const auto& part : part_pairs_) pairs_.insert(pairs_.end(), part.begin(), part.end());
  }
  return static_cast<int>(pairs_.size());
}

bool SelfCollision::keeps_pairs(const Cloth& cloth, const std::vector<Vec3>& x,
                                const std::vector<Vec3>& x0, double thickness, double margin,
                                ThreadPool* pool) {
  if (!region_cull_ || x.size() != x0.size() ||
      x.size() != static_cast<size_t>(cloth.num_vertices()))
    return false;
  if (!shapes_found_ || region_version_ != cloth.topology_version ||
      region_tris_ != static_cast<int>(cloth.topo.triangles.size())) {
    // Pairs put back (a saved state): the regions' shapes at x0, as the detection that found
    // them made them.
    prepare(cloth);
    region_shapes(cloth, x0, thickness + margin, pool);
    std::vector<char> active;
    find_conflicts(active);
    shapes_found_ = true;
  }
  const int R = regions();
  motion_.resize(R);
  auto regions_moved = [&](int rb, int re, int) {
    for (int r = rb; r < re; ++r) {
      double lo[3], hi[3], most2 = 0;  // (registers)
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::numeric_limits<double>::infinity();
        hi[a] = -lo[a];
      }
      for (int k = region_vlo_[r]; k < region_vlo_[r + 1]; ++k) {
        const int v = region_vert_[k];
        const Vec3 d = x[v] - x0[v];
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], d[a]);
          hi[a] = std::max(hi[a], d[a]);
        }
        most2 = std::max(most2, d.squaredNorm());
      }
      motion_[r] = {Vec3(lo[0], lo[1], lo[2]), Vec3(hi[0], hi[1], hi[2]), most2};
    }
  };
  if (pool)
    pool->parallel_for(R, regions_moved);
  else
    regions_moved(0, R, 0);
  // A vertex and a triangle came closer by at most the smaller of the diagonal of their regions'
  // displacement box and twice their largest displacement (XpbdSolver::self_due's bound).
  auto beyond = [](const Motion& A, const Motion& B, double limit) {
    const Vec3 lo = A.lo.cwiseMin(B.lo), hi = A.hi.cwiseMax(B.hi);
    return std::min((hi - lo).squaredNorm(), 4 * std::max(A.most2, B.most2)) > limit * limit;
  };
  Motion all = {Vec3::Constant(std::numeric_limits<double>::infinity()),
                Vec3::Constant(-std::numeric_limits<double>::infinity()), 0.0};
  for (int r = 0; r < R; ++r) {
    if (region_vlo_[r] == region_vlo_[r + 1]) continue;
    if (beyond(motion_[r], motion_[r], margin)) return false;  // within one region
    all = {all.lo.cwiseMin(motion_[r].lo), all.hi.cwiseMax(motion_[r].hi),
           std::max(all.most2, motion_[r].most2)};
  }
  if (R > 0 && beyond(all, all, thickness + 2 * margin)) return false;
  // Regions whose grown boxes met: adjacent ones, and the others listed by the cull.
  for (int a = 0; a < R; ++a) {
    for (int k = adj_lo_[a]; k < adj_lo_[a + 1]; ++k)
      if (adj_[k] > a && beyond(motion_[a], motion_[adj_[k]], margin)) return false;
    for (int k = conflict_lo_[a]; k < conflict_lo_[a + 1]; ++k) {
      const int b = static_cast<int>(conflict_[k] & 0xffffffffu);
      if (b > a && beyond(motion_[a], motion_[b], margin)) return false;
    }
  }
  return true;
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
