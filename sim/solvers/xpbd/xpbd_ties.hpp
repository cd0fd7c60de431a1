// Ties: vertex a held on the point (1 - t) x_b0 + t x_b1 of another vertex or edge, a hard
// (zero-compliance) XPBD constraint C = x_a - (1 - t) x_b0 - t x_b1 = 0 of rest length zero.
// A sewn garment's seams are ties where the two sides' vertices do not coincide (different
// vertex counts) or belong to pieces whose flat frames differ, so that they cannot be one vertex
// (a vertex has one material coordinate). XpbdSolver::set_ties projects them in every substep.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/core/types.hpp"

namespace drape::sim::xpbd {

struct Tie {
  int32_t a = 0, b0 = 0, b1 = 0;
  double t = 0;  // 0: onto vertex b0
};

// |C| of one tie at positions x (m).
double tie_gap(const Tie& tie, const std::vector<Vec3>& x);
// The largest |C| over the ties (0 when there are none).
double max_tie_gap(const std::vector<Tie>& ties, const std::vector<Vec3>& x);

// One Gauss-Seidel pass over the ties: each moves its vertices by w_i grad_i C lambda with
// lambda = -C / sum w_i |grad_i C|^2 (inverse masses w; a tie whose vertices are all fixed is
// left). Appends each vertex it moved to `moved` when given (duplicates possible).
void project_ties(const std::vector<Tie>& ties, std::vector<Vec3>& x, const double* w,
                  std::vector<int>* moved);

}  // namespace drape::sim::xpbd
