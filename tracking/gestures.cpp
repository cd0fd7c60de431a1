#include "tracking/gestures.hpp"

#include <algorithm>

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

void GestureRecognizer::update(const HandFrame& f, std::vector<Trigger>& out) {
  State& s = st_[static_cast<int>(f.hand)];
  if (!f.tracked) {
    // Lost hand: end whatever was active (a lost pinch must not stay latched).
    emit(s.pinch.update(false, f.time, 0.0), "pinch", f, out);
    emit(s.grab.update(false, f.time, 0.0), "grab", f, out);
    emit(s.open.update(false, f.time, 0.0), "open_palm", f, out);
    s.pinch_raw = false;
    s.history.clear();
    s.dwell_fired = false;
    return;
  }
  if (f.has_joints) {
    auto J = [&](Joint j) { return f.joints[static_cast<int>(j)]; };
    const double d = (J(Joint::ThumbTip) - J(Joint::IndexTip)).norm();
    if (!s.pinch_raw && d < p_.pinch_enter) s.pinch_raw = true;
    if (s.pinch_raw && d > p_.pinch_leave) s.pinch_raw = false;
    emit(s.pinch.update(s.pinch_raw, f.time, p_.min_duration), "pinch", f, out);
    const Vec3 palm = J(Joint::Palm);
    double curl = 0;
    for (Joint tip : {Joint::IndexTip, Joint::MiddleTip, Joint::RingTip, Joint::LittleTip})
      curl += (J(tip) - palm).norm() / 4.0;
    const bool fist = curl < p_.grab_curl;
    const bool open = curl > p_.open_extend && d > p_.pinch_leave;
    emit(s.grab.update(fist, f.time, p_.min_duration), "grab", f, out);
    emit(s.open.update(open, f.time, p_.min_duration), "open_palm", f, out);
    return;
  }
  // Palm-only source: dwell and push from the palm trajectory.
  const Vec3 p = f.palm.position;
  s.history.emplace_back(f.time, p);
  const double keep = std::max(p_.dwell_time, p_.push_time) + 0.1;
  while (!s.history.empty() && f.time - s.history.front().first > keep) s.history.pop_front();
  // dwell: every sample in the last dwell_time within dwell_radius of the current position.
  bool still = s.history.front().first <= f.time - p_.dwell_time + 1e-9;
  for (const auto& [t, q] : s.history)
    if (t >= f.time - p_.dwell_time && (q - p).norm() > p_.dwell_radius) still = false;
  if (still && !s.dwell_fired) {
    out.push_back(Trigger{"dwell", "gesture", f.time, f.hand, true});
    s.dwell_fired = true;
  } else if (!still && s.dwell_fired) {
    s.dwell_fired = false;
  }
  if (f.time >= s.push_block_until) {
    for (const auto& [t, q] : s.history) {
      if (f.time - t > p_.push_time) continue;
      if ((p - q).dot(p_.push_axis.normalized()) > p_.push_distance) {
        out.push_back(Trigger{"push", "gesture", f.time, f.hand, true});
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
