// The static finish of sleeping pieces (sim/rest/equilibrium_finisher.hpp) on a thread of its own.
//
// Finishing a piece that has fallen asleep takes ~20 cycles; at 128^2 a cycle is ~0.3 s
// (its coarse Newton step), at the app's 24^2 ~23 ms. Run on the simulation thread, one cycle
// per frame, that makes the fixed-rate loop miss its ticks for ~20 frames after a drape comes to
// rest. Here a job takes a copy of the cloth and of the scene when the pieces fall asleep and
// runs all its cycles on a thread of its own; the solver polls it once per frame, and when it
// has ended and its pieces are still asleep (not woken, not cut), copies their finished
// positions back in one frame. A piece that wakes while its job runs has the job cancelled (it
// stops after its current cycle) and its result dropped.
//
// Only the job's thread touches its copies while it runs; the solver reads them after joining
// it, so nothing is shared but two atomic flags (tests/sim/rest/finish_thread_test.cpp runs in the
// TSan build).
#pragma once

#include <atomic>
#include <thread>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/core/scene_objects.hpp"
#include "sim/energy/energy.hpp"
#include "sim/rest/equilibrium_finisher.hpp"

namespace drape::sim {

class FinishThread {
 public:
  FinishThread() = default;
  FinishThread(const FinishThread&) = delete;
  FinishThread& operator=(const FinishThread&) = delete;
  // Cancels a running job and waits for its current cycle to end.
  ~FinishThread();

  // Starts a job: finishes the vertices with group[i] >= 0 of a copy of `cloth` (friction
  // anchored where they are now) against a copy of `scene`, up to options.cycles cycles.
  // Throws std::logic_error while a job is busy and std::invalid_argument when `group` does
  // not have one entry per vertex.
  void start(const Cloth& cloth, const SceneObjects& scene, const std::vector<int>& group,
             const EnergyOptions& energy_options, const FinisherOptions& options);
  // A job was started and not yet collected.
  bool busy() const { return thread_.joinable(); }
  // The busy job has ended (finished or cancelled); collect() will not wait.
  bool ended() const { return done_.load(std::memory_order_acquire); }
  // Asks the busy job to stop after its current cycle; does not wait.
  void cancel() { cancel_.store(true, std::memory_order_relaxed); }
  // Waits for the busy job, ends it and returns its stats (stats.cycles: the cycles it ran).
  FinisherStats collect();

  // The job's copy (valid after collect() until the next start()): its finished positions,
  // the topology version they belong to, and the group it was started with.
  const Cloth& cloth() const { return cloth_; }
  const std::vector<int>& group() const { return group_; }
  // The positions the job started from (the caller compares them with its cloth's before it
  // uses the result: a vertex moved meanwhile by anything but the solver means the job's
  // result is stale for its piece).
  const std::vector<Vec3>& start_positions() const { return start_; }
  // The job ran to its end (converged or out of cycles) rather than being cancelled.
  bool completed() const { return completed_; }
  // The job's thread runs at a lower priority than the fixed-rate simulation and the renderer
  // (Linux: its nice value raised by this much; 0 keeps the caller's), so that on two cores the
  // finish takes the time they leave rather than stretching their ticks. With nice +10 the
  // kernel's fair scheduler still gives it about a tenth of a core under full load, so a finish
  // is delayed, never starved. Applies to jobs started after it is set.
  void set_nice(int n) { nice_ = n; }
  // The nice value the last job's thread ran at (Linux; 0 elsewhere).
  int job_nice() const { return job_nice_; }

 private:
  void work();

  std::thread thread_;
  std::atomic<bool> cancel_{false}, done_{false};
  Cloth cloth_;
  SceneObjects scene_;
  std::vector<int> group_;
  std::vector<Vec3> start_;
  EnergyOptions energy_options_;
  EquilibriumFinisher finisher_;  // kept from job to job (its cooked energy, its pattern)
  FinisherStats stats_;
  bool completed_ = false;
  int nice_ = 10, job_nice_ = 0;
};

}  // namespace drape::sim
