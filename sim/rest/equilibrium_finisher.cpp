#include "sim/rest/equilibrium_finisher.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>

#include "sim/core/stopwatch.hpp"

namespace drape::sim {

EquilibriumFinisher::EquilibriumFinisher(FinisherOptions opt) : opt_(opt) {}
EquilibriumFinisher::~EquilibriumFinisher() = default;

void EquilibriumFinisher::anchor(const Cloth& cloth, const std::vector<int>& group) {
  const int n = cloth.num_vertices();
  if (static_cast<int>(anchor_.size()) != n) anchor_ = cloth.state.x;
  for (int i = 0; i < n && i < static_cast<int>(group.size()); ++i)
    if (group[i] >= 0) anchor_[i] = cloth.state.x[i];
}

FinisherStats EquilibriumFinisher::cycle(Cloth& cloth, const SceneObjects& scene,
                                         const std::vector<int>& group,
                                         const EnergyOptions& energy_options, ThreadPool* pool) {
  const auto t0 = std::chrono::steady_clock::now();
  FinisherStats st;
  auto& S = cloth.state;
  const int n = cloth.num_vertices();
  if (static_cast<int>(group.size()) != n) return st;
  if (static_cast<int>(anchor_.size()) != n) anchor(cloth, group);
  if (!energy_.up_to_date(cloth) || version_ != cloth.topology_version) {
    EnergyOptions eo = energy_options;
    eo.bending_matrix = true;  // the per-vertex blocks read the bending matrix
    energy_.build(cloth, eo);
    energy_.vertex_neighbours(nbr_off_, nbrs_);
    colours_ = greedy_colouring(nbr_off_, nbrs_, colour_of_, colour_off_, colour_items_);
    version_ = cloth.topology_version;
  }
  energy_.set_form(&scene);
  energy_.set_contact_stiffness(opt_.contact_stiffness);
  // The nominal edge (a cloth without one, imported or remeshed: its mean material edge).
  const auto& mat = cloth.topo.material;
  double edge = nominal_edge(cloth);
  if (!(edge > 0)) edge = 0.01;
  int factor = opt_.coarse_factor;
  if (factor <= 0) {
    Vec2 lo(1e30, 1e30), hi(-1e30, -1e30);
    for (int i = 0; i < n; ++i)
      if (group[i] >= 0) {
        lo = lo.cwiseMin(mat[i]);
        hi = hi.cwiseMax(mat[i]);
      }
    const double side = hi.x() >= lo.x() ? (hi - lo).maxCoeff() / edge : 0.0;
    factor = std::clamp(static_cast<int>(std::lround(side / 16)), 2, 4);
  }
  coarse_.options().factor = factor;
  coarse_.options().rotations = opt_.rotations;
  const double inv_tau2 = 1.0 / (opt_.tau * opt_.tau);
  // A vertex's step is at most half an edge (its block can be nearly singular where the
  // projected membrane has no stiffness, e.g. under compression).
  const double max_step2 = 0.25 * edge * edge;
  auto sweep_range = [&](const int* items, int b, int e) {
    for (int k = b; k < e; ++k) {
      const int i = items[k];
      if (group[i] < 0) continue;
      Vec3 f;
      Mat3 H;
      const double m = S.mass[i];
      energy_.vertex_force_hessian(i, S.x, m, f, H);
      H.diagonal().array() += m * inv_tau2;
      const Eigen::LLT<Mat3> llt(H);
      if (llt.info() != Eigen::Success) continue;
      Vec3 dx = llt.solve(f);
      const double d2 = dx.squaredNorm();
      if (d2 > max_step2) dx *= std::sqrt(max_step2 / d2);
      S.x[i] += dx;
    }
  };
  before_ = S.x;
  energy_.detect_contacts(cloth, scene, pool);
  if (scene.friction > 0) {
    energy_.set_friction(scene.friction, opt_.friction_eps, anchor_);
    energy_.lag_friction_load(S.x, S.mass);
  }
  st.energy_before = energy_.energy(S.x, S.mass);
  const auto ts = std::chrono::steady_clock::now();
  for (int sw = 0; sw < opt_.sweeps; ++sw)
    for (int col = 0; col < colours_; ++col) {
      const int* items = colour_items_.data() + colour_off_[col];
      const int count = colour_off_[col + 1] - colour_off_[col];
      if (pool)
        pool->parallel_for(count, [&](int b, int e, int) { sweep_range(items, b, e); });
      else
        sweep_range(items, 0, count);
    }
  st.sweep_ms = ms_since(ts);
  const CoarseStats cs = coarse_.apply(cloth, energy_, group, S.x);
  st.coarse_ms = cs.total_ms;
  st.energy_after = cs.applied ? cs.energy_after : energy_.energy(S.x, S.mass);
  // Extrapolation along the cycle's displacement d: a slowly converging cycle moves along
  // nearly the same (softest) mode every time, so E(x + s d) is minimised over s by a parabola
  // through E(x), grad E(x).d and E(x + d), and the step kept only when it lowers E.
  if (opt_.extrapolate > 0) {
    const int nn = n;
    dir_.resize(nn);
    double dmax = 0;
    for (int i = 0; i < nn; ++i) {
      dir_[i] = group[i] >= 0 ? Vec3(S.x[i] - before_[i]) : Vec3::Zero();
      dmax = std::max(dmax, dir_[i].squaredNorm());
    }
    dmax = std::sqrt(dmax);
    if (dmax > 0) {
      energy_.gradient(S.x, S.mass, grad_);
      double slope = 0;
      for (int i = 0; i < nn; ++i) slope += grad_[i].dot(dir_[i]);
      const double e0 = st.energy_after;
      trial_.resize(nn);
      auto at = [&](double t) {
        for (int i = 0; i < nn; ++i) trial_[i] = S.x[i] + t * dir_[i];
        return energy_.energy(trial_, S.mass);
      };
      const double e1 = at(1.0);
      const double curv = e1 - e0 - slope;  // phi(t) ~ e0 + slope t + curv t^2
      if (slope < 0 && curv > 0) {
        const double t = std::min(-slope / (2 * curv), opt_.extrapolate);
        const double et = at(t);
        if (et < e0) {
          S.x.swap(trial_);
          st.energy_after = et;
          st.extrapolation = t;
        }
      }
    }
  }
  energy_.clear_friction();
  st.cycles = 1;
  double mv = 0;
  for (int i = 0; i < n; ++i)
    if (group[i] >= 0) {
      mv = std::max(mv, (S.x[i] - before_[i]).squaredNorm());
      S.v[i].setZero();
      S.x_prev[i] = S.x[i];
    }
  st.last_move = st.max_move = std::sqrt(mv);
  st.total_ms = ms_since(t0);
  return st;
}

FinisherStats EquilibriumFinisher::run(Cloth& cloth, const SceneObjects& scene,
                                       const std::vector<int>& group,
                                       const EnergyOptions& energy_options, ThreadPool* pool,
                                       const std::atomic<bool>* stop) {
  FinisherStats all;
  if (static_cast<int>(group.size()) != cloth.num_vertices()) return all;
  anchor(cloth, group);
  const std::vector<Vec3> start = cloth.state.x;
  for (int c = 0; c < opt_.cycles; ++c) {
    if (stop && stop->load(std::memory_order_relaxed)) break;
    const FinisherStats st = cycle(cloth, scene, group, energy_options, pool);
    if (c == 0) all.energy_before = st.energy_before;
    all.energy_after = st.energy_after;
    all.last_move = st.last_move;
    all.sweep_ms += st.sweep_ms;
    all.coarse_ms += st.coarse_ms;
    all.total_ms += st.total_ms;
    ++all.cycles;
    if (st.last_move < opt_.move_tolerance) break;
  }
  double mv = 0;
  for (int i = 0; i < cloth.num_vertices(); ++i)
    if (group[i] >= 0) mv = std::max(mv, (cloth.state.x[i] - start[i]).squaredNorm());
  all.max_move = std::sqrt(mv);
  return all;
}

}  // namespace drape::sim
