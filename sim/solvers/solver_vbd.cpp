#include "sim/solvers/solver_vbd.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>

namespace drape::sim {

namespace {
constexpr double kG2 = kGravity * kGravity;
}  // namespace

VbdSolver::VbdSolver(VbdOptions opt)
    : opt_(opt), pool_(std::make_unique<ThreadPool>(std::max(1, opt.threads))) {}
VbdSolver::~VbdSolver() = default;

void VbdSolver::cook(const Cloth& cloth) {
  energy_.build(cloth, opt_.energy, pool_.get());
  energy_.vertex_neighbours(nbr_off_, nbrs_);
  num_colours_ = greedy_colouring(nbr_off_, nbrs_, colour_of_, colour_off_, colour_items_);
  const int n = cloth.num_vertices();
  y_.resize(n);
  xt_.resize(n);
  xprev_iter_.resize(n);
  xprev2_iter_.resize(n);
  vprev_.assign(cloth.state.v.begin(), cloth.state.v.end());
  rest_count_.assign(n, 0);
  worker_max_.assign(pool_->size() * 16, 0.0);
  // Per-vertex step limit from the shortest incident rest edge (material space).
  max_step_.assign(n, 0.0);
  for (const auto& t : cloth.topo.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      const double l = (cloth.topo.material[a] - cloth.topo.material[b]).norm();
      for (int v : {a, b})
        if (l > 0 && (max_step_[v] == 0 || l < max_step_[v])) max_step_[v] = l;
    }
  const double fallback = cloth.topo.spacing > 0 ? cloth.topo.spacing : 0.01;
  for (int i = 0; i < n; ++i)
    max_step_[i] = opt_.max_step * (max_step_[i] > 0 ? max_step_[i] : fallback);
}

StepStats VbdSolver::step(Cloth& cloth, const SceneObjects& scene, double dt) {
  StepStats st;
  if (!energy_.up_to_date(cloth)) cook(cloth);
  energy_.set_form(&scene);
  const int ns = std::max(1, opt_.substeps);
  const double h = dt / ns;
  for (int s = 0; s < ns; ++s) {
    st.residual = substep(cloth, scene, h, st);
    ++st.substeps;
  }
  return st;
}

double VbdSolver::substep(Cloth& cloth, const SceneObjects& scene, double h, StepStats& st) {
  auto& S = cloth.state;
  const int n = cloth.num_vertices();
  // Contacts once per substep, at the start-of-step positions.
  const auto t0 = std::chrono::steady_clock::now();
  if (opt_.contact_stiffness > 0) {
    energy_.set_contact_stiffness(opt_.contact_stiffness);
  } else {
    // Stiff relative to the inertia of the heaviest vertex and to the membrane.
    double mmax = 0;
    for (int i = 0; i < n; ++i) mmax = std::max(mmax, S.mass[i]);
    energy_.set_contact_stiffness(std::max(1e4, 1e3 * mmax / (h * h)));
  }
  st.max_penetration = std::max(st.max_penetration, energy_.detect_contacts(cloth, scene));
  if (scene.friction > 0) {
    // Friction anchored at the substep's start, loads from the penalty there (lagged, as in
    // the VBD paper), sticking below kFrictionSlipSpeed.
    energy_.set_friction(scene.friction, kFrictionSlipSpeed * h, S.x);
    energy_.lag_friction_penalty(S.x);
  } else {
    energy_.clear_friction();
  }
  st.collision_ms +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  const Vec3 g = opt_.energy.gravity ? opt_.energy.g : Vec3::Zero();
  // Wake frozen vertices next to moving ones (and all when freezing is off).
  if (!opt_.freeze) {
    for (int i = 0; i < n; ++i) S.flags[i] &= static_cast<uint8_t>(~kFlagFrozen);
  } else {
    for (int i = 0; i < n; ++i) {
      if (!(S.flags[i] & kFlagFrozen)) continue;
      bool wake = energy_.contact_of(i) >= 0 &&
                  energy_.contacts()[energy_.contact_of(i)].n.dot(
                      S.x[i] - energy_.contacts()[energy_.contact_of(i)].p) < 0;
      for (int k = nbr_off_[i]; k < nbr_off_[i + 1] && !wake; ++k) {
        const int j = nbrs_[k];
        if (!(S.flags[j] & kFlagFrozen) &&
            (S.v[j].norm() > opt_.freeze_speed * 2 || !cloth.is_free(j))) {
          // A pinned/kinematic neighbour wakes only if it moved.
          if (!cloth.is_free(j) && (S.x[j] - S.x_prev[j]).norm() < 1e-9) continue;
          wake = true;
        }
      }
      if (wake) {
        S.flags[i] &= static_cast<uint8_t>(~kFlagFrozen);
        rest_count_[i] = 0;
      }
    }
  }
  const double gn = g.norm();
  const Vec3 gdir = gn > 0 ? Vec3(g / gn) : Vec3::Zero();
  const double h_prev = h_prev_ > 0 ? h_prev_ : h;
  const double drag = std::exp(-opt_.air_drag * h);
  for (int i = 0; i < n; ++i) {
    xt_[i] = S.x[i];
    if (cloth.is_free(i) && !(S.flags[i] & kFlagFrozen)) {
      y_[i] = S.x[i] + (h * drag) * S.v[i];
      switch (opt_.init) {
        case VbdOptions::Init::kInertia:
          S.x[i] = y_[i];
          break;
        case VbdOptions::Init::kInertiaGravity:
          S.x[i] = y_[i] + h * h * g;
          break;
        case VbdOptions::Init::kAdaptive: {
          const double a = std::clamp((S.v[i] - vprev_[i]).dot(gdir) / h_prev, 0.0, gn);
          Vec3 acc = a * gdir;
          // A vertex touching a surface also gets the slide that gravity and Coulomb friction
          // give a block there: gravity's tangential part less mu times its normal part. The
          // previous acceleration of a cloth at rest on a slope is zero, and the local solves,
          // each held by stiff membrane neighbours, neither start a slide nor stop one
          // themselves (measured on an incline: 2.8 of 703 mm in 0.5 s without friction; with
          // the tangential gravity alone, a 20-degree slope that friction holds slid 1.7 m).
          const int ci = energy_.contact_of(i);
          if (ci >= 0) {
            const Contact& c = energy_.contacts()[ci];
            if (c.n.dot(S.x[i] - c.p) < 1e-4) {
              const double gn = c.n.dot(g);
              const Vec3 gt = g - gn * c.n;
              const double gtl = gt.norm();
              const double slide = std::max(0.0, gtl - (gn < 0 ? scene.friction * -gn : 0.0));
              acc = c.n.dot(acc) * c.n;  // the adaptive term along the normal only
              if (gtl > 0) acc += (slide / gtl) * gt;
            }
          }
          S.x[i] = y_[i] + (h * h) * acc;
          break;
        }
      }
    } else {
      y_[i] = S.x[i];
    }
  }
  const double inv_h2 = 1.0 / (h * h);
  const double kd_h = opt_.rayleigh_damping / h;
  double omega = 1.0;
  double residual = 0;
  for (int it = 0; it < opt_.iterations; ++it) {
    std::fill(worker_max_.begin(), worker_max_.end(), 0.0);
    if (opt_.chebyshev) {
      for (int i = 0; i < n; ++i) {
        xprev2_iter_[i] = xprev_iter_[i];
        xprev_iter_[i] = S.x[i];
      }
    }
    for (int c = 0; c < num_colours_; ++c) {
      const int* items = colour_items_.data() + colour_off_[c];
      const int count = colour_off_[c + 1] - colour_off_[c];
      pool_->parallel_for(count, [&](int b, int e, int w) {
        double local = 0, local_f = 0;
        for (int k = b; k < e; ++k) {
          const int i = items[k];
          if (!cloth.is_free(i) || (S.flags[i] & kFlagFrozen)) continue;
          Vec3 f;
          Mat3 H;
          energy_.vertex_force_hessian(i, S.x, S.mass[i], f, H);
          if (kd_h > 0) {
            f -= kd_h * H * (S.x[i] - xt_[i]);
            H *= (1.0 + kd_h);
          }
          const double m = S.mass[i] * inv_h2;
          f -= m * (S.x[i] - y_[i]);
          H.diagonal().array() += m;
          const double det = H.determinant();
          if (!(std::abs(det) > 1e-30)) continue;
          local_f = std::max(local_f, f.squaredNorm() / (S.mass[i] * S.mass[i] * kG2));
          Eigen::LLT<Mat3> llt(H);
          Vec3 dx = llt.info() == Eigen::Success ? Vec3(llt.solve(f)) : Vec3(H.inverse() * f);
          const double len2 = dx.squaredNorm();
          if (len2 > max_step_[i] * max_step_[i]) dx *= max_step_[i] / std::sqrt(len2);
          if (!dx.allFinite()) continue;
          S.x[i] += dx;
          local = std::max(local, dx.squaredNorm());
        }
        worker_max_[w * 16] = std::max(worker_max_[w * 16], local);
        worker_max_[w * 16 + 8] = std::max(worker_max_[w * 16 + 8], local_f);
      });
    }
    ++st.iterations;
    residual = 0;
    double moved = 0;
    for (int w = 0; w < pool_->size(); ++w) {
      moved = std::max(moved, worker_max_[w * 16]);
      residual = std::max(residual, worker_max_[w * 16 + 8]);
    }
    moved = std::sqrt(moved);
    residual = std::sqrt(residual);  // largest |f_i| / (m_i g) before the update
    if (opt_.chebyshev && it > 0) {
      omega = it == 1 ? 2.0 / (2.0 - opt_.chebyshev_rho * opt_.chebyshev_rho)
                      : 4.0 / (4.0 - opt_.chebyshev_rho * opt_.chebyshev_rho * omega);
      for (int i = 0; i < n; ++i)
        if (cloth.is_free(i) && !(S.flags[i] & kFlagFrozen))
          S.x[i] = omega * (S.x[i] - xprev2_iter_[i]) + xprev2_iter_[i];
    }
    if (moved < opt_.tolerance && residual < opt_.force_tolerance) break;
  }
  frozen_count_ = 0;
  h_prev_ = h;
  for (int i = 0; i < n; ++i) {
    S.x_prev[i] = xt_[i];
    vprev_[i] = S.v[i];
    if (cloth.is_free(i) && !(S.flags[i] & kFlagFrozen)) {
      S.v[i] = (S.x[i] - xt_[i]) / h;
      if (opt_.freeze) {
        rest_count_[i] = S.v[i].norm() < opt_.freeze_speed ? rest_count_[i] + 1 : 0;
        if (rest_count_[i] >= opt_.freeze_steps) {
          S.flags[i] |= kFlagFrozen;
          S.v[i].setZero();
        }
      }
    } else if (S.flags[i] & kFlagFrozen) {
      S.v[i].setZero();
    }
    frozen_count_ += (S.flags[i] & kFlagFrozen) ? 1 : 0;
  }
  S.time += h;
  return residual;
}

}  // namespace drape::sim
