// A two-level (coarse-grid) Newton correction of the static equilibrium, for local solvers.
//
// Gauss-Seidel solvers (XPBD, VBD) remove a residual's short wavelengths in a few sweeps but
// its long ones only in O(resolution^2) sweeps. This correction works on the long ones
// directly: with a prolongation P from a coarse lattice laid over the material coordinates
// (bilinear weights, nodes every `factor` nominal fine edges, separately per group of vertices
// so that pieces cut apart are not coupled), it solves the Galerkin system
//   (P^T H P) d = -P^T grad E(x)
// (H the PSD-projected Hessian of the cloth energy: membrane, bending, springs, friction when
// set) by a sparse Cholesky of the small coarse matrix, and moves x by P d with a backtracking
// line search on E. A vertex in contact (within contact_reach of its plane) moves only along
// its plane: its prolongation row is projected, so the contact's normal stiffness never enters
// the coarse model (with it, the nodes around the contact zone locked: measured, the coarse
// residual stalled at 10 % of its start).
//
// What it cannot do (measured on the form drape): converge alone.
// A bilinear field moving along a soft isometric mode (a flap swinging, a fold rolling)
// stretches the membrane at second order, so the coarse model sees those modes as stiff
// (membrane locking): on its own it stops where the remaining error is 99 % in the coarse space
// and 1.3 mJ of energy away. It is a correction between the fine solver's sweeps, which relax
// the membrane after each step (sim/rest/equilibrium_finisher.hpp).
// CoarseOptions::rotations gives every node a small rotation too, so that locally rigid motions
// of a curved patch lie in the coarse space (with Gauss-Seidel sweeps between corrections, 128^2
// drape 2.81 -> 0.72 mm from equilibrium in 20 cycles; 1.39 mm with translations only). Its
// Galerkin matrix is formed from the fine Hessian's 3x3 blocks. Positions only: the caller decides
// what happens to velocities.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/energy/energy.hpp"

namespace drape::sim {

struct CoarseOptions {
  int factor = 4;  // coarse lattice spacing in nominal fine edges (ClothTopology::spacing)
  // A contact vertex closer than this to its plane (m) slides on the plane in the coarse space.
  double contact_reach = 1e-4;
  int line_search_steps = 8;  // halvings of the step before giving up
  // Each node carries a small rotation besides its translation: a vertex moves by
  // sum_n w_n (t_n + theta_n x (x_i - c_n)) (c_n the node's weighted centre at x), so locally
  // rigid motions of a curved patch, which a bilinear field of translations can only follow by
  // stretching the membrane, lie in the coarse space (6 unknowns per node instead of 3).
  bool rotations = false;
};

struct CoarseStats {
  bool applied = false;                        // a step that lowered E was taken
  int nodes = 0;                               // coarse nodes
  double energy_before = 0, energy_after = 0;  // J
  double alpha = 0;                            // accepted step length (1: the full step)
  double max_move = 0;                         // largest vertex displacement (m)
  double residual = 0;                         // |P^T grad E|_inf before the step (N)
  double build_ms = 0, assemble_ms = 0, factor_ms = 0, total_ms = 0;
  bool rebuilt = false;  // the lattice and its pattern were built for this call
  bool reused = false;   // the last call's matrix and prolongation were used
};

// The cloth's nominal grid spacing (m); a cloth without one (imported, remeshed): its mean
// material edge; 0 without triangles.
double nominal_edge(const Cloth& cloth);

class CoarseCorrection {
 public:
  explicit CoarseCorrection(CoarseOptions opt = {});
  ~CoarseCorrection();
  CoarseOptions& options() { return opt_; }

  // One correction of x. `group[i]` >= 0: vertex i may move and belongs to that group (pieces
  // are coarsened separately); -1: it stays. The energy must be up to date for the cloth, with
  // its contacts (and friction, if wanted) set for x. No element may join two groups (pieces
  // are connected components: std::invalid_argument otherwise). Allocates only when the
  // topology, the groups or the lattice factor changed since the last call.
  // `reuse`: keep the last call's prolongation and factorised matrix (same lattice; x moved
  // little since), i.e. a step in the same subspace with a slightly stale model, which the line
  // search keeps a descent step; it skips the assembly and the factorisation.
  CoarseStats apply(const Cloth& cloth, const ClothEnergy& energy, const std::vector<int>& group,
                    std::vector<Vec3>& x, bool reuse = false);
  // Diagnostics: the least-squares fit P d of a vertex field f by the coarse space of the last
  // apply() (same lattice, same contact projection); false when there is none.
  bool fit(const std::vector<Vec3>& f, std::vector<Vec3>& fitted);

 private:
  struct Impl;
  CoarseOptions opt_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drape::sim
