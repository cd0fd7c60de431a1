#include "sim/solvers/solver_factory.hpp"

#include "sim/solvers/cook_ahead.hpp"
#include "sim/solvers/solver_newton.hpp"
#include "sim/solvers/solver_vbd.hpp"
#include "sim/solvers/verlet_solver.hpp"
#include "sim/solvers/watchdog.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"

namespace drape::sim {

Result<std::unique_ptr<Solver>> make_solver(const std::string& name_in, const SolverConfig& cfg) {
  const std::string name = name_in == "default" ? std::string(kDefaultSolver) : name_in;
  std::unique_ptr<Solver> s;
  EnergyOptions eo;
  if (cfg.springs_model) eo.model = EnergyOptions::Model::kSprings;
  if (name == "vbd") {
    VbdOptions o;
    o.energy = eo;
    if (cfg.substeps > 0) o.substeps = cfg.substeps;
    if (cfg.iterations > 0) o.iterations = cfg.iterations;
    if (cfg.tolerance > 0) o.tolerance = cfg.tolerance;
    o.freeze = cfg.freeze;
    o.chebyshev = cfg.chebyshev;
    o.threads = cfg.threads;
    if (cfg.air_drag >= 0) o.air_drag = cfg.air_drag;
    s = std::make_unique<VbdSolver>(o);
  } else if (name == "xpbd") {
    XpbdOptions o;
    o.energy = eo;
    if (cfg.substeps > 0) o.substeps = cfg.substeps;
    if (cfg.iterations > 0) o.iterations = cfg.iterations;
    if (cfg.air_drag >= 0) o.air_drag = cfg.air_drag;
    o.threads = cfg.threads;
    o.freeze = cfg.freeze;
    o.finish_thread = cfg.finish_thread;
    o.settle = cfg.settle;
    if (cfg.cook_ahead_ticks > 0)
      s = std::make_unique<CookAheadSolver>(o, CookAheadOptions{cfg.cook_ahead_ticks});
    else
      s = std::make_unique<XpbdSolver>(o);
  } else if (name == "newton") {
    NewtonOptions o;
    o.energy = eo;
    if (cfg.substeps > 0) o.substeps = cfg.substeps;
    if (cfg.iterations > 0) o.max_iterations = cfg.iterations;
    if (cfg.tolerance > 0) o.tolerance = cfg.tolerance;
    if (cfg.air_drag >= 0) o.air_drag = cfg.air_drag;
    s = std::make_unique<NewtonSolver>(o);
  } else if (name == "verlet") {
    VerletParams p;
    if (cfg.substeps > 0) p.substeps = cfg.substeps;
    if (cfg.air_drag >= 0) p.air_drag = cfg.air_drag;
    s = std::make_unique<VerletSolver>(p);
  } else {
    return make_error("make_solver", "unknown solver '" + name +
                                         "' (expected default, vbd, xpbd, newton or verlet)");
  }
  if (cfg.watchdog) s = std::make_unique<WatchdogSolver>(std::move(s));
  return s;
}

}  // namespace drape::sim
