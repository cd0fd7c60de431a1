// Cloth self-collision, off unless the scene asks for it: vertex-triangle proximity pairs found
// through a spatial hash of the triangles' bounds, and their projection (each vertex kept at least
// `thickness` from the triangle's plane, on the side it was on when the pair was found).
//
// Detection: every triangle is entered in the hash cells its bounding box, grown by the reach
// (thickness + margin), overlaps; each vertex looks up its own cell and tests the triangles
// there that do not contain it (nor a vertex made from the same one: a cut's other side): the
// pair is kept when the vertex is within the reach of the triangle's plane and projects inside
// the triangle, or, projecting outside it (over an edge or a corner of a convex layer, between
// the prisms of its triangles), is within the reach of the triangle and within 15 deg of its
// normal from the triangle's nearest point (a vertex over a ridge pairs with the triangles on
// both sides). The side (sign of the distance) is taken then, from a state assumed free of
// intersections, and kept until the next detection. A pair farther than the reach cannot come
// within `thickness` before the vertex and the triangle have come `margin` closer, which the
// solver bounds from the displacements since the detection (XpbdSolver::self_due, keeps_pairs
// below) to detect again in time.
// Projection: C = side n . (x_v - sum_k b_k x_k) - thickness >= 0 (n the triangle's unit
// normal, b the barycentric coordinates of the vertex's projection, both taken as constant in
// the correction; outside the triangle b is clamped onto it), inverse-mass weighted, one
// Gauss-Seidel pass.
// Limits (docs/solvers.md): vertex-face pairs only (no edge-edge test: two layers can still
// cross where edges pass each other between vertices, on meshes much coarser than the
// thickness); a vertex over a ridge that turns by more than 30 deg between two triangles is
// paired with neither until it slides over one and the next detection; the side is not repaired
// once a layer has passed through; a triangle stretched over more than 8 hash cells per axis is
// entered in the first 8 only.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "sim/core/cloth.hpp"

namespace drape::sim {

class ThreadPool;  // sim/core/thread_pool.hpp

struct SelfContact {
  int32_t vertex, triangle;
  double side;  // +1: the vertex is on the triangle's normal side, -1: behind it
};

class SelfCollision {
 public:
  // Finds the vertex-triangle pairs within thickness + margin of each other. Vertices that are
  // not free (pinned, kinematic, no-collide) still repel free ones; pairs of two fixed ends
  // are skipped. Returns the number of pairs.
  // With a pool, the triangles' frames and the vertex tests run on it (the same pairs in the
  // same order).
  int detect(const Cloth& cloth, const std::vector<Vec3>& x, double thickness, double margin,
             ThreadPool* pool = nullptr);
  // One projection pass over the pairs: pushes apart those closer than `thickness`. w: inverse
  // mass per vertex (0 = fixed). Returns the largest correction applied (m). moved (optional)
  // gets the vertices of every pair it corrected appended (repeats included).
  double project(const Cloth& cloth, std::vector<Vec3>& x, const double* w, double thickness,
                 std::vector<int>* moved = nullptr) const;
  const std::vector<SelfContact>& contacts() const { return pairs_; }
  // The cloth's split into regions (per topology: see below), made ahead of the first detection
  // on it (CookAheadSolver's worker); the detection makes it otherwise.
  void prepare(const Cloth& cloth);
  int region_builds() const { return region_builds_; }  // splits made (one per topology)
  // Puts pairs found earlier back (a solver's saved state); clear() forgets them.
  void set_contacts(std::vector<SelfContact> pairs) {
    pairs_ = std::move(pairs);
    shapes_found_ = false;
  }
  void clear() {
    pairs_.clear();
    shapes_found_ = false;
  }
  // Whether the pairs the last detection found (at x0, with this thickness and margin) are still
  // all the pairs that can be within `thickness` at x, by region: the displacements since x0
  // bound how much closer a vertex and a triangle came, per pair of regions whose boxes met at
  // x0 (within the margin, as the solver's bound over the whole cloth) and over the whole cloth
  // for regions that were farther apart (within thickness + 2 margin: their boxes grown by the
  // reach did not meet). x0 must be the positions the pairs were found at; pairs put back by
  // set_contacts() have the regions' shapes made at x0 here. False without the region cull.
  bool keeps_pairs(const Cloth& cloth, const std::vector<Vec3>& x, const std::vector<Vec3>& x0,
                   double thickness, double margin, ThreadPool* pool = nullptr);
  // The per-entry bounding-sphere rejection (on by default; off only to measure it: the same
  // pairs are found either way).
  void set_sphere_test(bool on) { sphere_test_ = on; }
  // The region cull (on by default; off only to measure and test it): see below.
  void set_region_cull(bool on) { region_cull_ = on; }
  // Regions and triangles the last detection tested (the others were culled).
  int regions() const { return std::max(0, static_cast<int>(region_lo_.size()) - 1); }
  int active_regions() const { return active_regions_; }
  int active_triangles() const { return active_tris_; }
  // Smallest side-signed distance minus thickness over the pairs at x (< 0: a pair too close
  // or crossed); +infinity when there are no pairs.
  double min_clearance(const Cloth& cloth, const std::vector<Vec3>& x, double thickness) const;

