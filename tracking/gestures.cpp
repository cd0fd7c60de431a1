#include "tracking/gestures.hpp"

#include <algorithm>
#include <cmath>

namespace drape::tracking {

int Debounced::update(bool raw, double t, double min_duration) {
  if (raw != cand_) {
    cand_ = raw;
    since_ = t;
  }
  if (cand_ != on_ && t - since_ >= min_duration) {
    on_ = cand_;
    return on_ ? 1 : -1;
  }
  return 0;
}

void GestureRecognizer::emit(int edge, const char* name, const HandFrame& f,
                             std::vector<Trigger>& out) {
  if (edge == 0) return;
  out.push_back(Trigger{name, "gesture", f.time, f.hand, edge > 0});
}

namespace {
constexpr const char* kPinchNames[4] = {"pinch", "pinch_middle", "pinch_ring", "pinch_little"};
constexpr Joint kTips[4] = {Joint::IndexTip, Joint::MiddleTip, Joint::RingTip, Joint::LittleTip};
}  // namespace

HandShape hand_shape(const HandFrame& f) {
  auto J = [&](Joint j) { return f.joints[static_cast<int>(j)]; };
  HandShape s;
  const Vec3 palm = J(Joint::Palm);
  for (int k = 0; k < 4; ++k) {
    s.tip_distance[k] = (J(Joint::ThumbTip) - J(kTips[k])).norm();
    s.curl += (J(kTips[k]) - palm).norm() / 4.0;
  }
  // XR_EXT_hand_tracking: a joint's +y points out of the back of the hand, +x across it.
  s.normal = f.palm.orientation * Vec3(0, -1, 0);
  const Vec3 across = f.palm.orientation * Vec3(1, 0, 0);
  const double tips = std::abs((J(Joint::LittleTip) - J(Joint::IndexTip)).dot(across));
  const double knuckles =
      std::abs((J(Joint::LittleProximal) - J(Joint::IndexProximal)).dot(across));
  s.spread = knuckles > 1e-3 ? tips / knuckles : 1.0;
  return s;
}

void GestureRecognizer::lose(const HandFrame& f, State& s, std::vector<Trigger>& out) {
  // Lost hand: end whatever was active (a lost pinch must not stay latched).
  for (int k = 0; k < 4; ++k) emit(s.pinch[k].update(false, f.time, 0.0), kPinchNames[k], f, out);
  emit(s.grab.update(false, f.time, 0.0), "grab", f, out);
  emit(s.flat.update(false, f.time, 0.0), "flat", f, out);
  emit(s.palm_up.update(false, f.time, 0.0), "palm_up", f, out);
  s.pinch_finger = -1;
  s.history.clear();
  s.dwell_fired = false;
}

void GestureRecognizer::update(const HandFrame& f, std::vector<Trigger>& out) {
  State& s = st_[static_cast<int>(f.hand)];
  if (!f.tracked) return lose(f, s, out);
  s.history.emplace_back(f.time, f.palm.position);
  const double keep = std::max(p_.dwell_time, p_.push_time) + 0.1;
  while (!s.history.empty() && f.time - s.history.front().first > keep) s.history.pop_front();
  if (f.has_joints) return update_joints(f, s, out);
  update_palm_only(f, s, out);
}

// The finger the thumb pinches: it starts below pinch_enter when that finger is clearly the
// nearest (a thumb between two fingertips pinches neither), and holds until pinch_leave; a fist
// takes no pinch.
void GestureRecognizer::update_pinch_finger(const HandShape& h, State& s) const {
  if (s.pinch_finger >= 0 && h.tip_distance[s.pinch_finger] > p_.pinch_leave) s.pinch_finger = -1;
  if (s.grab.on()) return;
  for (int k = 0; k < 4; ++k) {
    if (k == s.pinch_finger || h.tip_distance[k] >= p_.pinch_enter) continue;
    bool clearly = true;
    for (int j = 0; j < 4; ++j)
      if (j != k && h.tip_distance[k] >= p_.pinch_nearest * h.tip_distance[j]) clearly = false;
    if (clearly) s.pinch_finger = k;
  }
}

// Joints' push: the open hand's palm, facing forward, moved along its own normal by push_distance
// within push_time (then nothing for push_time).
bool GestureRecognizer::joint_push(const HandFrame& f, const HandShape& h, State& s) const {
  // Facing forward, not down: a flat hand pressing the cloth down (smoothing) is no push.
  if (f.time < s.push_block_until || std::abs(h.normal.dot(p_.up)) > 0.5) return false;
  for (const auto& [t, q] : s.history) {
    if (f.time - t > p_.push_time) continue;
    if ((f.palm.position - q).dot(h.normal) > p_.push_distance) {
      s.push_block_until = f.time + p_.push_time;
      return true;
    }
  }
  return false;
}

void GestureRecognizer::update_joints(const HandFrame& f, State& s, std::vector<Trigger>& out) {
  const HandShape h = hand_shape(f);
  update_pinch_finger(h, s);
  for (int k = 0; k < 4; ++k)
    emit(s.pinch[k].update(s.pinch_finger == k, f.time, p_.min_duration), kPinchNames[k], f, out);
  const bool no_pinch =
      s.pinch_finger < 0 && *std::min_element(h.tip_distance, h.tip_distance + 4) > p_.pinch_leave;
  const bool fist = h.curl < p_.grab_curl && s.pinch_finger < 0;
  const bool open = h.curl > p_.extend_curl && no_pinch;
  const bool flat = open && h.spread < p_.together && h.normal.dot(-p_.up) > p_.facing_cos;
  const bool up = open && h.normal.dot(p_.up) > p_.facing_cos;
  emit(s.grab.update(fist, f.time, p_.min_duration), "grab", f, out);
  emit(s.flat.update(flat, f.time, p_.min_duration), "flat", f, out);
  emit(s.palm_up.update(up, f.time, p_.min_duration), "palm_up", f, out);
  if (open && joint_push(f, h, s)) out.push_back(Trigger{"push", "gesture", f.time, f.hand, true});
}

// Palm-only source: dwell and push from the palm trajectory.
void GestureRecognizer::update_palm_only(const HandFrame& f, State& s, std::vector<Trigger>& out) {
  const Vec3 p = f.palm.position;
  // dwell: every sample in the last dwell_time within dwell_radius of the current position. Only
  // a move re-arms it: a gap in the samples (a source's burst) shortens the history, not the stay.
  bool moved = false;
  for (const auto& [t, q] : s.history)
    if (t >= f.time - p_.dwell_time && (q - p).norm() > p_.dwell_radius) moved = true;
  const bool still = !moved && s.history.front().first <= f.time - p_.dwell_time + 1e-9;
  if (still && !s.dwell_fired) {
    out.push_back(Trigger{"dwell", "gesture", f.time, f.hand, true});
    s.dwell_fired = true;
  } else if (moved) {
    s.dwell_fired = false;
  }
  if (f.time >= s.push_block_until) {
    for (const auto& [t, q] : s.history) {
      if (f.time - t > p_.push_time) continue;
      if ((p - q).dot(p_.push_axis.normalized()) > p_.push_distance) {
        out.push_back(Trigger{"palm_push", "gesture", f.time, f.hand, true});
        s.push_block_until = f.time + p_.push_time;
        break;
      }
    }
  }
}

void ButtonMapper::update(Hand h, const std::string& button, bool pressed, double t,
                          std::vector<Trigger>& out) {
  auto& v = state_[static_cast<int>(h)];
  auto it = std::find_if(v.begin(), v.end(), [&](auto& e) { return e.first == button; });
  if (it == v.end()) {
    v.emplace_back(button, false);
    it = v.end() - 1;
  }
  if (it->second != pressed) {
    it->second = pressed;
    out.push_back(Trigger{"button." + button, "controller", t, h, pressed});
  }
}

}  // namespace drape::tracking
