// The study's baseline (method 3.2-3.3): mass-spring forces (eq. 3-1) with gravity (3-2, 3-3),
// damped Verlet integration (3-4) and the collision response force of eq. 3-7, as published.
// Kept as the reference point for every later speed and accuracy claim.
#pragma once

#include <vector>

#include "sim/energy/collision.hpp"
#include "sim/energy/springs.hpp"
#include "sim/solvers/solver.hpp"

namespace drape::sim {

struct VerletParams {
  // Substeps per step() call. <= 0: automatic, the fewest that keep h below
  // safety * 2 / sqrt(lambda_max) with lambda_max bounded by Gershgorin (max_eigenvalue_bound).
  int substeps = 0;
  double safety = 0.9;
  // Damping alpha of eq. 3-4. The study gives no value; alpha <= 0 derives it from a rate per
  // second so that the damping does not change with the substep: alpha = exp(-air_drag h).
  double alpha = 0;
  double air_drag = 1.0;         // 1/s
  double stiffness_scale = 1.0;  // 1 = the fabric's stiffness (build_springs)
  bool collide = true;
  // true: the baseline's response as published, a force, so the displacement it causes also
  // becomes velocity in the next Verlet step (the 1 s drop of Drop.PanelOnFormStaysOutside
  // passes with it, at most 0.26 mm into the shell). false (default): the predicted x(t+h) is
  // projected to the offset surface after the Verlet update and x(t) stays the previous position,
  // so the velocity loses its component into the object (a position projection; docs/sim-core.md).
  bool response_as_velocity = false;
  // When the state turns non-finite, restore the frame's start state and
  // report `diverged` instead of leaving NaNs in the cloth.
  bool rollback_on_divergence = true;
};

class VerletSolver : public Solver {
 public:
  explicit VerletSolver(VerletParams p = {}) : p_(p) {}
  std::string name() const override { return "verlet-baseline"; }
  StepStats step(Cloth& cloth, const SceneObjects& scene, double dt) override;

  const VerletParams& params() const { return p_; }
  VerletParams& params() { return p_; }
  // Springs of the cooked topology (after the first step, or cook()).
  const Springs& springs() const { return springs_; }
  // Rebuilds the springs for the cloth's topology (step() does it when the version changes).
  void cook(const Cloth& cloth);
  // Substeps step() would use for a frame of length dt.
  int substeps_for(const Cloth& cloth, double dt);
  // The Gershgorin bound of the stable substep (2 / sqrt(lambda bound)), in seconds.
  double stable_dt_bound(const Cloth& cloth);

 private:
  void substep(Cloth& cloth, const SceneObjects& scene, double h, StepStats& stats);

  VerletParams p_;
  Springs springs_;
  uint64_t cooked_version_ = 0;
  const void* cooked_cloth_ = nullptr;
  double lambda_bound_ = -1;
  std::vector<Vec3> force_, disp_, x0_, xprev0_;
  Collider collider_;
};

}  // namespace drape::sim
