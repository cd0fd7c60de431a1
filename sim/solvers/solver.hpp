// One interface for every solver of the cloth energy (baseline Verlet, XPBD, VBD, Newton...).
#pragma once

#include <string>

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
};

}  // namespace drape::sim
