// One interface for every hand source (XR runtime, Kinect, UDP skeleton stream, trace).
#pragma once
#include <string>
#include <vector>

#include "tracking/types.hpp"

namespace drape::tracking {

enum class SourceState { Ok, NoData, Unavailable, Error };

struct SourceStatus {
  SourceState state = SourceState::NoData;
  std::string message;  // human-readable, e.g. "no Kinect found (libfreenect: 0 devices)"
};

class HandSource {
 public:
  virtual ~HandSource() = default;
  virtual std::string name() const = 0;
  // Latest frames (0..2: one per hand) produced since the last poll, oldest first.
  virtual std::vector<HandFrame> poll() = 0;
  virtual SourceStatus status() const = 0;
};

// XR adapter: xr_app feeds joint poses (XR_EXT_hand_tracking) or controller poses+buttons.
struct XrJointInput {
  bool active = false;
  double time = 0;
  std::array<Pose, kJointCount> joints{};
  std::array<bool, kJointCount> valid{};
};
struct XrControllerInput {
  bool active = false;
  double time = 0;
  Pose grip;
  double trigger = 0;  // 0..1 analog value
  bool a = false, b = false, squeeze = false;
  bool menu = false;
  double stick_x = 0, stick_y = 0;  // thumbstick, -1..1 (+y up, +x right)
  bool stick_click = false;
  double pad_x = 0, pad_y = 0;  // trackpad position, -1..1
  bool pad_click = false;
};

class XrHandSource : public HandSource {
 public:
  std::string name() const override { return "xr"; }
  void feed_joints(Hand h, const XrJointInput& in);
  // Controller poses become palm-only frames; buttons become triggers in `take_triggers()`:
  // "button.trigger" (the analog trigger with hysteresis), "button.squeeze", "button.a",
  // "button.b", "button.menu", "button.menu_hold" (the menu button held for 1 s: a save),
  // "button.stick" (its click); "stick.up" / "down" / "left" /
  // "right" (the thumbstick pushed that way, with hysteresis); "trackpad.up" / "down" / "left" /
  // "right" / "center" (the region clicked, held until the click ends); "palm_up" (the
  // controller rolled so that the palm faces up).
  void feed_controller(Hand h, const XrControllerInput& in);
  std::vector<HandFrame> poll() override;
  std::vector<Trigger> take_triggers();
  SourceStatus status() const override;

 private:
  std::vector<HandFrame> pending_;
  std::vector<Trigger> triggers_;
  void edge(Hand h, const std::string& name, bool on, double time);
  void stick_edges(Hand h, const XrControllerInput& in);
  void pad_edges(Hand h, const XrControllerInput& in);
  void palm_up_edge(Hand h, const XrControllerInput& in);
  void menu_edges(Hand h, const XrControllerInput& in);
  bool trigger_down_[2] = {false, false};
  double menu_since_[2] = {-1, -1};     // when the menu button went down; -1: up
  bool menu_held_[2] = {false, false};  // this press reached kMenuHoldSeconds (no tap)
  int stick_dir_[2] = {-1, -1};         // 0 up, 1 down, 2 left, 3 right; -1 centred
  int pad_region_[2] = {-1, -1};        // as stick_dir_, 4 centre; -1 not clicked
  bool palm_up_[2] = {false, false};
  std::vector<std::pair<std::string, bool>> buttons_[2];
  double last_time_ = -1;
};

}  // namespace drape::tracking
