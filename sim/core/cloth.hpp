// The cloth: a triangle mesh whose vertices keep their flat material coordinates forever,
// split into an immutable-between-edits topology and the per-step state (structure of arrays).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "sim/core/fabric.hpp"
#include "sim/core/types.hpp"

namespace drape::sim {

// Per-vertex flags (bit set).
enum VertexFlag : uint8_t {
  kFlagPinned = 1u << 0,     // fixed in place (pin, end of move, boundary condition)
  kFlagPinched = 1u << 1,    // attached to a hand: position driven by the hand
  kFlagKinematic = 1u << 2,  // driven from outside: excluded from dynamics and collision (move)
  kFlagFrozen = 1u << 3,     // at rest: skipped by solvers until woken
  kFlagNoCollide = 1u << 4,  // skip collision for this vertex
};

// Everything that changes only on a topology edit (slit, cut, sew, remesh).
struct ClothTopology {
  std::vector<std::array<int32_t, 3>> triangles;  // counter-clockwise in material (u, v) space
  // Flat material coordinates in metres: u along the weft, v along the warp (grain). Kept
  // through every edit so a pattern can always be read back.
  std::vector<Vec2> material;
  std::vector<int32_t> vertex_zone;    // dart zone (0 when there are no slits)
  std::vector<int32_t> triangle_zone;  // dart zone per triangle
  std::vector<int32_t> vertex_origin;  // vertex this one was duplicated from (itself if original)
  double spacing = 0.01;               // nominal edge length of the generated grid (m)
  int grid_nx = 0, grid_ny = 0;        // > 0 when generated as a grid: vertex(i, j) = j * nx + i

  int num_vertices() const { return static_cast<int>(material.size()); }
  int num_triangles() const { return static_cast<int>(triangles.size()); }
};

// What a step changes.
struct ClothState {
  std::vector<Vec3> x;           // positions (m, stage space)
  std::vector<Vec3> x_prev;      // positions at the previous step (Verlet, velocity estimates)
  std::vector<Vec3> v;           // velocities (m/s)
  std::vector<double> mass;      // lumped mass (kg)
  std::vector<double> inv_mass;  // 0 for fixed vertices
  std::vector<uint8_t> flags;    // VertexFlag bits
  double time = 0.0;             // simulated time (s)
};

// Vertex → incident triangles and component labels, kept with the cloth so topology edits
// need not rebuild them (sim/ops/cut.cpp builds it on demand with ensure_incidence() and updates it
// in place on each split). Valid only while `version == Cloth::topology_version` and the sizes
// match: any other edit bumps topology_version and so invalidates it (it is rebuilt when next
// needed). Nothing else needs to maintain it.
struct ClothIncidence {
  bool built = false;
  uint64_t version = 0;       // topology_version it describes
  int32_t num_triangles = 0;  // triangle count it describes
  // Triangles of vertex v: tris[start[v] .. start[v] + count[v]), ascending (tris has slack).
  std::vector<int32_t> start, count, tris;
  std::vector<int32_t> component;  // connected-component label per vertex (-1: in no triangle)
  int32_t components = 0;          // number of labels
};

struct Cloth {
  ClothTopology topo;
  ClothState state;
  FabricParams fabric;
  uint64_t topology_version = 1;  // incremented on each topology edit (solvers re-cook then)
  ClothIncidence incidence;       // kept adjacency (see above); may be stale (not built)

  int num_vertices() const { return topo.num_vertices(); }
  // True when vertex i takes part in dynamics (not pinned, pinched, kinematic or frozen).
  bool is_free(int i) const {
    return (state.flags[i] & (kFlagPinned | kFlagPinched | kFlagKinematic)) == 0;
  }
  // Duplicates vertex `src` (same position, material coordinates, zone; origin = src's
  // origin) and returns the new index. Masses are not re-lumped: call relump_masses().
  int duplicate_vertex(int src);
  // Recomputes lumped masses from triangle areas in material space and the areal density,
  // and inverse masses (0 where pinned/pinched/kinematic).
  void relump_masses();
  // Marks a topology change: bumps topology_version.
  void topology_changed() { ++topology_version; }
  // Checks array sizes, index ranges and finiteness; returns an empty string when valid.
  std::string validate() const;
};

// A rectangular panel of width (along weft) x height (along warp), grid spacing.
struct PanelSpec {
  double width = 0.5;     // m, along u (weft)
  double height = 0.5;    // m, along v (warp)
  double spacing = 0.01;  // m; the grid has round(width/spacing)+1 columns
  // Resolution override: when > 0, the grid has exactly nx x ny vertices.
  int nx = 0, ny = 0;
};

// Builds the flat panel: material coordinates (u, v) from (0, 0) at the bottom-left corner,
// triangles alternating their diagonal (criss-cross) to avoid a preferred shear direction.
Cloth make_panel(const PanelSpec& spec, const FabricParams& fabric);

// Initial state 1: spread open. Places the flat panel in 3D with material
// point (u, v) at origin + u * axis_u + v * axis_v (axes need not be unit: they are normalised).
void place_spread(Cloth& cloth, const Vec3& origin, const Vec3& axis_u, const Vec3& axis_v);
// Initial state 2: rolled up. The panel is rolled around an axis parallel to
// axis_u, starting from its v = 0 edge, into a spiral of the given inner radius; the
// v = height edge ends up at `origin` + height-dependent wrap.
void place_rolled(Cloth& cloth, const Vec3& origin, const Vec3& axis_u, const Vec3& up,
                  double inner_radius);

// 64-bit FNV-1a hash of positions (bitwise), flags and topology: equal hashes mean equal states.
uint64_t state_hash(const Cloth& cloth);

}  // namespace drape::sim
