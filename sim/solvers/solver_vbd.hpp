// Vertex Block Descent (Chen, Liu, Yang, Yuksel, SIGGRAPH 2024) on the cloth energy of
// sim/energy/energy.hpp: block coordinate descent on the implicit-Euler incremental potential, one
// 3x3 Newton step per vertex, vertices of one colour in parallel (2 threads), contacts as
// penalty energies detected once per substep, early stop on the residual, optional Chebyshev
// acceleration and freezing of regions at rest. The default real-time solver.
#pragma once

#include <memory>
#include <vector>

#include "sim/core/thread_pool.hpp"
#include "sim/energy/energy.hpp"
#include "sim/solvers/solver.hpp"

namespace drape::sim {

struct VbdOptions {
  // Initial guess of each substep (Chen et al. 2024, sec. 3.6): kInertia x + h v;
  // kInertiaGravity x + h v + h^2 g (full gravity: biases an under-converged solve downwards,
  // so a cloth at rest is not a fixed point); kAdaptive x + h v + h^2 a~ with a~ the previous
  // substep's acceleration projected on gravity, clamped to [0, |g|] (the default: a cloth at
  // rest stays exactly at rest, a falling one gets the full gravity term); for a vertex
  // touching a surface, that term's normal part plus the slide of a block there (gravity's
  // tangential part less the scene's friction times its normal part).
  enum class Init { kInertia, kInertiaGravity, kAdaptive };
  Init init = Init::kAdaptive;
  int substeps = 2;
  int iterations = 8;  // maximum per substep
  // Early stop of a substep (both must hold): no vertex moved more than `tolerance` (m) in the
  // last iteration AND the largest per-vertex force residual |f_i| (inertia included, before
  // its update) is below force_tolerance * m_i |g|. The displacement test alone stops a stiff
  // cloth after one iteration (the Gauss-Seidel steps are tiny but the error is not).
  double tolerance = 1e-6;
  double force_tolerance = 1e-2;
  // Largest step of one vertex per iteration, as a fraction of its shortest incident rest
  // edge (a PSD-projected block Hessian can underestimate the curvature of compressed or
  // degenerate triangles after a cut; the clamp keeps such a block step from overshooting).
  double max_step = 0.5;
  bool chebyshev = false;
  double chebyshev_rho = 0.9;  // estimated spectral radius
  bool freeze = false;         // freeze regions at rest (kFlagFrozen) until something nears
  double freeze_speed = 1e-3;  // m/s: below this for freeze_steps substeps -> frozen
  int freeze_steps = 30;
  // Rayleigh factor k_d (s): adds k_d/h * H_i (x_i - x_i,t) with the vertex's own 3x3 block
  // only (the paper's form): NOT invariant under rigid motion (it also slows a falling cloth),
  // so off by default; use air_drag to settle swinging cloth.
  double rayleigh_damping = 0.0;
  // Air drag (1/s), the same as VerletParams::air_drag and XpbdOptions::air_drag: the
  // inertia target is y = x + h v exp(-air_drag h).
  double air_drag = 1.0;
  int threads = 2;
  EnergyOptions energy;
  double contact_stiffness = 0;  // 0: automatic
};

class VbdSolver : public Solver {
 public:
  explicit VbdSolver(VbdOptions opt = {});
  ~VbdSolver() override;
  std::string name() const override { return "vbd"; }
  StepStats step(Cloth& cloth, const SceneObjects& scene, double dt) override;
  ThreadPool* pool() override { return pool_.get(); }
  VbdOptions& options() { return opt_; }
  const ClothEnergy& energy() const { return energy_; }
  int num_colours() const { return num_colours_; }
  int frozen_count() const { return frozen_count_; }

 private:
  void cook(const Cloth& cloth);
  double substep(Cloth& cloth, const SceneObjects& scene, double h, StepStats& st);

  VbdOptions opt_;
  ClothEnergy energy_;
  std::unique_ptr<ThreadPool> pool_;
  std::vector<int> colour_of_, colour_off_, colour_items_;
  std::vector<int> nbr_off_, nbrs_;
  int num_colours_ = 0;
  std::vector<Vec3> y_, xt_, xprev_iter_, xprev2_iter_, vprev_;
  std::vector<int> rest_count_;
  std::vector<double> max_step_;
  std::vector<double> worker_max_;
  int frozen_count_ = 0;
  double h_prev_ = 0;
};

}  // namespace drape::sim
