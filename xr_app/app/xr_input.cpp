// The OpenXR app's input: actions and hand tracking (see xr_input.hpp).
#include "xr_app/app/xr_input.hpp"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

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
  suggest_bindings(instance);
}

void XrInput::suggest_bindings(XrInstance instance) {
  for (const char* prof : kProfiles) {
    std::string p = prof;
    std::vector<XrActionSuggestedBinding> b;
    const bool simple = p.find("simple") != std::string::npos;
    const bool oculus = p.find("oculus") != std::string::npos;
    const bool index = p.find("index") != std::string::npos;
    for (const char* side : {"left", "right"}) {
      const std::string h = std::string("/user/hand/") + side;
      const bool left = std::string(side) == "left";
      auto bind = [&](XrAction a, const std::string& comp) {
        b.push_back({a, xr_path(instance, (h + comp).c_str())});
      };
      bind(pinch_, simple ? "/input/select/click" : "/input/trigger/value");
      if (!simple) bind(grab_, oculus || index ? "/input/squeeze/value" : "/input/squeeze/click");
      bind(pose_, "/input/grip/pose");
      // Primary / secondary buttons ("button.a" / "button.b" of the command map): A/B (X/Y on
      // the left Touch controller); trackpad click / menu on Vive and WMR; menu on simple.
      if (oculus) {
        bind(primary_, left ? "/input/x/click" : "/input/a/click");
        bind(secondary_, left ? "/input/y/click" : "/input/b/click");
      } else if (index) {
        bind(primary_, "/input/a/click");
        bind(secondary_, "/input/b/click");
      } else if (simple) {
        bind(secondary_, "/input/menu/click");
      } else {
        bind(primary_, "/input/trackpad/click");
        bind(secondary_, "/input/menu/click");
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
  }
}

}  // namespace drape::app
