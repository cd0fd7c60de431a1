// One interface for every solver of the cloth energy (baseline Verlet, XPBD, VBD, Newton...).
#pragma once

#include <string>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/core/scene_objects.hpp"

namespace drape::sim {

class ThreadPool;  // sim/core/thread_pool.hpp

struct StepStats {
  int substeps = 0;
  int iterations = 0;          // total over substeps
  double residual = 0;         // solver-specific convergence measure at the end (0 if none)
  bool diverged = false;       // NaN/inf or blow-up detected (and rolled back when supported)
  int retries = 0;             // rollbacks performed by the watchdog
  double collision_ms = 0;     // time spent in collision detection/response
  double max_penetration = 0;  // deepest penetration found (m), before response
};

class Solver {
 public:
  virtual ~Solver() = default;
  virtual std::string name() const = 0;
  // Advances the cloth by one frame of length dt (substepping internally as configured),
  // against the scene's objects. Must not allocate per step once warmed up for a topology.
  virtual StepStats step(Cloth& cloth, const SceneObjects& scene, double dt) = 0;
  // The solver's worker threads, for work around its steps (the watchdog's checks), or null.
  virtual ThreadPool* pool() { return nullptr; }
  // The state the solver carries from one step to the next beyond the cloth (XPBD: warm-start
  // multipliers, the pieces' sleep and settling, the static finish in progress, the
  // single-precision anchors), as bytes, for its next step on `cloth`. restore_state() puts it
  // into a solver of the same configuration, with that cloth: the solver then steps on bit for
  // bit as the saved one would (a session's checkpoints, sim/ops/checkpoint.hpp). Only XPBD (the
  // session's solver) implements it; the others save nothing, and a checkpoint restores them as
  // fresh ones. restore_state() returns "" or why the bytes do not fit (the solver is then as a
  // fresh one).
  virtual std::vector<unsigned char> save_state(const Cloth& cloth) const {
    (void)cloth;
    return {};
  }
  virtual std::string restore_state(const std::vector<unsigned char>& bytes, const Cloth& cloth) {
    (void)cloth;
    return bytes.empty() ? "" : "the " + name() + " solver keeps no state to restore";
  }
};

}  // namespace drape::sim
