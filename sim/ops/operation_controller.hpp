// What the app feeds: named triggers (begin/end) and hand proxies → operations, on the sim
// thread. Installs itself into the World's hooks, keeps the undo history, records sessions and
// replays them step for step (bit-identical in lock-step).
//
// Use from any thread through the SimThread:  sim.post([c](World& w) { c->trigger(w, "pinch",
// TriggerPhase::kBegin, 1); });  every method must run on the sim thread (inside a command or
// while the thread is stopped).
#pragma once

#include <array>
#include <memory>
#include <string>

#include "sim/ops/history.hpp"
#include "sim/ops/operations.hpp"
#include "sim/ops/session_log.hpp"

namespace drape::sim {

class OperationController {
 public:
  explicit OperationController(OperationParams params = {}) : params_(std::move(params)) {}

  // Sets world.before_step / after_step / decorate_snapshot to this controller (which must
  // outlive the world's use of them; keep it in a shared_ptr captured by the hooks' owner).
  void install(World& w);

  // Hand proxies for this tick (id 0 left, 1 right). Non-finite poses are ignored with a reason.
  void set_hands(World& w, const std::array<HandProxy, 2>& hands);
  // Trigger names: pinch, release, pin, cut, move, map, smooth, undo, redo, stop, next (the
  // hand's next candidate particle, see select_candidate). Unknown names are ignored with a
  // reason. hand: 0 left, 1 right (move uses both hands).
  void trigger(World& w, const std::string& name, TriggerPhase phase, int hand);
  // A predetermined cut line (Table 3-3: "cut along a predefined line").
  void cut_stroke(World& w, int hand, const std::vector<Vec3>& points);
  // Chooses which candidate (0 = best) the hand's next pinch takes (layered cloth).
  void select_candidate(World& w, int hand, int index);

  // Recording: from now on every input is logged with its step; the log starts from the cloth
  // as it is now. stop_recording() stamps the final step and state hash.
  void start_recording(const World& w);
  SessionLog stop_recording(const World& w);
  bool recording() const { return recording_; }
  // Replay: restores the session's cloth and scene objects into w, then feeds the logged inputs
  // at their steps (live inputs are ignored meanwhile). replaying() is false once done.
  void start_replay(World& w, SessionLog log);
  bool replaying() const { return replaying_; }
  uint64_t step() const { return step_; }

  const OperationsState& state() const { return state_; }
  OperationsState& state() { return state_; }
  const History& history() const { return history_; }
  History& history() { return history_; }
  // A checkpoint's step count (restore_checkpoint).
  void set_step(uint64_t step) { step_ = step; }
  OperationParams& params() { return params_; }

  // The hooks (public so a caller can chain them with its own).
  void before_step(World& w, double dt);
  void after_step(World& w, double dt);
  void decorate(const World& w, SceneSnapshot& snap) const;

 private:
  void apply_hands(World& w, const std::array<HandProxy, 2>& hands);
  void apply_trigger(World& w, const std::string& name, TriggerPhase phase, int hand);
  void apply_stroke(World& w, int hand, const std::vector<Vec3>& points);
  void next_candidate(World& w, TriggerPhase phase, int hand);
  bool active(const std::string& name, int hand) const;
  void log(SessionEvent e);

  OperationParams params_;
  OperationsState state_;
  History history_;
  uint64_t step_ = 0;
  bool recording_ = false, replaying_ = false, feeding_ = false;
  SessionLog log_;
  size_t replay_pos_ = 0;
};

}  // namespace drape::sim
