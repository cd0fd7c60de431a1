#include <algorithm>
#include <cmath>
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

namespace {
constexpr const char* kDirections[5] = {"up", "down", "left", "right", "center"};
constexpr double kStickEnter = 0.7, kStickLeave = 0.4;    // stick deflection hysteresis
constexpr double kPadCentre = 0.5;                        // trackpad: centre region radius
constexpr double kPalmUpEnter = 0.7, kPalmUpLeave = 0.5;  // palm normal . up
constexpr double kMenuHoldSeconds = 1.0;  // the menu button held this long: "button.menu_hold"

// The direction (0 up, 1 down, 2 left, 3 right) of the dominant axis of (x, y).
int direction(double x, double y) {
  if (std::abs(y) >= std::abs(x)) return y >= 0 ? 0 : 1;
  return x < 0 ? 2 : 3;
}
// How far (x, y) points along direction d.
double along(int d, double x, double y) {
  const double v[4] = {y, -y, -x, x};
  return v[d];
}
}  // namespace

void XrHandSource::edge(Hand h, const std::string& name, bool on, double time) {
  auto& v = buttons_[static_cast<int>(h)];
  auto it = std::find_if(v.begin(), v.end(), [&](auto& e) { return e.first == name; });
  if (it == v.end()) {
    v.emplace_back(name, false);
    it = v.end() - 1;
  }
  if (it->second != on) {
    it->second = on;
    triggers_.push_back(Trigger{name, "controller", time, h, on});
  }
}

// The stick pushed past kStickEnter along its dominant axis starts that direction; it ends
// below kStickLeave along it (or when another direction starts).
void XrHandSource::stick_edges(Hand h, const XrControllerInput& in) {
  const int i = static_cast<int>(h);
  const double x = in.active ? in.stick_x : 0, y = in.active ? in.stick_y : 0;
  int& d = stick_dir_[i];
  if (d >= 0 && along(d, x, y) < kStickLeave) d = -1;
  const int want = direction(x, y);
  if (along(want, x, y) > kStickEnter) d = want;
  for (int k = 0; k < 4; ++k) edge(h, std::string("stick.") + kDirections[k], d == k, in.time);
}

// A trackpad click acts on the region under the thumb when it clicks (the centre, or the
// dominant direction), held until the click ends.
void XrHandSource::pad_edges(Hand h, const XrControllerInput& in) {
  const int i = static_cast<int>(h);
  const bool click = in.active && in.pad_click;
  int& r = pad_region_[i];
  if (!click) r = -1;
  if (click && r < 0)
    r = std::hypot(in.pad_x, in.pad_y) < kPadCentre ? 4 : direction(in.pad_x, in.pad_y);
  for (int k = 0; k < 5; ++k) edge(h, std::string("trackpad.") + kDirections[k], r == k, in.time);
}

// The grip pose's +x is the palm's normal on the left hand and its opposite on the right
// (OpenXR's grip pose); the palm up is that normal within ~45 degrees of up.
void XrHandSource::palm_up_edge(Hand h, const XrControllerInput& in) {
  const int i = static_cast<int>(h);
  const Vec3 normal = in.grip.orientation * Vec3(h == Hand::Left ? 1 : -1, 0, 0);
  const double up = in.active ? normal.dot(Vec3(0, 1, 0)) : -1;
  bool& on = palm_up_[i];
  if (!on && up > kPalmUpEnter) on = true;
  if (on && up < kPalmUpLeave) on = false;
  edge(h, "palm_up", on, in.time);
}

// The menu button: a press let go before kMenuHoldSeconds is a tap, "button.menu" (begin and
// end when it is let go); a press held that long is "button.menu_hold" alone (begin at the
// second, end when let go). Holding the button to save therefore never also stops or undoes; a
// controller lost while the button is down gives neither.
void XrHandSource::menu_edges(Hand h, const XrControllerInput& in) {
  const int i = static_cast<int>(h);
  double& since = menu_since_[i];
  const bool down = in.menu && in.active;
  if (down && since < 0) since = in.time;
  const bool held = down && in.time - since >= kMenuHoldSeconds;
  if (held) menu_held_[i] = true;
  if (!down && since >= 0) {
    if (in.active && !menu_held_[i]) {
      edge(h, "button.menu", true, in.time);
      edge(h, "button.menu", false, in.time);
    }
    since = -1;
    menu_held_[i] = false;
  }
  edge(h, "button.menu_hold", held, in.time);
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
  trigger_down_[i] = down;
  edge(h, "button.trigger", down && in.active, in.time);
  edge(h, "button.squeeze", in.squeeze && in.active, in.time);
  edge(h, "button.a", in.a && in.active, in.time);
  edge(h, "button.b", in.b && in.active, in.time);
  menu_edges(h, in);
  edge(h, "button.stick", in.stick_click && in.active, in.time);
  stick_edges(h, in);
  pad_edges(h, in);
  palm_up_edge(h, in);
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
