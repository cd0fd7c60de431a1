// Implicit Euler with Newton's method and a sparse direct solve (Eigen SimplicialLDLT): the
// accuracy reference of the study, and the static solver (energy minimisation with pinned
// vertices) that geometric draping calls through relax_static().
#pragma once

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <memory>
#include <vector>

#include "sim/energy.hpp"
#include "sim/solver.hpp"

namespace drape::sim {

struct NewtonOptions {
  int substeps = 1;
  int max_iterations = 20;  // Newton iterations per substep
  double tolerance = 1e-6;  // stop when |grad G|_inf < tolerance * (max vertex weight)
  bool line_search = true;  // backtracking (Armijo) on G
  EnergyOptions energy;
  double contact_stiffness = 0;  // 0: automatic
  // Air drag (1/s) as in VBD: the inertia target is y = x + h v exp(-air_damping h).
  double air_damping = 0;
};

class NewtonSolver : public Solver {
 public:
  explicit NewtonSolver(NewtonOptions opt = {});
  ~NewtonSolver() override;
  std::string name() const override { return "newton"; }
  StepStats step(Cloth& cloth, const SceneObjects& scene, double dt) override;
  NewtonOptions& options() { return opt_; }
  ClothEnergy& energy() { return energy_; }

  // One minimisation of G(x) = 1/(2h^2)|x - y|_M^2 + E(x) (h <= 0 or inf: E alone), from the
  // cloth's current x; y given per vertex (ignored when static). Returns iterations used and
  // sets the final |grad|_inf relative to the weight scale in `residual`.
  int minimise(Cloth& cloth, const SceneObjects& scene, double h, const std::vector<Vec3>* y,
               double tolerance, int max_iterations, double& residual);

 private:
  void cook(const Cloth& cloth);
  double objective(const Cloth& cloth, const std::vector<Vec3>& x, double inv_h2,
                   const std::vector<Vec3>* y) const;

  NewtonOptions opt_;
  ClothEnergy energy_;
  std::vector<int> dof_;  // free-vertex index or -1
  int ndof_ = 0;
  std::vector<Eigen::Triplet<double>> trip_;
  Eigen::SparseMatrix<double> H_;
  std::unique_ptr<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>> ldlt_;
  bool analysed_ = false;
  std::vector<Vec3> grad_, xtrial_, y_, xt_;
  Eigen::VectorXd rhs_, dx_;
};

struct StaticOptions {
  double tolerance = 1e-6;  // |grad E|_inf relative to the largest vertex weight (m g)
  int max_iterations = 100;
  EnergyOptions energy;  // e.g. pressure toward the form (method 2.1), gravity off/on
  bool contacts = true;  // penalty contact against the scene's objects (redetected)
  double contact_stiffness = 0;
};

struct StaticResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0;  // final |grad E|_inf / (max m g)
  double energy = 0;    // J at the end
  double ms = 0;
};

// Static draping: minimises E with pinned/pinched/kinematic vertices fixed (Newton with
// PSD-projected Hessians, Levenberg-Marquardt regularisation and line search). Velocities are
// zeroed; x_prev = x. The cloth's arrays are updated in place.
StaticResult relax_static(Cloth& cloth, const SceneObjects& scene, const StaticOptions& opt = {});

}  // namespace drape::sim