 private:
  std::vector<SelfContact> pairs_;
  std::vector<std::vector<SelfContact>> part_pairs_;  // per pool part (detect with a pool)
  // The hash: table_start_[b] .. table_start_[b + 1] index entries_ (triangle ids).
  std::vector<int32_t> table_start_, entries_, fill_;
  double hash_ic_ = 1;  // 1 / the cell's side
  uint32_t hash_mask_ = 0;
  void build_hash(const Cloth& cloth, const std::vector<Vec3>& x, double reach);
  struct Sphere {
    float x, y, z, r;  // an entry's triangle: bounding sphere centre, radius + reach (padded)
  };
  std::vector<Sphere> spheres_;  // parallel to entries_
  bool sphere_test_ = true;
  // The region cull: the cloth is split once per topology into regions (the triangles of one
  // cell of a material-space grid 6 edges wide that are connected to each other). At each
  // detection a region whose triangle normals lie within kFlatCone (37 deg) of their mean is flat
  // (a height field over that axis: none of its vertices is within reach above one of its own
  // triangles); a flat region whose box, grown by the reach, meets no other region's, or meets
  // only adjacent regions that are flat together with it, has no pair and is left out of the
  // hash and the vertex tests. Only the regions that fold, or that lie against another layer,
  // are tested, and of a flat one only the triangles and vertices inside the box of a region
  // it meets.
  bool region_cull_ = true;
  uint64_t region_version_ = 0;
  int region_tris_ = -1;
  int region_builds_ = 0;
  std::vector<int32_t> region_of_;                 // per triangle
  std::vector<int32_t> region_lo_;                 // per region: its first entry in region_tri_
  std::vector<int32_t> region_tri_;                // triangles grouped by region
  std::vector<int32_t> region_vlo_, region_vert_;  // per region its vertices (CSR)
  // A vertex's home region (that of the first triangle around it; -1: in none). A vertex of a
  // flat region tests no triangle of its home region nor of a region flat together with it.
  std::vector<int32_t> vertex_region_;
  // The triangles and vertices the last detection tested (ascending).
  std::vector<int32_t> active_tri_, active_vert_;
  std::vector<Vec3> region_n_;  // per entry of region_tri_: its triangle's area normal (cull)
  struct Box {
    Vec3 lo, hi, axis;
    double cone;  // half-angle of the normals about the axis (pi: not flat)
  };
  std::vector<Box> box_;  // per region, at the last detection
  std::vector<char> region_flat_;
  // Per region its adjacent regions (CSR: adj_lo_, adj_; per topology) and whether each is flat
  // together with it (per detection).
  std::vector<int32_t> adj_lo_, adj_;
  std::vector<char> adj_together_;
  // Pairs of regions whose boxes meet and that are not flat together, both ways ((a << 32) | b,
  // sorted), and per region a its first pair (CSR).
  std::vector<uint64_t> conflict_;
  std::vector<int32_t> conflict_lo_;
  // find_conflicts' boxes sorted by their low end on the sweep axis: (low end, region), and the
  // boxes in that order (lo, hi on the sweep axis, then on the other two).
  std::vector<std::pair<double, int32_t>> order_;
  struct SweepBox {
    double b[6];
    int32_t r;
  };
  std::vector<SweepBox> sweep_;
  bool flat_together(int a, int b) const;
  // The region shapes (box_, conflict_) are those of the detection that found pairs_.
  bool shapes_found_ = false;
  struct Motion {  // a region's displacements since x0: their box and largest squared length
    Vec3 lo, hi;
    double most2;
  };
  std::vector<Motion> motion_;  // per region (keeps_pairs)
  int active_regions_ = 0, active_tris_ = 0;
  void build_regions(const Cloth& cloth);
  void region_box(const Cloth& cloth, const std::vector<Vec3>& x, double reach, int r);
  void region_shapes(const Cloth& cloth, const std::vector<Vec3>& x, double reach,
                     ThreadPool* pool);
  void find_conflicts(std::vector<char>& active);
  bool meets(int r, const Vec3& lo, const Vec3& hi) const;
  void cull(const Cloth& cloth, const std::vector<Vec3>& x, double reach, ThreadPool* pool);
  struct TriFrame {
    Vec3 a, n, g1, g2;  // corner, unit normal, barycentric gradients (detect())
  };
  std::vector<TriFrame> pre_;
  // Per vertex the triangles around it (CSR; per topology), and whether a corner of triangle t
  // is vertex v's neighbour in the mesh (or v itself).
  std::vector<int32_t> fan_lo_, fan_;
  uint64_t fans_version_ = 0;
  int fans_tris_ = -1;
  void build_fans(const Cloth& cloth);
  bool near_in_mesh(const Cloth& cloth, int v, int t) const;
};

}  // namespace drape::sim
