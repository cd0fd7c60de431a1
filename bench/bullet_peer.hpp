// The peer of the solver benchmark (solvers_bench): Bullet's soft body (Debian libbullet-dev,
// btSoftBody position-based links) on the hanging-sheet scene of sim/testbeds/testbed.hpp, with the
// same vertices, triangles, lumped masses, pins, gravity and frame length as our solvers. Matching
// (docs/solvers.md, "Measured figures"): one Bullet link per triangle edge of the cloth; each
// link's kLST is derived from the FEM's stiffness along that edge (warp, weft, or the diagonal's
// shear stiffness 2G), the substep h and the link's reduced mass:
//   s = k h^2 / (m_ab + k h^2)  (the fraction of the violation an implicit spring removes in
//   one step), kLST = 1 - (1 - s)^(1/iterations) (so `iterations` passes remove the same).
// No damping (fabric damping 0 -> kDP 0), no aerodynamics (kLF = kDG = 0, air density 0), no
// self-collision, no bending constraints (bullet_peer_bench --bending measures their effect).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace drape::bench {

struct PeerRow {
  int resolution = 0;
  double dt = 0;  // substep (s)
  int iterations = 0;
  double ms_per_frame = 0;
  bool stable = true;
  // Final positions, in the same vertex order as make_hanging_sheet(res).cloth.
  std::vector<Eigen::Vector3d> positions;
};

// Runs Bullet's soft body on make_hanging_sheet(res) for the scene's duration in 1/90 s frames,
// each frame `substeps` Bullet steps of 1/(90 substeps) s with `iterations` position-solver
// iterations. Wall time per frame in ms_per_frame. stable = every position finite and within
// 50 m of the start. Without Bullet at build time: stable = false, positions empty.
PeerRow run_bullet_sheet(int res, int substeps, int iterations);

// Options for exploring the matching (the driver uses them; run_bullet_sheet uses defaults).
struct PeerOptions {
  double klst_scale = 1.0;  // multiplies the derived per-link kLST (clamped to [0, 1])
  double klst_fixed = 0.0;  // > 0: every link gets this kLST instead of the derived one
  bool bending = false;     // Bullet's bending links (distance-2 links, kLST from bending)
  double kdp = 0.0;         // Bullet's velocity damping coefficient kDP
};
PeerRow run_bullet_sheet(int res, int substeps, int iterations, const PeerOptions& opt);

}  // namespace drape::bench
