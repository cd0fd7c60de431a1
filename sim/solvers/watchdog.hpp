// Divergence watchdog around any solver: after each step it checks for NaN/inf, runaway
// speeds, positions beyond a bound and (when an energy is given) an energy blow-up; a bad step
// is rolled back to the last good state and retried with more substeps (dt/2, dt/4, ...). If
// every retry fails, the last good state is kept with velocities zeroed: the cloth never
// disappears. Reported in StepStats (diverged, retries).
#pragma once

#include <memory>
#include <vector>

#include "sim/solvers/solver.hpp"

namespace drape::sim {

struct WatchdogOptions {
  int max_retries = 4;              // halvings of the step
  double max_speed = 100.0;         // m/s: faster means the step blew up
  double max_extent = 50.0;         // m from the origin
  double max_kinetic_growth = 1e3;  // KE(after) > growth * (KE(before) + scale) -> blow-up
};

class WatchdogSolver : public Solver {
 public:
  WatchdogSolver(std::unique_ptr<Solver> inner, WatchdogOptions opt = {});
  std::string name() const override { return inner_->name(); }
  StepStats step(Cloth& cloth, const SceneObjects& scene, double dt) override;
  ThreadPool* pool() override { return inner_->pool(); }
  // The inner solver's (the watchdog saves the cloth before each step: nothing of its own).
  std::vector<unsigned char> save_state(const Cloth& cloth) const override {
    return inner_->save_state(cloth);
  }
  std::string restore_state(const std::vector<unsigned char>& bytes, const Cloth& cloth) override {
    return inner_->restore_state(bytes, cloth);
  }
  Solver& inner() { return *inner_; }
  int total_rollbacks() const { return total_rollbacks_; }

 private:
  // Per part of the vertices (one per thread of the inner solver's pool): the sums of a pass.
  struct Part {
    bool ok = true;
    double mass = 0, ke = 0;
  };
  // Runs fn(begin, end, part) over the vertices in parts, on the inner solver's pool if it has
  // one; the parts' sums in part order (the same sums on any thread).
  template <class Fn>
  void by_parts(int n, Fn&& fn);
  // The state saved (x, x_prev, v, time); returns its kinetic energy.
  double save(const Cloth& cloth);
  double kinetic(const Cloth& cloth);
  // Finite, not too fast, within bounds, and no blow-up of the kinetic energy.
  bool healthy(const Cloth& cloth, double ke_before);
  void restore(Cloth& cloth) const;

  std::unique_ptr<Solver> inner_;
  WatchdogOptions opt_;
  std::vector<Vec3> x_, xp_, v_;
  std::vector<Part> parts_;
  double time_ = 0;
  int total_rollbacks_ = 0;
};

// True when every position and velocity is finite.
bool cloth_finite(const Cloth& cloth);

}  // namespace drape::sim
