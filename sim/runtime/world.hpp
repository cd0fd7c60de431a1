// Everything the simulation thread owns: the cloth, the scene, the solver, and hooks through
// which higher-level modules (operations) act before and after each step.
#pragma once

#include <deque>
#include <functional>
#include <memory>
#include <string>

#include "sim/core/cloth.hpp"
#include "sim/core/scene_objects.hpp"
#include "sim/core/snapshot.hpp"
#include "sim/solvers/solver.hpp"

namespace drape::sim {

struct World {
  Cloth cloth;
  SceneObjects scene;
  std::unique_ptr<Solver> solver;
  bool paused = false;  // geometric work in progress: no dynamics
  // Ticks completed before the one running now (SimThread sets it before the tick's commands):
  // the tick index a command's input is journaled under (journal.hpp).
  uint64_t tick = 0;

  // Hooks set by higher-level modules (e.g. operations): run on the sim thread. at_tick_start
  // runs at the start of each tick, after `tick` is set and before the tick's commands (a
  // session's checkpoints: sim/ops/checkpoint.hpp).
  std::function<void(World&)> at_tick_start;
  std::function<void(World&, double dt)> before_step;
  std::function<void(World&, double dt)> after_step;
  std::function<void(const World&, SceneSnapshot&)> decorate_snapshot;

  // Recent status lines (bounded): ignored commands with reasons, watchdog reports, ...
  std::deque<std::string> messages;
  void report(std::string msg) {
    messages.push_back(std::move(msg));
    while (messages.size() > 32) messages.pop_front();
  }
  StepStats last_step;
};

// Fills a snapshot from the world (cloth arrays, normals, objects, hands, messages), then
// calls decorate_snapshot. Reuses the snapshot's buffers.
void fill_snapshot(const World& world, SceneSnapshot& snap);

}  // namespace drape::sim
