// The OpenXR app's input: one action set (pinch, grab, hand pose, primary and secondary
// buttons, menu, thumbstick and its click, trackpad and its click, haptics) with suggested
// bindings for the common controllers (only the components each profile has), the hands' grip
// spaces, and XR_EXT_hand_tracking's joint sets when the system offers them.
#pragma once

#include <cstdint>
#include <string>

#include "xr_app/app/xr_common.hpp"

namespace drape::app {

// A controller as this frame sees it (located in the app's space).
struct ControllerState {
  bool active = false;  // the grip pose is valid
  XrPosef grip{};
  float trigger = 0;  // the pinch action's value (0 while it is inactive)
  bool squeeze = false, a = false, b = false, menu = false;
  XrVector2f stick{0, 0};  // thumbstick (0 while inactive)
  bool stick_click = false;
  XrVector2f pad{0, 0};  // trackpad position (0 while inactive)
  bool pad_click = false;
  std::string profile;  // the hand's interaction profile family ("oculus/touch"; "" none)
};

// This frame's hands: joint sets (index 0 left, 1 right) and, when read, the controllers.
struct HandInput {
  bool has_tracker[2] = {false, false};
  bool joints_active[2] = {false, false};
  XrHandJointLocationEXT joints[2][XR_HAND_JOINT_COUNT_EXT]{};
  ControllerState controllers[2];
};

class XrInput {
 public:
  explicit XrInput(Report& rep) : rep_(rep) {}

  // The action set, its actions and the suggested bindings (once per instance).
  void create_actions(XrInstance instance);
  bool has_actions() const { return action_set_ != XR_NULL_HANDLE; }
  // Attaches the action set to a new session; makes the grip spaces and the hand trackers.
  void attach(XrInstance instance, XrSession session, bool hand_tracking);
  // Destroys the session's hand trackers and grip spaces.
  void detach(XrInstance instance);
  void destroy_actions();

  // Syncs the actions (max_trigger: the largest pinch value seen) and locates the joints.
  void read_frame(XrSession session, XrSpace space, XrTime time, HandInput& in, float& max_trigger);
  // The controllers' grip poses and buttons at `time`.
  void read_controllers(XrSession session, XrSpace space, XrTime time, HandInput& in) const;

 private:
  void suggest_bindings(XrInstance instance);
  void read_profile(XrSession session, int hand, ControllerState& c) const;
  Report& rep_;
  XrInstance instance_ = XR_NULL_HANDLE;
  XrActionSet action_set_ = XR_NULL_HANDLE;
  XrAction pinch_ = XR_NULL_HANDLE, grab_ = XR_NULL_HANDLE, pose_ = XR_NULL_HANDLE,
           primary_ = XR_NULL_HANDLE, secondary_ = XR_NULL_HANDLE, haptic_ = XR_NULL_HANDLE,
           menu_ = XR_NULL_HANDLE, stick_ = XR_NULL_HANDLE, stick_click_ = XR_NULL_HANDLE,
           pad_ = XR_NULL_HANDLE, pad_click_ = XR_NULL_HANDLE;
  XrPath hand_paths_[2] = {XR_NULL_PATH, XR_NULL_PATH};
  XrSpace hand_spaces_[2] = {XR_NULL_HANDLE, XR_NULL_HANDLE};
  XrHandTrackerEXT trackers_[2] = {XR_NULL_HANDLE, XR_NULL_HANDLE};
  PFN_xrLocateHandJointsEXT locate_joints_ = nullptr;
};

}  // namespace drape::app
