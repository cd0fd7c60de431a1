#include <algorithm>
#include <utility>

#include "tracking/hand_source.hpp"

namespace drape::tracking {

void XrHandSource::feed_joints(Hand h, const XrJointInput& in) {
  HandFrame f;
  f.hand = h;
  f.time = in.time;
  const int palm = static_cast<int>(Joint::Palm);
  int valid = 0;
  for (int j = 0; j < kJointCount; ++j) {
    if (in.valid[j] && in.joints[j].position.allFinite()) ++valid;
    f.joints[j] = in.joints[j].position;
  }
  f.tracked = in.active && in.valid[palm] && in.joints[palm].position.allFinite();
  f.has_joints = f.tracked && valid == kJointCount;
  f.confidence = f.tracked ? static_cast<double>(valid) / kJointCount : 0.0;
  f.palm = in.joints[palm];
  pending_.push_back(f);
  last_time_ = in.time;
}

void XrHandSource::feed_controller(Hand h, const XrControllerInput& in) {
  HandFrame f;
  f.hand = h;
  f.time = in.time;
  f.tracked = in.active && in.grip.position.allFinite();
  f.confidence = f.tracked ? 1.0 : 0.0;
  f.palm = in.grip;
  pending_.push_back(f);
  last_time_ = in.time;
  // Analog trigger with hysteresis (press > 0.7, release < 0.3).
  const int i = static_cast<int>(h);
  bool down = trigger_down_[i];
  if (!down && in.trigger > 0.7) down = true;
  if (down && in.trigger < 0.3) down = false;
  auto edge = [&](const std::string& name, bool pressed) {
    auto& v = buttons_[i];
    auto it = std::find_if(v.begin(), v.end(), [&](auto& e) { return e.first == name; });
    if (it == v.end()) {
      v.emplace_back(name, false);
      it = v.end() - 1;
    }
    if (it->second != pressed) {
      it->second = pressed;
      triggers_.push_back(Trigger{"button." + name, "controller", in.time, h, pressed});
    }
  };
  trigger_down_[i] = down;
  edge("trigger", down && in.active);
  edge("squeeze", in.squeeze && in.active);
  edge("a", in.a && in.active);
  edge("b", in.b && in.active);
}

std::vector<HandFrame> XrHandSource::poll() {
  return std::exchange(pending_, {});
}
std::vector<Trigger> XrHandSource::take_triggers() {
  return std::exchange(triggers_, {});
}

SourceStatus XrHandSource::status() const {
  if (last_time_ < 0) return {SourceState::NoData, "xr: nothing fed yet"};
  return {SourceState::Ok, "xr: ok"};
}

}  // namespace drape::tracking
