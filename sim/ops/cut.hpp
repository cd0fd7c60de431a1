// The cut primitive: stroke → points on the cloth surface → a path along mesh
// edges → split by vertex duplication on the left of the cut direction. Material coordinates
// are kept; works on any triangle mesh (grid or already cut), not only on a regular grid.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "sim/core/cloth.hpp"

namespace drape::sim {

// A point on the cloth surface: triangle + barycentric coordinates (deformation independent).
struct SurfacePoint {
  int32_t triangle = -1;
  Vec3 bary{1.0 / 3, 1.0 / 3, 1.0 / 3};
  Vec3 position{0, 0, 0};  // where it is in 3D now
  Vec2 material{0, 0};     // (u, v) in the flat cloth
  double distance = 0;     // from the query point (m)
};

struct CutOptions {
  // Stroke samples farther than this from the cloth surface are off the cloth and dropped.
  double max_distance = 0.05;
  // Laplacian smoothing passes over the stroke (end points kept), and the minimum spacing
  // between kept samples (closer samples are merged): against tracking noise.
  int smoothing_passes = 3;
  double min_sample_spacing = 0.002;
  // A stroke end is extended along the stroke's direction (in material space) to the cloth's
  // edge when it lies within this distance of the edge (m, material; at least one grid spacing)
  // or when the stroke began/ended off the cloth beyond its edge (the sample's nearest cloth
  // point is on the boundary): a stroke drawn across the cloth from edge to edge separates it.
  double edge_snap = 0.02;
};

struct CutResult {
  bool ok = false;
  std::string reason;                  // why nothing was cut (when !ok)
  std::vector<int32_t> path;           // vertex path along mesh edges (pre-split indices)
  std::vector<int32_t> new_vertices;   // duplicates created (left side of the cut)
  std::vector<Vec3> smooth_stroke;     // smoothed stroke in 3D (display)
  std::vector<Vec2> smooth_stroke_uv;  // the same on the flat cloth (pattern outline)
  int components_before = 0, components_after = 0;
  std::array<bool, 2> extended{false, false};  // start / end extended to the cloth's edge
  double ms = 0;                               // time to compute and apply
};

// Builds the cloth's kept incidence (vertex → triangles, component labels; Cloth::incidence)
// when it is not valid for the current topology: O(V + T), once; cuts then keep it valid in
// place, so a cut costs O(path + the pieces it separates), not O(cloth). Returns true when it
// (re)built it. The operations call it after each step so a cut command never pays the build.
bool ensure_incidence(Cloth& cloth);
// ensure_incidence() plus headroom: reserves room for max(1024, V/8) more vertices in every
// per-vertex array and sizes this thread's scratch, so the next cuts neither rebuild nor
// reallocate. Cheap when already prepared (capacity checks); the operations call it after
// every step (sim thread), outside the cut command. Returns true when it changed anything.
bool prepare_for_cuts(Cloth& cloth);

// Nearest point of the cloth surface to p (brute force over triangles).
SurfacePoint nearest_surface_point(const Cloth& cloth, const Vec3& p);

// A path along mesh edges through the anchor vertices, in order (on any triangulation: each leg
// walks edge by edge toward the next anchor, staying close to the straight line between them in
// material space). Consecutive duplicates and loops are removed. Empty when an anchor is
// unreachable.
std::vector<int32_t> edge_path(const Cloth& cloth, const std::vector<int32_t>& anchors);

// Splits the cloth along a vertex path whose consecutive vertices share an edge: each path vertex
// is duplicated and the triangles on the LEFT of the cut direction (in material space) move to the
// duplicate; an interior end (a slit tip) is not duplicated. Masses are re-lumped (only the split
// vertices change: bit-identical to relump_masses()) and topology_version bumped when anything
// changed; the kept incidence is updated in place.
CutResult cut_path(Cloth& cloth, const std::vector<int32_t>& path);

// The whole cut from a stroke in 3D (hand samples): smoothed, projected onto the surface,
// anchors = nearest vertex of each projected point, ends extended to the edge when the stroke
// comes from / goes beyond it (CutOptions::edge_snap), path along edges, split.
CutResult cut_along(Cloth& cloth, const std::vector<Vec3>& stroke_points,
                    const CutOptions& options = {});

// The same from a stroke given in material space (u, v): for predetermined lines and tests.
CutResult cut_along_material(Cloth& cloth, const std::vector<Vec2>& stroke_uv);

// A straight stroke across the whole cloth along u, from 1 cm before its smallest material u to
// 1 cm past its largest, at v = vmin + at (vmax - vmin) over the cloth's material extent; cut
// with cut_along_material. For benchmarks and tests that cut a cloth in two.
CutResult cut_across_material(Cloth& cloth, double at);

// Connected components of the mesh (vertices joined by triangle edges; isolated vertices
// count as their own component only when `count_isolated`).
int count_components(const Cloth& cloth, bool count_isolated = false);
// Component label per vertex (-1 for vertices in no triangle).
std::vector<int32_t> component_labels(const Cloth& cloth, int* count = nullptr);

}  // namespace drape::sim
