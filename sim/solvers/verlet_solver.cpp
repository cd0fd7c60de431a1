// The explicit baseline: mass-spring network + damped Verlet, with the collision response.
#include "sim/solvers/verlet_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace drape::sim {

void VerletSolver::cook(const Cloth& cloth) {
  springs_ = build_springs(cloth, p_.stiffness_scale);
  cooked_version_ = cloth.topology_version;
  cooked_cloth_ = &cloth;
  lambda_bound_ = -1;
  const size_t n = cloth.num_vertices();
  force_.resize(n);
  disp_.resize(n);
  x0_.resize(n);
  xprev0_.resize(n);
}

double VerletSolver::stable_dt_bound(const Cloth& cloth) {
  if (cooked_cloth_ != &cloth || cooked_version_ != cloth.topology_version || springs_.size() == 0)
    cook(cloth);
  // Inverse masses change with pins: recompute (O(springs), cheap next to a frame).
  lambda_bound_ = max_eigenvalue_bound(cloth, springs_);
  return lambda_bound_ > 0 ? 2.0 / std::sqrt(lambda_bound_) : 1e9;
}

int VerletSolver::substeps_for(const Cloth& cloth, double dt) {
  if (p_.substeps > 0) return p_.substeps;
  const double h = p_.safety * stable_dt_bound(cloth);
  return std::max(1, static_cast<int>(std::ceil(dt / h)));
}

StepStats VerletSolver::step(Cloth& cloth, const SceneObjects& scene, double dt) {
  StepStats stats;
  if (cooked_cloth_ != &cloth || cooked_version_ != cloth.topology_version ||
      force_.size() != static_cast<size_t>(cloth.num_vertices()))
    cook(cloth);
  const int n_sub = substeps_for(cloth, dt);
  const double h = dt / n_sub;
  auto& st = cloth.state;
  if (p_.rollback_on_divergence) {
    std::copy(st.x.begin(), st.x.end(), x0_.begin());
    std::copy(st.x_prev.begin(), st.x_prev.end(), xprev0_.begin());
  }
  for (int s = 0; s < n_sub; ++s) substep(cloth, scene, h, stats);
  stats.substeps = n_sub;
  bool finite = true;
  for (const Vec3& x : st.x) finite = finite && x.allFinite();
  if (!finite) {
    stats.diverged = true;
    if (p_.rollback_on_divergence) {
      std::copy(x0_.begin(), x0_.end(), st.x.begin());
      std::copy(x0_.begin(), x0_.end(), st.x_prev.begin());  // at rest
      std::fill(st.v.begin(), st.v.end(), Vec3::Zero());
      (void)xprev0_;
      stats.retries = 1;
    }
  }
  return stats;
}

void VerletSolver::substep(Cloth& cloth, const SceneObjects& scene, double h, StepStats& stats) {
  auto& st = cloth.state;
  const int n = cloth.num_vertices();
  const Vec3 g(0, -kGravity, 0);
  // eq. 3-2: gravity. Stored as force / mass (acceleration) per vertex to save a division.
  for (int i = 0; i < n; ++i) force_[i] = st.mass[i] * g;
  // eq. 3-1: springs, one flat loop over the arrays.
  const int ns = springs_.size();
  const int32_t* A = springs_.a.data();
  const int32_t* B = springs_.b.data();
  const double* R = springs_.rest.data();
  const double* K = springs_.k.data();
  const Vec3* x = st.x.data();
  Vec3* f = force_.data();
  for (int s = 0; s < ns; ++s) {
    const Vec3 d = x[B[s]] - x[A[s]];
    const double len = d.norm();
    if (len <= 1e-12) continue;
    const Vec3 fs = (K[s] * (len - R[s]) / len) * d;
    f[A[s]] += fs;
    f[B[s]] -= fs;
  }
  // eq. 3-7 as published (response_as_velocity): F_resp dt^2 / m = -(eps - d) n, evaluated at
  // x(t) like the other forces and added to the step.
  const bool published = p_.collide && p_.response_as_velocity;
  bool any_contact = false;
  if (published) {
    const auto t0 = std::chrono::steady_clock::now();
    const CollisionStats cs = collider_.response_displacements(st, scene, disp_);
    stats.collision_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    stats.max_penetration = std::max(stats.max_penetration, cs.max_penetration);
    any_contact = cs.contacts > 0;
  }
  // eq. 3-4: x(t+h) = x(t) + alpha (x(t) - x(t-h)) + F h^2 / m.
  const double alpha = p_.alpha > 0 ? p_.alpha : std::exp(-p_.air_drag * h);
  const double h2 = h * h, inv_h = 1.0 / h;
  const double* inv_m = st.inv_mass.data();
  Vec3* xm = st.x.data();
  Vec3* xp = st.x_prev.data();
  Vec3* v = st.v.data();
  for (int i = 0; i < n; ++i) {
    if (inv_m[i] == 0 || !cloth.is_free(i)) {
      xp[i] = xm[i];
      v[i].setZero();
      continue;
    }
    Vec3 xn = xm[i] + alpha * (xm[i] - xp[i]) + (h2 * inv_m[i]) * f[i];
    if (any_contact) xn += disp_[i];
    xp[i] = xm[i];
    xm[i] = xn;
  }
  // Default: the same response as a projection of the predicted x(t+h) to
  // the offset surface, with x(t) kept as the previous position. The velocity (x(t+h) - x(t)) / h
  // then loses its component into the object, so neither the response nor the velocity that
  // carried the vertex inside survives into the next step. (Moving x(t) and x(t-h) together, as
  // before, kept the inward velocity: springs and gravity kept accelerating vertices in contact
  // into the form, by more each substep, and the cloth ended centimetres inside it.)
  if (p_.collide && !p_.response_as_velocity) {
    const auto t0 = std::chrono::steady_clock::now();
    const CollisionStats cs = collider_.project(st, scene);
    stats.collision_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    stats.max_penetration = std::max(stats.max_penetration, cs.max_penetration);
  }
  for (int i = 0; i < n; ++i) {
    if (inv_m[i] == 0 || !cloth.is_free(i)) continue;
    v[i] = (xm[i] - xp[i]) * inv_h;
  }
  st.time += h;
}

}  // namespace drape::sim
