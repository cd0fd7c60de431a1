// Implicit Euler with Newton's method and a sparse direct solve (CHOLMOD supernodal Cholesky by
// default, Eigen's SimplicialLDLT as the fallback): the accuracy reference of the benchmarks, and
// the static solver (energy minimisation with pinned vertices) that geometric draping calls through
// relax_static().
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdlib>
#include <memory>
#include <vector>

#include "sim/energy/energy.hpp"
#include "sim/solvers/solver.hpp"

namespace drape::sim {

// The sparse factorisation of the Newton systems. kCholmod: CHOLMOD's supernodal LL^T (dense
// BLAS kernels on the supernodes; several times faster than kSimplicial on the draped panels).
// kSimplicial: Eigen's SimplicialLDLT (the cross-check).
enum class LinearSolver { kCholmod, kSimplicial };

struct NewtonOptions {
  int substeps = 1;
  int max_iterations = 20;  // Newton iterations per substep
  double tolerance = 1e-6;  // stop when |grad G|_inf < tolerance * (max vertex weight)
  bool line_search = true;  // backtracking (Armijo) on G
  EnergyOptions energy;
  double contact_stiffness = 0;  // 0: automatic
  // Air drag (1/s) as in VBD: the inertia target is y = x + h v exp(-air_drag h).
  double air_drag = 0;
  LinearSolver linear_solver = LinearSolver::kCholmod;
  // Static mode (h <= 0) only: use the exact Hessian (no PSD projection of the membrane
  // stress / hinge curvature) whenever it factorises as positive definite, falling back to the
  // projected one when it does not. The projected Hessian drops the compressive geometric
  // stiffness of wrinkled triangles: Newton then converges only linearly (rate ~0.9 on the
  // draped form); with the exact Hessian near the minimum it converges quadratically.
  bool exact_hessian = false;
  // Static mode: update the Newton model's contact active set to the contacts the step
  // penetrates (re-solving, up to 3 passes): the model is then the exact piecewise-quadratic
  // penalty, not its linearisation at the current point.
  bool contact_prediction = false;
  // Static mode: solve each Newton system first by conjugate gradients preconditioned with the
  // last factorisation (of an earlier iterate's matrix, or of the same one before a contact
  // pass changed a few blocks), factorising anew only when that does not converge within
  // reuse_max_cg iterations to reuse_cg_tolerance (relative residual) or meets negative
  // curvature. Near a minimum the matrix changes little between iterates, so the stale factor
  // preconditions well; a CG iteration (two triangular solves) costs ~1/20 of a factorisation
  // on the form drape at 64^2-128^2, so a failed attempt costs about half of one.
  bool reuse_factorisation = false;
  int reuse_max_cg = 25;
  double reuse_cg_tolerance = 1e-6;
  // Diagnostics: one line per Newton iteration on stderr (residual, step, Hessian) and the
  // CHOLMOD analysis (sizes, flops, ordering).
  bool trace = false;
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
  // Optional position stopping rule for minimise(): also stop when a full accepted step moved
  // no free vertex by more than `step_tolerance` (m) and was less than half the previous one
  // (contracting by r < 1/2: the travel left, <= |dx| r / (1 - r), is below it too). 0: off.
  void set_step_tolerance(double t) { step_tolerance_ = t; }
  // Static mode: re-detect the contacts (re-linearise their planes) at every iteration.
  void set_contact_redetection(bool on) { redetect_ = on; }
  // Counters of the last minimise() call (diagnostics, tests).
  struct Counters {
    int factorisations = 0;
    int exact_steps = 0;      // steps taken with the exact Hessian
    int projected_steps = 0;  // steps taken with the PSD-projected Hessian
    int not_positive = 0;     // exact Hessians that were not positive definite
    int contact_passes = 0;   // extra solves for the contact active set
    int cg_solves = 0;        // systems solved by CG on a stale factorisation
    int cg_iterations = 0;
    double factor_ms = 0, assemble_ms = 0, cg_ms = 0;
    double last_step = 0;  // |dx|_inf of the last accepted step (m)
  };
  const Counters& counters() const { return counters_; }

