// XPBD (Macklin, Mueller, Chentanez 2016) with small steps (Macklin et al. 2019) on the SAME
// energy as the other solvers: each membrane triangle contributes three strain constraints
// (E_uu, E_vv, E_uv with compliances 1/(k A)), each bending hinge one linear vector constraint
// (sum K_k x_k, compliance 1/w), each spring a distance constraint; contacts are projected.
#pragma once

#include <vector>

#include "sim/energy.hpp"
#include "sim/solver.hpp"

namespace drape::sim {

struct XpbdOptions {
  int substeps = 10;
  int iterations = 1;  // per substep (small steps: 1)
  EnergyOptions energy;
  double damping = 1.0;  // velocity damping rate (1/s), air drag as in Verlet and VBD
};

class XpbdSolver : public Solver {
 public:
  explicit XpbdSolver(XpbdOptions opt = {}) : opt_(opt) {}
  std::string name() const override { return "xpbd"; }
  StepStats step(Cloth& cloth, const SceneObjects& scene, double dt) override;
  XpbdOptions& options() { return opt_; }

 private:
  XpbdOptions opt_;
  ClothEnergy energy_;
  std::vector<double> lambda_tri_, lambda_spring_;
  std::vector<Vec3> lambda_hinge_, xt_;
};

}  // namespace drape::sim
