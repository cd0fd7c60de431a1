// A cut without a stall: XPBD whose re-cook after a topology edit runs on a worker thread while
// the solver steps on with the topology it has cooked.
//
// A cut (or slit) only adds vertices: it duplicates the vertices of its path, keeps every other
// index and moves the triangles on one side onto the duplicates. The solver cooked for the cloth
// before the edit (the base) is therefore still a valid model of that cloth with the edit not
// yet made. When a step finds the topology changed that way, CookAheadSolver
//   * copies the cloth and cooks a second XpbdSolver for it on a worker thread, which also makes
//     the new solver's first-step work (XpbdSolver::warm) and, on a machine short of cores,
//     waits while each step runs (TickGate); once the solver is ready it copies what the next
//     edit's cook reads of its energy (ClothEnergy::spare_copy), beside the steps that use it;
//   * for the next `ticks` steps steps the base instead: each step copies the cloth's state of
//     the base's vertices into the base cloth, steps it with the cooked solver and copies the
//     result back; each new vertex follows the base vertex it was duplicated from (a hand,
//     pin or move acting on a new vertex acts on that vertex);
//   * at the step `ticks` after the edit adopts the new solver (waiting for the worker if it
//     has not finished), which starts from the base's single-precision anchors, and steps the
//     cloth as it is.
// The physical effect of the edit lands `ticks` steps late, always at the same step, whatever
// the worker's speed: runs, replays and resumed checkpoints give the same result bit for bit.
// `ticks` grows with the cloth (CookAheadOptions::ticks per 32 768 triangles), and by half with
// self-collision on (costlier steps), so the cook has time to end on a machine as loaded as the
// one it ran on. Other edits (an undo that removes vertices, a new cloth) are cooked in the
// step, as plain XPBD does.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "sim/core/thread_pool.hpp"
#include "sim/solvers/solver.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"

namespace drape::sim {

struct CookAheadOptions {
  int ticks = 8;  // steps from the edit to the new topology's first step, per 32 768 triangles
  // The same in percent with self-collision on: its steps leave the worker ~40 % less time
  // between them (128^2 on two cores, 24 runs: at 12 ticks one swap waited for the worker, at
  // 8 seven did).
  int self_collision_percent = 150;
  // The worker cooks on worker_threads threads of its own, at idle priority (Linux SCHED_IDLE)
  // with idle_priority: they take the time the ticks leave rather than stretching them.
  bool idle_priority = true;
  int worker_threads = 2;
  // The next cut's cook starts from the current topology's energy (incremental): the cook's
  // worker copies the energy it cooked, and a topology cooked in a step has its energy built on
  // a worker; false: that cook builds it whole.
  bool spare_energy = true;
  // The worker also makes the first step's inverse masses, bending blocks and single-precision
  // anchor terms (XpbdSolver::warm), so that the swap's step costs what any step does.
  bool warm = true;
  // The worker's threads wait while a step runs (TickGate): kAuto when the machine has fewer
  // cores than the solver's and the worker's threads together, where a thread at SCHED_IDLE
  // alone still takes slices of a core a step needs (measured on two cores: 2-4 ms inside a
  // 5 ms step). On more cores the worker runs beside the steps, and so it does beside steps
  // that follow one another without a pause (they overran their period: no time is left
  // between them). kAlways: every step (tests).
  enum class KeepOff { kAuto, kAlways, kNever };
  KeepOff keep_off_steps = KeepOff::kAuto;
  // Tests: the worker sleeps this long before it cooks (a slow or loaded machine; the result
  // must not change, only the due step waits).
  int worker_delay_ms = 0;
};

class CookAheadSolver : public Solver {
 public:
  explicit CookAheadSolver(XpbdOptions xpbd, CookAheadOptions opt = {});
  ~CookAheadSolver() override;
  std::string name() const override { return active_->name(); }
  StepStats step(Cloth& cloth, const SceneObjects& scene, double dt) override;
  ThreadPool* pool() override { return active_->pool(); }
  // Not pending: the XPBD solver's state as it saves it. Pending: the base cloth, the steps
  // left and the XPBD solver's state on the base (restore cooks the edit again on the worker).
  std::vector<unsigned char> save_state(const Cloth& cloth) const override;
  std::string restore_state(const std::vector<unsigned char>& bytes, const Cloth& cloth) override;

