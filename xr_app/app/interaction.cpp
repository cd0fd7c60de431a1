// The draping session's interaction: every hand input goes through the tracking XR adapter
// (tracking::XrHandSource: the joints of XR_EXT_hand_tracking and the controller's grip pose,
// trigger, squeeze, buttons, thumbstick and trackpad); its triggers, the gestures' and the voice
// cues' go through the command map (per hand, and per interaction profile for controllers) to
// the sim's operations, except the help, which the session shows itself.
#include <cstdio>

#include "xr_app/app/draping_session.hpp"

namespace drape::app {

namespace {
tracking::Vec3 vec3(const XrVector3f& p) {
  return tracking::Vec3(p.x, p.y, p.z);
}
tracking::Quat quat(const XrQuaternionf& q) {
  return tracking::Quat(q.w, q.x, q.y, q.z);
}

sim::TriggerPhase sim_phase(tracking::Phase p) {
  switch (p) {
    case tracking::Phase::End:
      return sim::TriggerPhase::kEnd;
    case tracking::Phase::Toggle:
      return sim::TriggerPhase::kToggle;
    case tracking::Phase::Begin:
    case tracking::Phase::Once:
      break;
  }
  return sim::TriggerPhase::kBegin;
}
}  // namespace

void DrapingSession::interact(int64_t frame, const HandInput& in) {
  if (!sim_) return;
  const double t = static_cast<double>(frame) / 90.0;
  std::array<sim::HandProxy, 2> hands{};
  std::vector<tracking::Trigger> trig;
  overlays_.clear();
  if (opt_.hands != "xr")
    read_external_hands(t, hands, trig);
  else
    for (int h = 0; h < 2; ++h) read_hand(h, t, in, hands[h], trig);
  hear_cues(frame, t, trig);
  const std::vector<Op> use = map_triggers(frame, trig);
  if (hands[1].tracked) {
    posted_.push_back({frame, hands[1].position, Clock::now()});
    if (posted_.size() > 256) posted_.erase(posted_.begin());
  }
  bool cut_trigger = false;
  for (const auto& op : use) cut_trigger = cut_trigger || op.name == "cut" || op.name == "stop";
  if (ops_) {
    auto ops = ops_;
    std::shared_ptr<FreeOutcomes> free = free_;  // the pinches taken and let go, both modes
    std::shared_ptr<Said> said = said_;
    // The journal's record of this input (--record), written on the sim thread before it is
    // applied, under the tick that applies it.
    std::shared_ptr<sim::JournalWriter> journal = journal_;
    sim::JournalTick rec;
    if (journal) {
      rec.hands = hands;
      for (const auto& op : use)
        rec.ops.push_back({op.name, static_cast<uint8_t>(op.phase), static_cast<int8_t>(op.hand)});
      for (const auto& tr : trig)
        if (tr.source == "voice" && tr.begin) rec.phrases.push_back(tr.command);
    }
    sim_->post([ops, hands, use, free, said, journal, rec](sim::World& w) mutable {
      if (journal && journal->is_open()) {
        rec.tick = w.tick;
        if (std::string e = journal->write(rec); !e.empty()) {
          w.report("journal: " + e + " (recording stopped)");
          journal->close();
        }
      }
      ops->set_hands(w, hands);
      w.scene.hands.assign(hands.begin(), hands.end());  // into the snapshot (latency probe)
      apply_triggers(w, use, *ops, *said);
      if (free) note_free_outcomes(w, ops->state(), *free);
    });
  }
  if (opt_.sim_lock_step) {
    sim_->advance(1);  // orders the sim's writes before these reads (sim_thread.hpp)
    if (ops_) note_lock_step_outcomes(cut_trigger);
    if (ops_) drain_pinch_lines();
  } else if (ops_) {
    drain_free_outcomes();
  }
  if (ops_) drain_said(frame);
  poll_saves(frame, false);  // refusals and the hands' operations into the feedback panel
  drain_exports();           // mid-session patterns written by the pattern worker
  if (!ext_)
    feedback_.set_status("hands", hands[0].tracked || hands[1].tracked ? "" : "no hand tracked");
}

// On the sim thread, after a frame's hands and triggers: pinches taken and let go (with how far
// the particle moved while held) and the frames spent holding one.
void DrapingSession::note_free_outcomes(const sim::World& w, const sim::OperationsState& st,
                                        FreeOutcomes& out) {
  auto at = [](const sim::Vec3& p) {
    char b[96];
    std::snprintf(b, sizeof b, "(%.3f, %.3f, %.3f)", p.x(), p.y(), p.z());
    return std::string(b);
  };
  std::vector<std::string> lines;
  for (int h = 0; h < 2; ++h) {
    const int32_t v = st.pinched[h], was = out.pinched[h];
    if (v == was) continue;
    const std::string hand = tracking::hand_name(static_cast<tracking::Hand>(h));
    if (was >= 0 && was < w.cloth.num_vertices()) {
      const sim::Vec3& p = w.cloth.state.x[was];
      char b[64];
      std::snprintf(b, sizeof b, " (moved %.1f mm)", (p - out.taken_at[h]).norm() * 1e3);
      lines.push_back("pinch: " + hand + " hand let particle " + std::to_string(was) + " go at " +
                      at(p) + b);
    }
    if (v >= 0 && v < w.cloth.num_vertices()) {
      out.taken_at[h] = w.cloth.state.x[v];
      lines.push_back("pinch: " + hand + " hand took particle " + std::to_string(v) + " at " +
                      at(out.taken_at[h]));
    }
    out.pinched[h] = v;
  }
  for (int h = 0; h < 2; ++h) out.busy[h] = st.pinched[h] >= 0 || st.cutting[h];
  if (st.pinched[0] >= 0 || st.pinched[1] >= 0) ++out.frames_pinched;
  if (lines.empty()) return;
  std::lock_guard lock(out.m);
  for (auto& l : lines) out.lines.push_back(std::move(l));
}

// On the frame loop (free-running sim): the sim thread's pinch outcomes into the result and the
// log.
void DrapingSession::drain_free_outcomes() {
  rep_.r.frames_pinched = free_->frames_pinched;
  for (int h = 0; h < 2; ++h) ops_busy_[h] = free_->busy[h];
  drain_pinch_lines();
}

// The pinches taken and let go (note_free_outcomes' lines) into the log.
void DrapingSession::drain_pinch_lines() {
  std::vector<std::string> lines;
  {
    std::lock_guard lock(free_->m);
    lines.swap(free_->lines);
  }
  for (const auto& l : lines) rep_.note(l);
}

namespace {
// The controller's buttons, stick and trackpad for the XR adapter.
void feed_buttons(const ControllerState& c, tracking::XrControllerInput& ci) {
  ci.trigger = c.trigger;
  ci.squeeze = c.squeeze;
  ci.a = c.a;
  ci.b = c.b;
  ci.menu = c.menu;
  ci.stick_x = c.stick.x;
  ci.stick_y = c.stick.y;
  ci.stick_click = c.stick_click;
  ci.pad_x = c.pad.x;
  ci.pad_y = c.pad.y;
  ci.pad_click = c.pad_click;
}
}  // namespace

void DrapingSession::read_hand(int h, double t, const HandInput& in, sim::HandProxy& hand,
                               std::vector<tracking::Trigger>& trig) {
  const auto side = static_cast<tracking::Hand>(h);
  hand.id = h;
  tracking::HandFrame joint_frame;
  bool have_joint_frame = false;
  if (in.has_tracker[h]) {
    tracking::XrJointInput ji;
    ji.active = in.joints_active[h];
    ji.time = t;
    for (int k = 0; k < tracking::kJointCount; ++k) {
      const auto& jl = in.joints[h][k];
      ji.joints[k].position = vec3(jl.pose.position);
      ji.joints[k].orientation = quat(jl.pose.orientation);
      if (ji.joints[k].orientation.norm() > 0.5) ji.joints[k].orientation.normalize();
      ji.valid[k] =
          in.joints_active[h] && (jl.locationFlags & XR_SPACE_LOCATION_POSITION_VALID_BIT);
    }
    xr_source_.feed_joints(side, ji);
    for (const auto& f : xr_source_.poll()) {
      // A held controller's joints are the runtime's synthesis from its buttons: its gestures
      // are ignored (a lost frame ends any in progress) so that a button never fires twice.
      tracking::HandFrame g = f;
      g.tracked = f.tracked && !in.controllers[h].active;
      lost_frames_[h] = f.tracked || in.controllers[h].active ? 0 : lost_frames_[h] + 1;
      if (lost_frames_[h] == 0) {
        gestures_.update(g, trig);
      } else if (lost_frames_[h] > grace_frames_) {
        // Lost past the sim's grace: the sim has ended the hand's operations itself
        // (sim::ops_track_loss), so the ends the recognizer makes now are not sent. Within the
        // grace the recognizer keeps its state: a hand back in time goes on with its gesture.
        std::vector<tracking::Trigger> ended;
        gestures_.update(g, ended);
      }
      if (f.tracked && f.has_joints) {
        joint_frame = f;
        have_joint_frame = true;
      }
    }
  }
  const ControllerState& c = in.controllers[h];
  tracking::XrControllerInput ci;
  ci.time = t;
  if (c.active) {
    ci.active = true;
    ci.grip.position = vec3(c.grip.position);
    ci.grip.orientation = quat(c.grip.orientation);
  }
  feed_buttons(c, ci);
  profiles_[h] = c.profile;
  xr_source_.feed_controller(side, ci);
  tracking::HandFrame ctrl_frame;
  bool have_ctrl = false;
  for (const auto& f : xr_source_.poll())
    if (f.tracked) {
      ctrl_frame = f;
      have_ctrl = true;
    }
  for (auto& tr : xr_source_.take_triggers()) trig.push_back(tr);
  render::HandOverlay ov;
  ov.id = h;
  if (have_joint_frame) {
    // The hand proxy: the pinch point between the thumb and index tips (palm orientation).
    const auto& J = joint_frame.joints;
    hand.tracked = true;
    hand.position = 0.5 * (J[static_cast<int>(tracking::Joint::ThumbTip)] +
                           J[static_cast<int>(tracking::Joint::IndexTip)]);
    hand.orientation = joint_frame.palm.orientation;
    hand.tip = hand.position;
    hand.radius = 0.02;
    ov.has_joints = true;
    for (int k = 0; k < tracking::kJointCount; ++k) ov.joints[k] = J[k].cast<float>();
  } else if (have_ctrl) {
    // No hand tracking for this hand: the controller's grip pose is the hand.
    hand.tracked = true;
    hand.position = ctrl_frame.palm.position;
    hand.orientation = ctrl_frame.palm.orientation;
    hand.tip = hand.position;
    hand.radius = 0.03;
  }
  if (hand.tracked) {
    ov.pointer = hand.position.cast<float>();
    ov.active = gestures_.pinching(side) || ops_busy_[h];
    overlays_.push_back(ov);
  }
}

// Triggers -> the command map (assets/commands.json) -> operations of the sim.
std::vector<DrapingSession::Op> DrapingSession::map_triggers(
    int64_t frame, const std::vector<tracking::Trigger>& trig) {
  std::vector<Op> use;
  for (const auto& tr : trig) {
    const int hi = static_cast<int>(tr.hand);
    const auto act = commands_.lookup(tr, tr.source == "controller" ? profiles_[hi] : "");
    std::string line = "frame " + std::to_string(frame) + ": " + tr.source + " " + tr.command +
                       (tr.begin ? " begin" : " end") + " hand " + tracking::hand_name(tr.hand);
    if (!act) {
      if (opt_.verbose) rep_.note("unmapped trigger " + line);
      continue;
    }
    Op op{act->operation, sim_phase(act->phase), static_cast<int>(tr.hand)};
    if (op.name == "*") {  // "stop": ends whatever is in progress
      op.name = "stop";
      op.phase = sim::TriggerPhase::kBegin;
    }
    line += " -> " + op.name + " " + tracking::phase_name(act->phase);
    rep_.r.triggers.push_back(line);
    if (opt_.verbose) rep_.note("trigger " + line);
    // Saving is the app's: the sim copies the session, another thread writes the file.
    if (op.name == "save") {
      if (act->phase != tracking::Phase::End) save_session(frame);
      continue;
    }
    if (app_operation(*act, op)) continue;
    use.push_back(op);
  }
  return use;
}

// Lock step: the tick of this frame has run; its pinches and cuts are this frame's outcome.
void DrapingSession::note_lock_step_outcomes(bool cut_trigger) {
  XrAppResult& r = rep_.r;
  const auto& st = ops_->state();
  if (st.pinched[0] >= 0 || st.pinched[1] >= 0) ++r.frames_pinched;
  bool cut_end = false;
  for (int h = 0; h < 2; ++h) {
    cut_end = cut_end || (cut_trigger && cutting_[h] && !st.cutting[h]);
    cutting_[h] = st.cutting[h];
    ops_busy_[h] = st.pinched[h] >= 0 || st.cutting[h];
  }
  if (!cut_end) return;
  if (st.last_cut.ok) {
    ++r.cuts_ok;
    r.cut_new_vertices += static_cast<int>(st.last_cut.new_vertices.size());
    r.components_before = st.last_cut.components_before;
    r.components_after = st.last_cut.components_after;
  }
  rep_.note("cut: " + std::string(st.last_cut.ok ? "ok" : "failed: " + st.last_cut.reason) +
            ", components " + std::to_string(st.last_cut.components_before) + " -> " +
            std::to_string(st.last_cut.components_after));
}

}  // namespace drape::app
