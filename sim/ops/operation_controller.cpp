// Triggers + hand proxies → operations, undo history, session record/replay (see header).
#include "sim/ops/operation_controller.hpp"

#include <cstdio>
#include <utility>

namespace drape::sim {

void OperationController::install(World& w) {
  w.before_step = [this](World& world, double dt) { before_step(world, dt); };
  w.after_step = [this](World& world, double dt) { after_step(world, dt); };
  w.decorate_snapshot = [this](const World& world, SceneSnapshot& snap) { decorate(world, snap); };
}

void OperationController::log(SessionEvent e) {
  if (!recording_) return;
  e.step = step_;
  log_.events.push_back(std::move(e));
}

void OperationController::set_hands(World& w, const std::array<HandProxy, 2>& hands) {
  if (replaying_ && !feeding_) return;  // the log drives the hands during a replay
  apply_hands(w, hands);
}

void OperationController::apply_hands(World& w, const std::array<HandProxy, 2>& hands) {
  SessionEvent e;
  e.kind = SessionEvent::Kind::kHands;
  e.hands = hands;
  log(std::move(e));
  ops_set_hands(w, state_, hands);
}

void OperationController::trigger(World& w, const std::string& name, TriggerPhase phase, int hand) {
  if (replaying_ && !feeding_) {
    if (name == "stop") {
      replaying_ = false;
      w.report("replay: stopped by the user");
    } else {
      w.report("trigger " + name + ": ignored during a replay");
    }
    return;
  }
  if (name == "next") return next_candidate(w, phase, hand);
  apply_trigger(w, name, phase, hand);
}

// "next": the hand's next pinch takes the next candidate particle (cycling back to the best),
// through select_candidate so the session log records a selection.
void OperationController::next_candidate(World& w, TriggerPhase phase, int hand) {
  if (phase == TriggerPhase::kEnd) return;
  if (hand != 0 && hand != 1) return w.report("trigger next: hand must be 0 or 1: ignored");
  const int n = static_cast<int>(state_.candidates[hand].particles.size());
  if (n == 0)
    return w.report(std::string("next: no candidate particle near the ") +
                    (hand == 0 ? "left" : "right") + " hand: ignored");
  select_candidate(w, hand, (state_.candidates[hand].chosen + 1) % n);
}

void OperationController::cut_stroke(World& w, int hand, const std::vector<Vec3>& points) {
  if (replaying_ && !feeding_) return w.report("cut stroke: ignored during a replay");
  apply_stroke(w, hand, points);
}

void OperationController::select_candidate(World& w, int hand, int index) {
  if (replaying_ && !feeding_) return;
  if ((hand != 0 && hand != 1) || index < 0)
    return w.report("select: hand must be 0 or 1 and index >= 0: ignored");
  SessionEvent e;
  e.kind = SessionEvent::Kind::kSelect;
  e.hand = hand;
  e.index = index;
  log(std::move(e));
  state_.selected[hand] = index;
  ops_update_candidates(w, state_, params_);
}

bool OperationController::active(const std::string& name, int hand) const {
  const int h = (hand == 0 || hand == 1) ? hand : 1;
  if (name == "pinch") return state_.pinched[h] >= 0;
  if (name == "cut") return state_.cutting[h];
  if (name == "move") return state_.moving;
  if (name == "smooth") return state_.smoothing[h];
  return false;
}

void OperationController::apply_stroke(World& w, int hand, const std::vector<Vec3>& points) {
  SessionEvent e;
  e.kind = SessionEvent::Kind::kStroke;
  e.hand = hand;
  e.points = points;
  log(std::move(e));
  Cloth before = history_.take_copy(w.cloth);
  OperationsState ops_before = state_;
  if (ops_cut_stroke(w, state_, params_, points))
    history_.push("cut", std::move(before), ops_before);
}

void OperationController::apply_trigger(World& w, const std::string& name, TriggerPhase phase,
                                        int hand) {
  static const char* kNames[] = {"pinch", "release", "pin",  "cut",  "move",
                                 "map",   "smooth",  "undo", "redo", "stop"};
  bool known = false;
  for (const char* k : kNames) known = known || name == k;
  if (!known) return w.report("trigger \"" + name + "\": unknown operation: ignored");
  if (hand != 0 && hand != 1) return w.report("trigger " + name + ": hand must be 0 or 1: ignored");
  SessionEvent e;
  e.kind = SessionEvent::Kind::kTrigger;
  e.name = name;
  e.phase = phase;
  e.hand = hand;
  log(std::move(e));

  const bool begin =
      phase == TriggerPhase::kBegin || (phase == TriggerPhase::kToggle && !active(name, hand));
  if (name == "undo" || name == "redo") {
    if (!begin) return;
    const std::string label =
        name == "undo" ? history_.undo(w.cloth, state_) : history_.redo(w.cloth, state_);
    if (label.empty())
      w.report(name + ": nothing to " + name + ": ignored");
    else
      w.report(name + ": " + label);
    ops_update_candidates(w, state_, params_);
    return;
  }
  if (name == "stop") {
    if (begin) ops_stop(w, state_);
    return;
  }
  // Operations that change the cloth keep the state before them for undo.
  const bool changes = !(name == "cut" && begin);
  Cloth before;
  OperationsState ops_before;
  if (changes) {
    before = history_.take_copy(w.cloth);
    ops_before = state_;
  }
  bool done = false;
  if (name == "pinch") {
    done = begin ? ops_pinch_begin(w, state_, params_, hand) : ops_pinch_end(w, state_, hand);
  } else if (name == "release") {
    if (begin) done = ops_release(w, state_, params_, hand);
  } else if (name == "pin") {
    if (begin) done = ops_pin(w, state_, params_, hand);
  } else if (name == "cut") {
    if (begin)
      ops_cut_begin(w, state_, hand);
    else
      done = ops_cut_end(w, state_, params_, hand);
  } else if (name == "move") {
    done = begin ? ops_move_begin(w, state_) : ops_move_end(w, state_);
  } else if (name == "map") {
    if (begin) done = ops_map(w, state_, hand);
  } else if (name == "smooth") {
    done = begin ? ops_smooth_begin(w, state_, hand) : ops_smooth_end(w, state_, hand);
    if (!begin) done = false;  // the state before smoothing began is the undo point
  }
  // The end of a pinch or move keeps no undo point: the state before its begin is the one to
  // return to (undo then leaves nothing in progress), as for smoothing.
  const bool ends_held = !begin && (name == "pinch" || name == "move");
  if (done && ends_held) history_.drop_redo();
  if (done && !ends_held) history_.push(name, std::move(before), ops_before);
}

void OperationController::start_recording(const World& w) {
  recording_ = true;
  step_ = 0;
  log_ = SessionLog{};
  log_.initial = w.cloth;
  log_.plates = w.scene.plates;
  log_.boxes = w.scene.boxes;
  log_.spheres = w.scene.spheres;
  log_.floor = w.scene.floor;
  log_.offset = w.scene.offset;
  // The hands as they are now, so a replay starts from the same proxies.
  SessionEvent e;
  e.kind = SessionEvent::Kind::kHands;
  e.hands = state_.hands;
  for (int h = 0; h < 2; ++h) e.hands[h].tracked = state_.hand_valid[h];
  log(std::move(e));
}

SessionLog OperationController::stop_recording(const World& w) {
  recording_ = false;
  log_.final_step = step_;
  log_.final_hash = state_hash(w.cloth);
  return std::move(log_);
}

void OperationController::start_replay(World& w, SessionLog log) {
  const uint64_t version = w.cloth.topology_version + 1;
  w.cloth = log.initial;
  w.cloth.topology_version = version;
  w.scene.plates = log.plates;
  w.scene.boxes = log.boxes;
  w.scene.spheres = log.spheres;
  w.scene.floor = log.floor;
  w.scene.offset = log.offset;
  state_ = OperationsState{};
  history_.clear();
  recording_ = false;
  log_ = std::move(log);
  replay_pos_ = 0;
  step_ = 0;
  replaying_ = true;
  w.report("replay: " + std::to_string(log_.events.size()) + " events over " +
           std::to_string(log_.final_step) + " steps");
  if (log_.final_step == 0) {
    feeding_ = true;
    for (; replay_pos_ < log_.events.size(); ++replay_pos_) {
      const SessionEvent& e = log_.events[replay_pos_];
      if (e.kind == SessionEvent::Kind::kHands) apply_hands(w, e.hands);
      if (e.kind == SessionEvent::Kind::kTrigger) apply_trigger(w, e.name, e.phase, e.hand);
      if (e.kind == SessionEvent::Kind::kStroke) apply_stroke(w, e.hand, e.points);
      if (e.kind == SessionEvent::Kind::kSelect) select_candidate(w, e.hand, e.index);
    }
    feeding_ = false;
    replaying_ = false;
  }
}

void OperationController::before_step(World& w, double dt) {
  if (replaying_) {
    feeding_ = true;
    while (replay_pos_ < log_.events.size() && log_.events[replay_pos_].step <= step_) {
      const SessionEvent& e = log_.events[replay_pos_++];
      switch (e.kind) {
        case SessionEvent::Kind::kHands:
          apply_hands(w, e.hands);
          break;
        case SessionEvent::Kind::kTrigger:
          apply_trigger(w, e.name, e.phase, e.hand);
          break;
        case SessionEvent::Kind::kStroke:
          apply_stroke(w, e.hand, e.points);
          break;
        case SessionEvent::Kind::kSelect:
          select_candidate(w, e.hand, e.index);
          break;
      }
    }
    feeding_ = false;
  }
  ops_before_step(w, state_, params_, dt);
}

void OperationController::after_step(World& w, double dt) {
  ops_after_step(w, state_, params_, dt);
  history_.prepare_spare(w.cloth);  // the next operation's undo copy allocates nothing
  ++step_;
  if (replaying_ && step_ >= log_.final_step && replay_pos_ >= log_.events.size()) {
    replaying_ = false;
    const uint64_t h = state_hash(w.cloth);
    char buf[128];
    std::snprintf(buf, sizeof buf, "replay: done at step %llu, state hash %016llx (%s)",
                  static_cast<unsigned long long>(step_), static_cast<unsigned long long>(h),
                  h == log_.final_hash ? "matches the recording" : "DIFFERS from the recording");
    w.report(buf);
  }
}

void OperationController::decorate(const World& w, SceneSnapshot& snap) const {
  ops_decorate(w, state_, snap);
}

}  // namespace drape::sim
