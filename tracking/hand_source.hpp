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
};

class XrHandSource : public HandSource {
 public:
  std::string name() const override { return "xr"; }
  void feed_joints(Hand h, const XrJointInput& in);
  // Controller poses become palm-only frames; buttons become triggers in `triggers()`.
  void feed_controller(Hand h, const XrControllerInput& in);
  std::vector<HandFrame> poll() override;
  std::vector<Trigger> take_triggers();
  SourceStatus status() const override;

 private:
  std::vector<HandFrame> pending_;
  std::vector<Trigger> triggers_;
  bool trigger_down_[2] = {false, false};
  std::vector<std::pair<std::string, bool>> buttons_[2];
  double last_time_ = -1;
};

}  // namespace drape::tracking
