// make_solver("vbd" | "xpbd" | "newton" | "verlet", options): one place that knows every
// solver; wrapped in the divergence watchdog unless asked not to.
#pragma once

#include <memory>
#include <string>

#include "sim/core/types.hpp"
#include "sim/solvers/solver.hpp"

namespace drape::sim {

struct SolverConfig {
  int substeps = 0;      // 0: the solver's default
  int iterations = 0;    // 0: the solver's default
  double tolerance = 0;  // 0: default
  bool watchdog = true;
  bool freeze = false;  // VBD: freeze regions at rest; XPBD: pieces at rest sleep
  // XPBD with freeze: the static finish of sleeping pieces on a thread of its own (lands when
  // its job ends: wall time) or, when false, one cycle per step (the same frames on every run:
  // lock-step replays). XpbdOptions::finish_thread.
  bool finish_thread = true;
  bool settle = true;          // XPBD: settle pieces at rest (XpbdOptions::settle)
  bool chebyshev = false;      // VBD
  bool springs_model = false;  // the baseline's 8-spring energy instead of FEM + bending
  int threads = 2;
  // XPBD: > 0 cooks a cut's new topology on a worker thread while the cloth steps on uncut for
  // this many steps per 32 768 triangles (CookAheadSolver: no stall on a cut); 0 cooks it in the
  // step.
  int cook_ahead_ticks = 0;
  double air_drag = -1;  // 1/s, VBD and XPBD; < 0: the solver's default (1/s, as Verlet)
};

// The default real-time solver, chosen on the run-time-against-error chart of
// `./drape bench solvers` (docs/solvers.md): XPBD reaches a given error in less time than VBD
// on every reference scene (sim/testbeds).
inline constexpr const char* kDefaultSolver = "xpbd";

// Names: "default" (= kDefaultSolver), "vbd", "xpbd", "newton", "verlet" (the explicit
// baseline).
Result<std::unique_ptr<Solver>> make_solver(const std::string& name, const SolverConfig& cfg = {});

}  // namespace drape::sim
