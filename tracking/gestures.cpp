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
    const double reach = (J(kTips[k]) - palm).norm();
    s.curl += reach / 4.0;
    if (k == 0)
      s.index_reach = reach;
    else
      s.others_curl += reach / 3.0;
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
  // Lost hand: end whatever was active (a lost pinch must not stay latched); a palm push that
  // waited for the other hand's is given now, the two hands' together state ends.
  const int h = static_cast<int>(f.hand);
  if (pending_push_[h] >= 0) {
    out.push_back(Trigger{"palm_push", "gesture", pending_push_[h], f.hand, true});
    pending_push_[h] = -1;
  }
  if (together_.on()) {
    HandFrame right = f;
    right.hand = Hand::Right;
    emit(together_.update(false, f.time, 0.0), "hands_together", right, out);
    together_ended_ = f.time;
  }
  for (int k = 0; k < 4; ++k) emit(s.pinch[k].update(false, f.time, 0.0), kPinchNames[k], f, out);
  emit(s.grab.update(false, f.time, 0.0), "grab", f, out);
  emit(s.point.update(false, f.time, 0.0), "point", f, out);
  emit(s.flat.update(false, f.time, 0.0), "flat", f, out);
  emit(s.palm_up.update(false, f.time, 0.0), "palm_up", f, out);
  s.pinch_finger = -1;
  s.history.clear();
  s.dwell_fired = false;
}

void GestureRecognizer::update(const HandFrame& f, std::vector<Trigger>& out) {
  State& s = st_[static_cast<int>(f.hand)];
  flush_pushes(f.time, out);
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
  // Pointing: the index finger out, the other three curled, no pinch (its mean curl can be a
  // fist's: pointing is no fist).
  const bool point = no_pinch && h.index_reach > p_.extend_curl && h.others_curl < p_.grab_curl;
  const bool fist = h.curl < p_.grab_curl && s.pinch_finger < 0 && !point;
  const bool open = h.curl > p_.extend_curl && no_pinch;
  const bool flat = open && h.spread < p_.together && h.normal.dot(-p_.up) > p_.facing_cos;
  const bool up = open && h.normal.dot(p_.up) > p_.facing_cos;
  emit(s.grab.update(fist, f.time, p_.min_duration), "grab", f, out);
  emit(s.point.update(point, f.time, p_.min_duration), "point", f, out);
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
  // Palms held together are the two hands' gesture, no dwell of either.
  if (still && !s.dwell_fired && !palms_near_) {
    out.push_back(Trigger{"dwell", "gesture", f.time, f.hand, true});
    s.dwell_fired = true;
  } else if (moved) {
    s.dwell_fired = false;
  }
  if (f.time >= s.push_block_until) {
    for (const auto& [t, q] : s.history) {
      if (f.time - t > p_.push_time) continue;
      if ((p - q).dot(p_.push_axis.normalized()) > p_.push_distance) {
        palm_pushed(f, out);
        s.push_block_until = f.time + p_.push_time;
        break;
      }
    }
  }
  update_two_hands(f, out);
}

// Whether the other hand's palm (palm-only) has a sample within pair_stale of f.
bool GestureRecognizer::other_palm_seen(const HandFrame& f) const {
  const State& o = st_[1 - static_cast<int>(f.hand)];
  return !o.history.empty() && std::abs(f.time - o.history.back().first) <= p_.pair_stale;
}

// A palm push of f's hand: with one hand seen, "palm_push" at once; with both, a push of the
// other hand waiting within both_push_window makes the pair a "both_push", else this one waits.
void GestureRecognizer::palm_pushed(const HandFrame& f, std::vector<Trigger>& out) {
  const int h = static_cast<int>(f.hand);
  if (!other_palm_seen(f)) {
    out.push_back(Trigger{"palm_push", "gesture", f.time, f.hand, true});
    return;
  }
  if (pending_push_[1 - h] >= 0) {
    pending_push_[1 - h] = -1;
    out.push_back(Trigger{"both_push", "gesture", f.time, Hand::Right, true});
    return;
  }
  pending_push_[h] = f.time;
}

// Palm pushes that waited past both_push_window without the other hand's: each a "palm_push".
void GestureRecognizer::flush_pushes(double t, std::vector<Trigger>& out) {
  for (int h = 0; h < 2; ++h)
    if (pending_push_[h] >= 0 && t - pending_push_[h] > p_.both_push_window) {
      out.push_back(Trigger{"palm_push", "gesture", pending_push_[h], static_cast<Hand>(h), true});
      pending_push_[h] = -1;
    }
}

// Both palms: together (held) and spread apart quickly.
void GestureRecognizer::update_two_hands(const HandFrame& f, std::vector<Trigger>& out) {
  palms_near_ = false;
  if (!other_palm_seen(f)) return;
  const State& o = st_[1 - static_cast<int>(f.hand)];
  const double d = (f.palm.position - o.history.back().second).norm();
  palms_near_ = d < p_.together_leave;
  HandFrame right = f;
  right.hand = Hand::Right;
  const bool near = together_.on() ? d < p_.together_leave : d < p_.together_enter;
  const int edge = together_.update(near, f.time, p_.together_hold);
  emit(edge, "hands_together", right, out);
  if (edge < 0) together_ended_ = f.time;
  if (together_.on() || d <= p_.apart_to || f.time - together_ended_ < p_.apart_quiet) return;
  // Spread: the palms' distance, paired sample by sample over apart_time, was under apart_from.
  const State& s = st_[static_cast<int>(f.hand)];
  for (const auto& [t, q] : s.history) {
    if (f.time - t > p_.apart_time) continue;
    for (const auto& [u, r] : o.history)
      if (std::abs(u - t) <= p_.pair_stale * 0.5 && (q - r).norm() < p_.apart_from) {
        out.push_back(Trigger{"hands_apart", "gesture", f.time, Hand::Right, true});
        together_ended_ = f.time;  // once per spread (apart_quiet)
        return;
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
