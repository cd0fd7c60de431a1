#include "sim/solvers/watchdog.hpp"

#include <algorithm>
#include <cmath>

#include "sim/core/thread_pool.hpp"

namespace drape::sim {

bool cloth_finite(const Cloth& cloth) {
  const auto& S = cloth.state;
  for (size_t i = 0; i < S.x.size(); ++i)
    if (!S.x[i].allFinite() || !S.v[i].allFinite()) return false;
  return true;
}

WatchdogSolver::WatchdogSolver(std::unique_ptr<Solver> inner, WatchdogOptions opt)
    : inner_(std::move(inner)), opt_(opt) {}

template <class Fn>
void WatchdogSolver::by_parts(int n, Fn&& fn) {
  ThreadPool* pool = inner_->pool();
  const int np = pool && n >= 4096 ? pool->size() : 1;
  parts_.assign(np, Part{});
  if (np == 1)
    fn(0, n, parts_[0]);
  else
    pool->parallel_parts(n, [&](int b, int e, int k) { fn(b, e, parts_[k]); });
}

double WatchdogSolver::kinetic(const Cloth& cloth) {
  const auto& S = cloth.state;
  by_parts(static_cast<int>(S.v.size()), [&](int b, int e, Part& p) {
    for (int i = b; i < e; ++i) p.ke += 0.5 * S.mass[i] * S.v[i].squaredNorm();
  });
  double ke = 0;
  for (const Part& p : parts_) ke += p.ke;
  return ke;
}

bool WatchdogSolver::healthy(const Cloth& cloth, double ke_before) {
  const auto& S = cloth.state;
  const double v2max = opt_.max_speed * opt_.max_speed, x2max = opt_.max_extent * opt_.max_extent;
  by_parts(static_cast<int>(S.x.size()), [&](int b, int e, Part& p) {
    for (int i = b; i < e; ++i) {
      if (!S.x[i].allFinite() || !S.v[i].allFinite() || S.v[i].squaredNorm() > v2max ||
          S.x[i].squaredNorm() > x2max) {
        p.ok = false;
        return;
      }
      p.mass += S.mass[i];
      p.ke += 0.5 * S.mass[i] * S.v[i].squaredNorm();
    }
  });
  double mass = 0, ke = 0;
  for (const Part& p : parts_) {
    if (!p.ok) return false;
    mass += p.mass;
    ke += p.ke;
  }
  // Scale: the kinetic energy of the whole cloth at 1 m/s.
  return ke <= opt_.max_kinetic_growth * (ke_before + 0.5 * mass * 1.0);
}

double WatchdogSolver::save(const Cloth& cloth) {
  const auto& S = cloth.state;
  const int n = static_cast<int>(S.x.size());
  x_.resize(n);  // same sizes after warm-up: no allocation
  xp_.resize(S.x_prev.size());
  v_.resize(S.v.size());
  time_ = S.time;
  by_parts(n, [&](int b, int e, Part& p) {
    std::copy(S.x.begin() + b, S.x.begin() + e, x_.begin() + b);
    if (S.x_prev.size() == S.x.size())
      std::copy(S.x_prev.begin() + b, S.x_prev.begin() + e, xp_.begin() + b);
    for (int i = b; i < e; ++i) {
      v_[i] = S.v[i];
      p.ke += 0.5 * S.mass[i] * S.v[i].squaredNorm();
    }
  });
  if (S.x_prev.size() != S.x.size()) xp_ = S.x_prev;
  double ke = 0;
  for (const Part& p : parts_) ke += p.ke;
  return ke;
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
  const double ke0 = save(cloth);
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
