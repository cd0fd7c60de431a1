// Cloth self-collision, off unless the scene asks for it: vertex-triangle proximity pairs found
// through a spatial hash of the triangles' bounds, and their projection (each vertex kept at least
// `thickness` from the triangle's plane, on the side it was on when the pair was found).
//
// Detection: every triangle is entered in the hash cells its bounding box, grown by the reach
// (thickness + margin), overlaps; each vertex looks up its own cell and tests the triangles
// there that do not contain it: the pair is kept when the vertex is within the reach of the
// triangle's plane and projects inside the triangle. The side (sign of the distance) is taken
// then, from a state assumed free of intersections, and kept until the next detection. A pair
// farther than the reach cannot come within `thickness` before any vertex has moved margin / 2,
// which is when the solver detects again (XpbdSolver's contact reuse rule).
// Projection: C = side n . (x_v - sum_k b_k x_k) - thickness >= 0 (n the triangle's unit
// normal, b the barycentric coordinates of the vertex's projection, both taken as constant in
// the correction), inverse-mass weighted, one Gauss-Seidel pass.
// Limits (docs/solvers.md): vertex-face pairs only (no edge-edge test: two layers can still
// cross where edges pass each other between vertices, on meshes much coarser than the
// thickness); the side is not repaired once a layer has passed through; a triangle stretched over
// more than 8 hash cells per axis is entered in the first 8 only.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/core/cloth.hpp"

namespace drape::sim {

struct SelfContact {
  int32_t vertex, triangle;
  double side;  // +1: the vertex is on the triangle's normal side, -1: behind it
};

class SelfCollision {
 public:
  // Finds the vertex-triangle pairs within thickness + margin of each other. Vertices that are
  // not free (pinned, kinematic, no-collide) still repel free ones; pairs of two fixed ends
  // are skipped. Returns the number of pairs.
  int detect(const Cloth& cloth, const std::vector<Vec3>& x, double thickness, double margin);
  // One projection pass over the pairs: pushes apart those closer than `thickness`. w: inverse
  // mass per vertex (0 = fixed). Returns the largest correction applied (m).
  double project(const Cloth& cloth, std::vector<Vec3>& x, const double* w, double thickness) const;
  const std::vector<SelfContact>& contacts() const { return pairs_; }
  // The per-entry bounding-sphere rejection (on by default; off only to measure it: the same
  // pairs are found either way).
  void set_sphere_test(bool on) { sphere_test_ = on; }
  // Smallest side-signed distance minus thickness over the pairs at x (< 0: a pair too close
  // or crossed); +infinity when there are no pairs.
  double min_clearance(const Cloth& cloth, const std::vector<Vec3>& x, double thickness) const;

 private:
  std::vector<SelfContact> pairs_;
  // The hash: table_start_[b] .. table_start_[b + 1] index entries_ (triangle ids).
  std::vector<int32_t> table_start_, entries_, fill_;
  struct Sphere {
    float x, y, z, r;  // an entry's triangle: bounding sphere centre, radius + reach (padded)
  };
  std::vector<Sphere> spheres_;  // parallel to entries_
  bool sphere_test_ = true;
  struct TriFrame {
    Vec3 a, n, g1, g2;  // corner, unit normal, barycentric gradients (detect())
  };
  std::vector<TriFrame> pre_;
};

}  // namespace drape::sim
