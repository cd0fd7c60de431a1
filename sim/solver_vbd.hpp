// Vertex Block Descent (Chen, Liu, Yang, Yuksel, SIGGRAPH 2024) on the cloth energy of
// sim/energy.hpp: block coordinate descent on the implicit-Euler incremental potential, one
// 3x3 Newton step per vertex, vertices of one colour in parallel (2 threads), contacts as
// penalty energies detected once per substep, early stop on the residual, optional Chebyshev
// acceleration and freezing of regions at rest. The default real-time solver.
#pragma once

#include <memory>
#include <vector>

#include "sim/energy.hpp"
#include "sim/parallel.hpp"
#include "sim/solver.hpp"

namespace drape::sim {

struct VbdOptions {
  int substeps = 2;
  int iterations = 8;       // maximum per substep
  double tolerance = 1e-6;  // m: stop a substep when no vertex moved more than this
  bool chebyshev = false;
  double chebyshev_rho = 0.9;  // estimated spectral radius
  bool freeze = false;         // freeze regions at rest (kFlagFrozen) until something nears
  double freeze_speed = 1e-3;  // m/s: below this for freeze_steps substeps -> frozen
  int freeze_steps = 30;
  double damping = 0.0;  // Rayleigh factor k_d (s): adds k_d/h * H (x - x_t)
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
  std::vector<Vec3> y_, xt_, xprev_iter_, xprev2_iter_;
  std::vector<int> rest_count_;
  std::vector<double> worker_max_;
  int frozen_count_ = 0;
};

}  // namespace drape::sim