 private:
  struct Linear;  // the sparse matrix, its fixed assembly pattern and the factorisation
  void assemble(const Cloth& cloth, double inv_h2, double mu, bool exact, bool record);
  void cook(const Cloth& cloth);
  double objective(const Cloth& cloth, const std::vector<Vec3>& x, double inv_h2,
                   const std::vector<Vec3>* y) const;

  NewtonOptions opt_;
  ClothEnergy energy_;
  std::vector<int> dof_;  // free-vertex index or -1
  int ndof_ = 0;
  std::unique_ptr<Linear> lin_;
  std::array<size_t, 5> pattern_sig_{};  // element counts the pattern was recorded for
  bool analysed_ = false;
  double step_tolerance_ = 0;
  bool redetect_ = false;
  Counters counters_;
  std::vector<Vec3> grad_, xtrial_, y_, xt_;
  std::vector<char> contact_active_;  // per contact: in the Newton model's active set
  std::vector<char> sticky_;          // per vertex: held by the previous iteration's model
  Eigen::VectorXd rhs_, dx_, model_rhs_, cg_x_;
};

struct StaticOptions {
  double tolerance = 1e-6;  // |grad E|_inf relative to the largest vertex weight (m g)
  int max_iterations = 100;
  // Also converged when the last Newton step moved no vertex by more than this (m) and the
  // steps contract (see NewtonSolver::set_step_tolerance); 0: the residual rule alone.
  double step_tolerance = 0;
  LinearSolver linear_solver = LinearSolver::kCholmod;
  bool exact_hessian = true;       // see NewtonOptions::exact_hessian
  bool contact_prediction = true;  // see NewtonOptions::contact_prediction
  // See NewtonOptions::reuse_factorisation. Measured on four XPBD end states of the form
  // scene: 1e-2 and 12 iterations (inexact Newton steps) took
  // 0.87x / 0.86x / 0.35x / 0.82x the time of factorising every system (32^2 3 s, 64^2 3 s,
  // 64^2 12 s, 128^2 9 s); the states' errors against the two polishes agree within
  // 0.007 mm rms.
  bool reuse_factorisation = true;
  int reuse_max_cg = 12;
  double reuse_cg_tolerance = 1e-2;
  // Re-linearise the contact planes at every Newton iterate (true) or only between rounds.
  bool redetect_every_iteration = true;
  EnergyOptions energy;  // e.g. pressure toward the form (method 2.1), gravity off/on
  bool contacts = true;  // penalty contact against the scene's objects (redetected)
  double contact_stiffness = 0;
  // Coulomb friction (SceneObjects::friction > 0): contact vertices anchored where the solve
  // starts, sticking while their tangential load is within mu times the normal one (the
  // smoothed potential of ClothEnergy::set_friction, sticking within friction_eps). The
  // minimum is then the frictional equilibrium nearest to the start: on a form with friction,
  // not the far end of a frictionless slide.
  // Off by default: a solve from far away (a flat panel onto a form: geometric draping) asks
  // for the energy's minimum, not for where friction would have held the panel.
  bool friction = false;
  double friction_eps = 1e-4;  // m
};

struct StaticResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0;  // final |grad E|_inf / (max m g)
  double energy = 0;    // J at the end
  double ms = 0;
  int rounds = 0;        // contact re-detection rounds
  int exact_steps = 0;   // Newton steps with the exact Hessian (the rest: projected)
  double factor_ms = 0;  // time in the sparse factorisations
  int factorisations = 0;
  int cg_solves = 0;      // Newton systems solved by CG on a stale factorisation instead
  int cg_iterations = 0;  // all CG iterations, those of attempts that failed included
  double cg_ms = 0;
  double last_step = 0;  // |dx|_inf of the last accepted Newton step (m)
};

// Static draping: minimises E with pinned/pinched/kinematic vertices fixed (Newton with
// PSD-projected Hessians, Levenberg-Marquardt regularisation and line search). Velocities are
// zeroed; x_prev = x. The cloth's arrays are updated in place.
StaticResult relax_static(Cloth& cloth, const SceneObjects& scene, const StaticOptions& opt = {});

}  // namespace drape::sim
