// The OpenXR app's input: actions and hand tracking (see xr_input.hpp).
#include "xr_app/app/xr_input.hpp"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "tracking/command_map.hpp"

namespace drape::app {

namespace {
const char* const kProfiles[] = {
    "/interaction_profiles/khr/simple_controller", "/interaction_profiles/oculus/touch_controller",
    "/interaction_profiles/valve/index_controller", "/interaction_profiles/htc/vive_controller",
    "/interaction_profiles/microsoft/motion_controller"};
}  // namespace

void XrInput::create_actions(XrInstance instance) {
  XrActionSetCreateInfo si{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::snprintf(si.actionSetName, XR_MAX_ACTION_SET_NAME_SIZE, "drape");
  std::snprintf(si.localizedActionSetName, XR_MAX_LOCALIZED_ACTION_SET_NAME_SIZE, "Drape");
  if (!rep_.ok(xrCreateActionSet(instance, &si, &action_set_), "xrCreateActionSet")) return;
  hand_paths_[0] = xr_path(instance, "/user/hand/left");
  hand_paths_[1] = xr_path(instance, "/user/hand/right");
  auto make = [&](const char* name, const char* loc, XrActionType t) {
    XrActionCreateInfo ai{XR_TYPE_ACTION_CREATE_INFO};
    std::snprintf(ai.actionName, XR_MAX_ACTION_NAME_SIZE, "%s", name);
    std::snprintf(ai.localizedActionName, XR_MAX_LOCALIZED_ACTION_NAME_SIZE, "%s", loc);
    ai.actionType = t;
    ai.countSubactionPaths = 2;
    ai.subactionPaths = hand_paths_;
    XrAction a = XR_NULL_HANDLE;
    rep_.ok(xrCreateAction(action_set_, &ai, &a), name);
    return a;
  };
  pinch_ = make("pinch", "Pinch", XR_ACTION_TYPE_FLOAT_INPUT);
  grab_ = make("grab", "Grab", XR_ACTION_TYPE_BOOLEAN_INPUT);
  pose_ = make("hand_pose", "Hand pose", XR_ACTION_TYPE_POSE_INPUT);
  primary_ = make("primary", "Primary button", XR_ACTION_TYPE_BOOLEAN_INPUT);
  secondary_ = make("secondary", "Secondary button", XR_ACTION_TYPE_BOOLEAN_INPUT);
  haptic_ = make("haptic", "Haptic", XR_ACTION_TYPE_VIBRATION_OUTPUT);
  menu_ = make("menu", "Menu button", XR_ACTION_TYPE_BOOLEAN_INPUT);
  stick_ = make("thumbstick", "Thumbstick", XR_ACTION_TYPE_VECTOR2F_INPUT);
  stick_click_ = make("thumbstick_click", "Thumbstick click", XR_ACTION_TYPE_BOOLEAN_INPUT);
  pad_ = make("trackpad", "Trackpad", XR_ACTION_TYPE_VECTOR2F_INPUT);
  pad_click_ = make("trackpad_click", "Trackpad click", XR_ACTION_TYPE_BOOLEAN_INPUT);
  suggest_bindings(instance);
}

namespace {
// The components of one profile for one hand (paths after /user/hand/<side>), from the
// OpenXR specification's interaction profile paths; "" where the profile has none.
struct ProfileComponents {
  const char* pinch = "/input/trigger/value";
  const char* grab = "";
  const char* primary = "";
  const char* secondary = "";
  const char* menu = "";
  bool stick = false, pad = false;
};

ProfileComponents components(const std::string& profile, bool left) {
  ProfileComponents c;
  if (profile.find("khr/simple") != std::string::npos) {
    c.pinch = "/input/select/click";
    c.menu = "/input/menu/click";
  } else if (profile.find("oculus/touch") != std::string::npos) {
    // Touch: X/Y and menu on the left, A/B on the right (its system button is the runtime's).
    c.grab = "/input/squeeze/value";
    c.primary = left ? "/input/x/click" : "/input/a/click";
    c.secondary = left ? "/input/y/click" : "/input/b/click";
    c.menu = left ? "/input/menu/click" : "";
    c.stick = true;
  } else if (profile.find("valve/index") != std::string::npos) {
    // Index: no menu button; its trackpad has no click.
    c.grab = "/input/squeeze/value";
    c.primary = "/input/a/click";
    c.secondary = "/input/b/click";
    c.stick = true;
  } else if (profile.find("htc/vive") != std::string::npos) {
    c.grab = "/input/squeeze/click";
    c.menu = "/input/menu/click";
    c.pad = true;
  } else {  // microsoft/motion
    c.grab = "/input/squeeze/click";
    c.menu = "/input/menu/click";
    c.stick = c.pad = true;
  }
  return c;
}
}  // namespace

// Every profile's components for both hands; what a profile lacks is bound by another input of
// it where assets/commands.json says so (a trackpad region for a stick), else not at all.
void XrInput::suggest_bindings(XrInstance instance) {
  for (const char* prof : kProfiles) {
    std::vector<XrActionSuggestedBinding> b;
    for (const char* side : {"left", "right"}) {
      const std::string h = std::string("/user/hand/") + side;
      const ProfileComponents c = components(prof, std::string(side) == "left");
      auto bind = [&](XrAction a, const std::string& comp) {
        if (!comp.empty()) b.push_back({a, xr_path(instance, (h + comp).c_str())});
      };
      bind(pinch_, c.pinch);
      bind(grab_, c.grab);
      bind(pose_, "/input/grip/pose");
      bind(primary_, c.primary);
      bind(secondary_, c.secondary);
      bind(menu_, c.menu);
      if (c.stick) {
        bind(stick_, "/input/thumbstick");
        bind(stick_click_, "/input/thumbstick/click");
      }
      if (c.pad) {
        bind(pad_, "/input/trackpad");
        bind(pad_click_, "/input/trackpad/click");
      }
      bind(haptic_, "/output/haptic");
    }
    XrInteractionProfileSuggestedBinding sb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
    sb.interactionProfile = xr_path(instance, prof);
    sb.countSuggestedBindings = static_cast<uint32_t>(b.size());
    sb.suggestedBindings = b.data();
    rep_.ok(xrSuggestInteractionProfileBindings(instance, &sb), prof);
  }
}

void XrInput::attach(XrInstance instance, XrSession session, bool hand_tracking) {
  instance_ = instance;
  XrSessionActionSetsAttachInfo at{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  at.countActionSets = 1;
  at.actionSets = &action_set_;
  rep_.ok(xrAttachSessionActionSets(session, &at), "xrAttachSessionActionSets");
  for (int h = 0; h < 2; ++h) {
    XrActionSpaceCreateInfo as{XR_TYPE_ACTION_SPACE_CREATE_INFO};
    as.action = pose_;
    as.subactionPath = hand_paths_[h];
    as.poseInActionSpace.orientation.w = 1;
    rep_.ok(xrCreateActionSpace(session, &as, &hand_spaces_[h]), "xrCreateActionSpace");
  }
  if (!hand_tracking) return;
  auto create = xr_function<PFN_xrCreateHandTrackerEXT>(instance, "xrCreateHandTrackerEXT");
  locate_joints_ = xr_function<PFN_xrLocateHandJointsEXT>(instance, "xrLocateHandJointsEXT");
  for (int h = 0; h < 2 && create; ++h) {
    XrHandTrackerCreateInfoEXT hc{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
    hc.hand = h == 0 ? XR_HAND_LEFT_EXT : XR_HAND_RIGHT_EXT;
    hc.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
    rep_.ok(create(session, &hc, &trackers_[h]), "xrCreateHandTrackerEXT");
  }
}

void XrInput::detach(XrInstance instance) {
  auto destroy_tracker = trackers_[0] || trackers_[1] ? xr_function<PFN_xrDestroyHandTrackerEXT>(
                                                            instance, "xrDestroyHandTrackerEXT")
                                                      : nullptr;
  for (int h = 0; h < 2; ++h) {
    if (trackers_[h] && destroy_tracker) destroy_tracker(trackers_[h]);
    trackers_[h] = XR_NULL_HANDLE;
    if (hand_spaces_[h]) xrDestroySpace(hand_spaces_[h]);
    hand_spaces_[h] = XR_NULL_HANDLE;
  }
}

void XrInput::destroy_actions() {
  if (action_set_) xrDestroyActionSet(action_set_);
  action_set_ = XR_NULL_HANDLE;
}

void XrInput::read_frame(XrSession session, XrSpace space, XrTime time, HandInput& in,
                         float& max_trigger) {
  XrActiveActionSet active{action_set_, XR_NULL_PATH};
  XrActionsSyncInfo sync{XR_TYPE_ACTIONS_SYNC_INFO};
  sync.countActiveActionSets = 1;
  sync.activeActionSets = &active;
  if (XR_SUCCEEDED(xrSyncActions(session, &sync))) {
    for (int h = 0; h < 2; ++h) {
      XrActionStateGetInfo gi{XR_TYPE_ACTION_STATE_GET_INFO};
      gi.action = pinch_;
      gi.subactionPath = hand_paths_[h];
      XrActionStateFloat f{XR_TYPE_ACTION_STATE_FLOAT};
      if (XR_SUCCEEDED(xrGetActionStateFloat(session, &gi, &f)) && f.isActive)
        max_trigger = std::max(max_trigger, f.currentState);
    }
  }
  for (int h = 0; h < 2; ++h) in.has_tracker[h] = trackers_[h] != XR_NULL_HANDLE;
  for (int h = 0; h < 2 && locate_joints_; ++h) {
    if (!trackers_[h]) continue;
    XrHandJointLocationsEXT loc{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
    loc.jointCount = XR_HAND_JOINT_COUNT_EXT;
    loc.jointLocations = in.joints[h];
    XrHandJointsLocateInfoEXT li{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
    li.baseSpace = space;
    li.time = time;
    in.joints_active[h] = XR_SUCCEEDED(locate_joints_(trackers_[h], &li, &loc)) && loc.isActive;
  }
}

void XrInput::read_controllers(XrSession session, XrSpace space, XrTime time, HandInput& in) const {
  for (int h = 0; h < 2; ++h) {
    ControllerState& c = in.controllers[h];
    XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
    if (hand_spaces_[h] != XR_NULL_HANDLE &&
        XR_SUCCEEDED(xrLocateSpace(hand_spaces_[h], space, time, &loc)) &&
        (loc.locationFlags & XR_SPACE_LOCATION_POSITION_VALID_BIT)) {
      c.active = true;
      c.grip = loc.pose;
    }
    XrActionStateGetInfo gi{XR_TYPE_ACTION_STATE_GET_INFO};
    gi.subactionPath = hand_paths_[h];
    gi.action = pinch_;
    XrActionStateFloat fv{XR_TYPE_ACTION_STATE_FLOAT};
    if (XR_SUCCEEDED(xrGetActionStateFloat(session, &gi, &fv)) && fv.isActive)
      c.trigger = fv.currentState;
    auto boolean = [&](XrAction a) {
      gi.action = a;
      XrActionStateBoolean bv{XR_TYPE_ACTION_STATE_BOOLEAN};
      return a != XR_NULL_HANDLE && XR_SUCCEEDED(xrGetActionStateBoolean(session, &gi, &bv)) &&
             bv.isActive && bv.currentState == XR_TRUE;
    };
    c.squeeze = boolean(grab_);
    c.a = boolean(primary_);
    c.b = boolean(secondary_);
    c.menu = boolean(menu_);
    c.stick_click = boolean(stick_click_);
    c.pad_click = boolean(pad_click_);
    auto vector2 = [&](XrAction a) {
      gi.action = a;
      XrActionStateVector2f vv{XR_TYPE_ACTION_STATE_VECTOR2F};
      const bool ok = XR_SUCCEEDED(xrGetActionStateVector2f(session, &gi, &vv)) && vv.isActive;
      return ok ? vv.currentState : XrVector2f{0, 0};
    };
    c.stick = vector2(stick_);
    c.pad = vector2(pad_);
    read_profile(session, h, c);
  }
}

// The hand's current interaction profile, as the command map's family name.
void XrInput::read_profile(XrSession session, int hand, ControllerState& c) const {
  XrInteractionProfileState ps{XR_TYPE_INTERACTION_PROFILE_STATE};
  if (!XR_SUCCEEDED(xrGetCurrentInteractionProfile(session, hand_paths_[hand], &ps)) ||
      ps.interactionProfile == XR_NULL_PATH)
    return;
  char buf[XR_MAX_PATH_LENGTH];
  uint32_t n = 0;
  if (XR_SUCCEEDED(xrPathToString(instance_, ps.interactionProfile, sizeof buf, &n, buf)))
    c.profile = tracking::profile_family(buf);
}

}  // namespace drape::app
