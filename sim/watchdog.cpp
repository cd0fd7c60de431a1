#include "sim/watchdog.hpp"

#include <cmath>

namespace drape::sim {

bool cloth_finite(const Cloth& cloth) {
  const auto& S = cloth.state;
  for (size_t i = 0; i < S.x.size(); ++i)
    if (!S.x[i].allFinite() || !S.v[i].allFinite()) return false;
  return true;
}

WatchdogSolver::WatchdogSolver(std::unique_ptr<Solver> inner, WatchdogOptions opt)
    : inner_(std::move(inner)), opt_(opt) {}

namespace {
double kinetic(const Cloth& c) {
  double ke = 0;
  for (size_t i = 0; i < c.state.v.size(); ++i)
    ke += 0.5 * c.state.mass[i] * c.state.v[i].squaredNorm();
  return ke;
}
}  // namespace

bool WatchdogSolver::healthy(const Cloth& cloth, double ke_before) const {
  const auto& S = cloth.state;
  double mass = 0;
  for (size_t i = 0; i < S.x.size(); ++i) {
    if (!S.x[i].allFinite() || !S.v[i].allFinite()) return false;
    if (S.v[i].squaredNorm() > opt_.max_speed * opt_.max_speed) return false;
    if (S.x[i].squaredNorm() > opt_.max_extent * opt_.max_extent) return false;
    mass += S.mass[i];
  }
  // Scale: the kinetic energy of the whole cloth at 1 m/s.
  const double ke = kinetic(cloth);
  return ke <= opt_.max_kinetic_growth * (ke_before + 0.5 * mass * 1.0);
}

void WatchdogSolver::save(const Cloth& cloth) {
  x_ = cloth.state.x;  // same sizes after warm-up: no allocation
  xp_ = cloth.state.x_prev;
  v_ = cloth.state.v;
  time_ = cloth.state.time;
}

void WatchdogSolver::restore(Cloth& cloth) const {
  // Only the vertices that existed when saved (a topology edit between save and restore is
  // not possible: both happen inside step()).
  cloth.state.x = x_;
  cloth.state.x_prev = xp_;
  cloth.state.v = v_;
  cloth.state.time = time_;
}

StepStats WatchdogSolver::step(Cloth& cloth, const SceneObjects& scene, double dt) {
  save(cloth);
  const double ke0 = kinetic(cloth);
  StepStats st = inner_->step(cloth, scene, dt);
  if (healthy(cloth, ke0)) return st;
  st.diverged = true;
  for (int r = 1; r <= opt_.max_retries; ++r) {
    restore(cloth);
    ++st.retries;
    ++total_rollbacks_;
    const int parts = 1 << r;
    bool ok = true;
    for (int p = 0; p < parts && ok; ++p) {
      const double ke = kinetic(cloth);
      StepStats s2 = inner_->step(cloth, scene, dt / parts);
      st.substeps += s2.substeps;
      st.iterations += s2.iterations;
      st.collision_ms += s2.collision_ms;
      ok = healthy(cloth, ke);
    }
    if (ok) return st;
  }
  // Give up on this frame: keep the last good shape, at rest.
  restore(cloth);
  for (auto& v : cloth.state.v) v.setZero();
  cloth.state.x_prev = cloth.state.x;
  cloth.state.time += dt;
  return st;
}

}  // namespace drape::sim