  // The solver stepping now (the base's while an edit is pending).
  XpbdSolver& xpbd() { return *active_; }
  const XpbdSolver& xpbd() const { return *active_; }
  // An edit is pending: the base steps, the worker cooks; steps until the new topology's first.
  bool pending() const { return pending_; }
  int steps_left() const { return steps_left_; }
  // Edits taken ahead (adopted or pending) and edits cooked in the step.
  int edits_ahead() const { return edits_ahead_; }
  int edits_in_step() const { return edits_in_step_; }
  // Steps at which the worker had not finished when its topology was due (the step waited).
  int waits() const { return waits_; }
  // The last edit taken ahead: wall ms from the end of the edit's step (the worker's release)
  // to the worker's start (after the worker before it ended), to the new solver ready, and to
  // the end of its spare energy copy (-1 until then).
  double start_ms() const { return start_ms_.load(std::memory_order_relaxed); }
  double ready_ms() const { return ready_ms_.load(std::memory_order_relaxed); }
  double spare_ms() const { return spare_ms_.load(std::memory_order_relaxed); }
  // The process's page faults while the worker made the new solver ready (its cook's first
  // touches of fresh memory; the steps beside it allocate nothing).
  long ready_faults() const { return ready_faults_.load(std::memory_order_relaxed); }
  // Steps from an edit of this cloth to its first step with the new topology, in a scene with
  // self-collision or without.
  int ticks_for(const Cloth& cloth, bool self_collision = false) const;

 private:
  // Each vertex of `cloth` maps onto a base vertex: itself below the base's count, else the base
  // vertex with its origin and (bit for bit) its position; false when one does not (the edit
  // is then cooked in the step).
  bool map_onto_base(const Cloth& cloth);
  bool mapped(const Cloth& cloth);  // map_onto_base once per topology of the cloth
  void start(const Cloth& cloth, int steps, double dt);  // the worker cooks `cloth`
  void adopt();  // the worker's solver becomes the active one
  StepStats step_base(Cloth& cloth, const SceneObjects& scene, double dt);
  void keep_base(const Cloth& cloth);  // the cloth the active solver is cooked for
  void join();

  CookAheadOptions opt_;
  std::unique_ptr<XpbdSolver> active_, next_;
  // The cloth the active solver is cooked for (topology, fabric, masses; the state of its
  // vertices comes from the stepped cloth in each step), and each cloth vertex's base vertex.
  Cloth base_;
  bool have_base_ = false;
  std::vector<int32_t> src_;
  bool map_ok_ = false;
  uint64_t mapped_version_ = 0;  // the topology src_ was made for (0: none)
  int mapped_n_ = -1;
  // The edit cooked by the worker: its cloth (kept as the next base) and the steps left.
  bool pending_ = false;
  int steps_left_ = 0;
  Cloth next_cloth_;
  std::vector<int32_t> next_src_;  // its vertices' base vertices
  bool self_collision_ = false;    // the last step's scene has self-collision (the worker warms it)
  std::thread worker_;
  std::atomic<bool> done_{false};        // the worker has cooked (it copies the spare energy after)
  const XpbdSolver* copying_ = nullptr;  // the solver whose energy that copy reads
  std::atomic<bool> released_{false};    // the worker may start (release())
  // Closed while a step runs (keep_off_: kAuto's cores rule) that began 1 ms or more after the
  // last one ended: the worker's threads wait at their pause points.
  TickGate gate_;
  bool keep_off_ = false;
  std::chrono::steady_clock::time_point last_step_end_{};
  // What the next edit's cook reads of the base's energy (ClothEnergy::spare_copy), made by a
  // worker after each new base (only workers touch it, one after the other): that cook updates
  // it for the triangles the edit reached instead of building it whole.
  std::unique_ptr<ClothEnergy> spare_;
  void start_spare(const Cloth& cloth);  // a worker builds spare_ for a topology cooked in a step
  // Starts `job` on a new worker thread (after the one before it ends), at idle priority, with a
  // pool of its own.
  void launch(std::function<void(ThreadPool&)> job);
  void release();  // the step that launched the worker is done: it may start
  // Runs `wait` (a step's wait for a thread that waits at the gate) with the gate open.
  void with_gate_open(const std::function<void()>& wait);
  // A solver and base cloth retired by a swap are destroyed off the step, after it (its threads
  // are joined there).
  std::thread reaper_;
  int edits_ahead_ = 0, edits_in_step_ = 0, waits_ = 0;
  std::atomic<double> start_ms_{-1}, ready_ms_{-1}, spare_ms_{-1};
  std::atomic<long> ready_faults_{-1};
  // When release() let the worker go: steady_clock ticks (the worker's times count from it).
  std::atomic<std::chrono::steady_clock::rep> released_at_{0};
};

}  // namespace drape::sim
