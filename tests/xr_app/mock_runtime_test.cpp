// Direct tests of the mock OpenXR runtime through the Khronos loader: negotiation, the
// session state machine, strict validation error codes, hand joints, actions, session loss,
// Vulkan swapchains and frame read-back.
#define XR_USE_GRAPHICS_API_VULKAN
#include <gtest/gtest.h>
#include <vulkan/vulkan.h>
// (Vulkan first: openxr_platform.h uses its types)
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "xr_app/mock_runtime/scenario.hpp"

namespace {

const std::string kManifest = std::string(DRAPE_BINARY_DIR) + "/bin/drape_mock_runtime.json";

std::string temp_dir() {
  auto d = std::filesystem::temp_directory_path() / ("drape_xr_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d.string();
}

std::string write_scenario(const std::string& name, const std::string& text) {
  std::string p = temp_dir() + "/" + name;
  std::ofstream(p) << text;
  return p;
}

void clear_env() {
  for (const char* v : {"DRAPE_MOCK_SCENARIO", "DRAPE_MOCK_END_AFTER_FRAMES", "DRAPE_MOCK_FAST",
                        "DRAPE_MOCK_WRITE_FRAMES", "DRAPE_MOCK_WRITE_EVERY",
                        "DRAPE_MOCK_LOSE_SESSION_AT_FRAME", "DRAPE_MOCK_WINDOW",
                        "DRAPE_MOCK_WINDOW_SIZE", "DRAPE_MOCK_WINDOW_LOG", "XR_ENABLE_API_LAYERS"})
    unsetenv(v);
  setenv("XR_RUNTIME_JSON", kManifest.c_str(), 1);
  setenv("DRAPE_MOCK_FAST", "1", 1);
}

template <class F>
F proc(XrInstance inst, const char* name) {
  PFN_xrVoidFunction fn = nullptr;
  EXPECT_EQ(xrGetInstanceProcAddr(inst, name, &fn), XR_SUCCESS) << name;
  return reinterpret_cast<F>(fn);
}

class MockRuntime : public ::testing::Test {
 protected:
  void SetUp() override { clear_env(); }
  void TearDown() override {
    if (session_) xrDestroySession(session_);
    if (instance_) xrDestroyInstance(instance_);
  }

  void create(std::vector<const char*> exts = {XR_MND_HEADLESS_EXTENSION_NAME,
                                               XR_EXT_HAND_TRACKING_EXTENSION_NAME}) {
    XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
    std::strcpy(ci.applicationInfo.applicationName, "drape_mock_test");
    ci.applicationInfo.apiVersion = XR_CURRENT_API_VERSION;
    ci.enabledExtensionCount = static_cast<uint32_t>(exts.size());
    ci.enabledExtensionNames = exts.data();
    ASSERT_EQ(xrCreateInstance(&ci, &instance_), XR_SUCCESS);
    XrSystemGetInfo gi{XR_TYPE_SYSTEM_GET_INFO};
    gi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
    ASSERT_EQ(xrGetSystem(instance_, &gi, &system_), XR_SUCCESS);
  }

  void create_headless_session() {
    XrSessionCreateInfo si{XR_TYPE_SESSION_CREATE_INFO};
    si.systemId = system_;
    ASSERT_EQ(xrCreateSession(instance_, &si, &session_), XR_SUCCESS);
  }

  std::vector<XrSessionState> drain_states() {
    std::vector<XrSessionState> out;
    XrEventDataBuffer ev{XR_TYPE_EVENT_DATA_BUFFER};
    while (xrPollEvent(instance_, &ev) == XR_SUCCESS) {
      if (ev.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED)
        out.push_back(reinterpret_cast<XrEventDataSessionStateChanged*>(&ev)->state);
      ev = {XR_TYPE_EVENT_DATA_BUFFER};
    }
    return out;
  }

  void begin() {
    drain_states();
    XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
    bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
    ASSERT_EQ(xrBeginSession(session_, &bi), XR_SUCCESS);
  }

  // One empty frame; returns its predicted display time.
  XrTime frame(XrResult* end_result = nullptr) {
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    EXPECT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_SUCCESS);
    EXPECT_EQ(xrBeginFrame(session_, nullptr), XR_SUCCESS);
    XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
    ei.displayTime = fs.predictedDisplayTime;
    ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    XrResult r = xrEndFrame(session_, &ei);
    if (end_result)
      *end_result = r;
    else
      EXPECT_EQ(r, XR_SUCCESS);
    return fs.predictedDisplayTime;
  }

  XrSpace stage() {
    XrReferenceSpaceCreateInfo ci{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
    ci.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_STAGE;
    ci.poseInReferenceSpace.orientation.w = 1;
    XrSpace s = XR_NULL_HANDLE;
    EXPECT_EQ(xrCreateReferenceSpace(session_, &ci, &s), XR_SUCCESS);
    return s;
  }

  XrPath path(const char* s) {
    XrPath p = XR_NULL_PATH;
    EXPECT_EQ(xrStringToPath(instance_, s, &p), XR_SUCCESS) << s;
    return p;
  }

  XrInstance instance_ = XR_NULL_HANDLE;
  XrSystemId system_ = XR_NULL_SYSTEM_ID;
  XrSession session_ = XR_NULL_HANDLE;
};

TEST_F(MockRuntime, NegotiatesAndListsExtensions) {
  uint32_t n = 0;
  ASSERT_EQ(xrEnumerateInstanceExtensionProperties(nullptr, 0, &n, nullptr), XR_SUCCESS);
  std::vector<XrExtensionProperties> props(n, {XR_TYPE_EXTENSION_PROPERTIES});
  ASSERT_EQ(xrEnumerateInstanceExtensionProperties(nullptr, n, &n, props.data()), XR_SUCCESS);
  std::vector<std::string> names;
  for (auto& p : props) names.push_back(p.extensionName);
  for (const char* want :
       {XR_KHR_VULKAN_ENABLE_EXTENSION_NAME, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME,
        XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME,
        XR_MND_HEADLESS_EXTENSION_NAME})
    EXPECT_NE(std::find(names.begin(), names.end(), want), names.end()) << want;
  create();
  XrInstanceProperties ip{XR_TYPE_INSTANCE_PROPERTIES};
  ASSERT_EQ(xrGetInstanceProperties(instance_, &ip), XR_SUCCESS);
  EXPECT_STREQ(ip.runtimeName, "drape mock runtime");
  uint32_t vc = 0;
  XrViewConfigurationView views[2] = {{XR_TYPE_VIEW_CONFIGURATION_VIEW},
                                      {XR_TYPE_VIEW_CONFIGURATION_VIEW}};
  ASSERT_EQ(xrEnumerateViewConfigurationViews(
                instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 2, &vc, views),
            XR_SUCCESS);
  EXPECT_EQ(vc, 2u);
  EXPECT_EQ(views[0].recommendedImageRectWidth, 1024u);
  XrSystemHandTrackingPropertiesEXT ht{XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT};
  XrSystemProperties sp{XR_TYPE_SYSTEM_PROPERTIES, &ht};
  ASSERT_EQ(xrGetSystemProperties(instance_, system_, &sp), XR_SUCCESS);
  EXPECT_EQ(ht.supportsHandTracking, XR_TRUE);
}

TEST_F(MockRuntime, SessionStateMachineRunsToExiting) {
  setenv("DRAPE_MOCK_END_AFTER_FRAMES", "3", 1);
  create();
  create_headless_session();
  EXPECT_EQ(drain_states(),
            (std::vector<XrSessionState>{XR_SESSION_STATE_IDLE, XR_SESSION_STATE_READY}));
  begin();
  XrTime t0 = frame();
  EXPECT_EQ(drain_states(),
            (std::vector<XrSessionState>{XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_VISIBLE,
                                         XR_SESSION_STATE_FOCUSED}));
  XrTime t1 = frame();
  EXPECT_EQ(t1 - t0, 11111111);  // 90 Hz predicted display times
  EXPECT_TRUE(drain_states().empty());
  // Not stopping yet: ending the session is refused.
  EXPECT_EQ(xrEndSession(session_), XR_ERROR_SESSION_NOT_STOPPING);
  frame();
  EXPECT_EQ(drain_states(),
            (std::vector<XrSessionState>{XR_SESSION_STATE_VISIBLE, XR_SESSION_STATE_SYNCHRONIZED,
                                         XR_SESSION_STATE_STOPPING}));
  ASSERT_EQ(xrEndSession(session_), XR_SUCCESS);
  EXPECT_EQ(drain_states(),
            (std::vector<XrSessionState>{XR_SESSION_STATE_IDLE, XR_SESSION_STATE_EXITING}));
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  EXPECT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_ERROR_SESSION_NOT_RUNNING);
}

TEST_F(MockRuntime, RequestExitSessionStops) {
  create();
  create_headless_session();
  EXPECT_EQ(xrRequestExitSession(session_), XR_ERROR_SESSION_NOT_RUNNING);
  begin();
  frame();
  drain_states();
  ASSERT_EQ(xrRequestExitSession(session_), XR_SUCCESS);
  auto st = drain_states();
  ASSERT_FALSE(st.empty());
  EXPECT_EQ(st.back(), XR_SESSION_STATE_STOPPING);
  ASSERT_EQ(xrEndSession(session_), XR_SUCCESS);
  EXPECT_EQ(drain_states().back(), XR_SESSION_STATE_EXITING);
}

TEST_F(MockRuntime, StrictValidationErrorCodes) {
  create();
  // Session creation: wrong struct type, null output, bad system, no graphics binding.
  XrSessionCreateInfo si{XR_TYPE_SESSION_BEGIN_INFO};
  si.systemId = system_;
  XrSession s = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateSession(instance_, &si, &s), XR_ERROR_VALIDATION_FAILURE);
  si.type = XR_TYPE_SESSION_CREATE_INFO;
  EXPECT_EQ(xrCreateSession(instance_, &si, nullptr), XR_ERROR_VALIDATION_FAILURE);
  si.systemId = 42;
  EXPECT_EQ(xrCreateSession(instance_, &si, &s), XR_ERROR_SYSTEM_INVALID);
  create_headless_session();
  // Frame loop order.
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  EXPECT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_ERROR_SESSION_NOT_RUNNING);
  EXPECT_EQ(xrEndSession(session_), XR_ERROR_SESSION_NOT_RUNNING);
  XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
  bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_MONO;
  EXPECT_EQ(xrBeginSession(session_, &bi), XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED);
  begin();
  EXPECT_EQ(xrBeginSession(session_, &bi), XR_ERROR_SESSION_RUNNING);
  EXPECT_EQ(xrBeginFrame(session_, nullptr), XR_ERROR_CALL_ORDER_INVALID);
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  ei.displayTime = 1;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  EXPECT_EQ(xrEndFrame(session_, &ei), XR_ERROR_CALL_ORDER_INVALID);
  XrFrameState bad{XR_TYPE_VIEW_STATE};
  EXPECT_EQ(xrWaitFrame(session_, nullptr, &bad), XR_ERROR_VALIDATION_FAILURE);
  ASSERT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_SUCCESS);
  ASSERT_EQ(xrBeginFrame(session_, nullptr), XR_SUCCESS);
  ei.displayTime = 0;
  EXPECT_EQ(xrEndFrame(session_, &ei), XR_ERROR_TIME_INVALID);
  ei.displayTime = fs.predictedDisplayTime;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_ADDITIVE;
  EXPECT_EQ(xrEndFrame(session_, &ei), XR_ERROR_ENVIRONMENT_BLEND_MODE_UNSUPPORTED);
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  ei.layerCount = 1;
  const XrCompositionLayerBaseHeader* null_layer = nullptr;
  ei.layers = &null_layer;
  EXPECT_EQ(xrEndFrame(session_, &ei), XR_ERROR_LAYER_INVALID);
  ei.layerCount = 0;
  EXPECT_EQ(xrEndFrame(session_, &ei), XR_SUCCESS);
  // Paths and handles.
  XrPath p;
  EXPECT_EQ(xrStringToPath(instance_, "/user/Hand/left", &p), XR_ERROR_PATH_FORMAT_INVALID);
  EXPECT_EQ(xrStringToPath(instance_, "/user//hand", &p), XR_ERROR_PATH_FORMAT_INVALID);
  EXPECT_EQ(xrStringToPath(instance_, "/user/hand/", &p), XR_ERROR_PATH_FORMAT_INVALID);
  EXPECT_EQ(xrStringToPath(instance_, "/user/../x", &p), XR_ERROR_PATH_FORMAT_INVALID);
  uint32_t n = 0;
  EXPECT_EQ(xrPathToString(instance_, 987654, 0, &n, nullptr), XR_ERROR_PATH_INVALID);
  XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_STAGE;  // zero quaternion
  XrSpace sp;
  EXPECT_EQ(xrCreateReferenceSpace(session_, &rs, &sp), XR_ERROR_POSE_INVALID);
  rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_UNBOUNDED_MSFT;
  rs.poseInReferenceSpace.orientation.w = 1;
  EXPECT_EQ(xrCreateReferenceSpace(session_, &rs, &sp), XR_ERROR_REFERENCE_SPACE_UNSUPPORTED);
  // Two-call idiom.
  XrReferenceSpaceType types[1];
  EXPECT_EQ(xrEnumerateReferenceSpaces(session_, 1, &n, types), XR_ERROR_SIZE_INSUFFICIENT);
  EXPECT_EQ(n, 3u);
  // Only one session per instance.
  XrSessionCreateInfo si2{XR_TYPE_SESSION_CREATE_INFO};
  si2.systemId = system_;
  EXPECT_EQ(xrCreateSession(instance_, &si2, &s), XR_ERROR_LIMIT_REACHED);
}

TEST_F(MockRuntime, GraphicsBindingRules) {
  create({XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME});
  XrSessionCreateInfo si{XR_TYPE_SESSION_CREATE_INFO};
  si.systemId = system_;
  XrSession s;
  // No binding and no XR_MND_headless.
  EXPECT_EQ(xrCreateSession(instance_, &si, &s), XR_ERROR_GRAPHICS_DEVICE_INVALID);
  // A binding before the graphics requirements were queried.
  XrGraphicsBindingVulkan2KHR b{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
  b.instance = reinterpret_cast<VkInstance>(1);
  si.next = &b;
  EXPECT_EQ(xrCreateSession(instance_, &si, &s), XR_ERROR_GRAPHICS_REQUIREMENTS_CALL_MISSING);
  // Extension functions of extensions not enabled are unsupported.
  PFN_xrVoidFunction fn = nullptr;
  EXPECT_EQ(xrGetInstanceProcAddr(instance_, "xrCreateHandTrackerEXT", &fn),
            XR_ERROR_FUNCTION_UNSUPPORTED);
}

TEST_F(MockRuntime, HandJointsFromPalmAndPinch) {
  std::string sc = write_scenario("hands.json", R"({
    "hands": {
      "right": [
        {"frame": 0, "palm": {"position": [0.2, 1.2, 0.4], "orientation": [0, 0, 0, 1]}, "pinch": 0.0},
        {"frame": 10, "palm": {"position": [0.3, 1.2, 0.4], "orientation": [0, 0, 0, 1]}, "pinch": 1.0}
      ]
    }
  })");
  setenv("DRAPE_MOCK_SCENARIO", sc.c_str(), 1);
  create();
  create_headless_session();
  begin();
  auto create_tracker = proc<PFN_xrCreateHandTrackerEXT>(instance_, "xrCreateHandTrackerEXT");
  auto locate = proc<PFN_xrLocateHandJointsEXT>(instance_, "xrLocateHandJointsEXT");
  XrHandTrackerCreateInfoEXT hc{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
  hc.hand = XR_HAND_RIGHT_EXT;
  hc.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
  XrHandTrackerEXT right, left;
  ASSERT_EQ(create_tracker(session_, &hc, &right), XR_SUCCESS);
  hc.hand = XR_HAND_LEFT_EXT;
  ASSERT_EQ(create_tracker(session_, &hc, &left), XR_SUCCESS);
  XrSpace st = stage();
  std::vector<XrTime> times;
  for (int i = 0; i <= 10; ++i) times.push_back(frame());
  XrHandJointLocationEXT joints[XR_HAND_JOINT_COUNT_EXT];
  XrHandJointLocationsEXT loc{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
  loc.jointCount = XR_HAND_JOINT_COUNT_EXT;
  loc.jointLocations = joints;
  XrHandJointsLocateInfoEXT li{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
  li.baseSpace = st;
  auto gap = [&] {
    auto& a = joints[XR_HAND_JOINT_THUMB_TIP_EXT].pose.position;
    auto& b = joints[XR_HAND_JOINT_INDEX_TIP_EXT].pose.position;
    return std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) +
                     (a.z - b.z) * (a.z - b.z));
  };
  for (int f : {0, 5, 10}) {
    li.time = times[f];
    ASSERT_EQ(locate(right, &li, &loc), XR_SUCCESS);
    ASSERT_TRUE(loc.isActive);
    float pinch = f / 10.f;
    float want = drape::mock::kOpenPinchGap +
                 (drape::mock::kClosedPinchGap - drape::mock::kOpenPinchGap) * pinch;
    std::printf("frame %d: thumb-index gap %.6f m (expected %.6f)\n", f, gap(), want);
    EXPECT_NEAR(gap(), want, 1e-5);
    EXPECT_NEAR(joints[XR_HAND_JOINT_PALM_EXT].pose.position.x, 0.2f + 0.01f * f, 1e-5);
    EXPECT_NEAR(joints[XR_HAND_JOINT_PALM_EXT].pose.position.y, 1.2f, 1e-5);
    for (auto& j : joints) {
      EXPECT_EQ(j.locationFlags & XR_SPACE_LOCATION_POSITION_TRACKED_BIT,
                XR_SPACE_LOCATION_POSITION_TRACKED_BIT);
      EXPECT_GT(j.radius, 0.f);
    }
    // Fingers point along -z of the palm; the index tip is ahead of the palm.
    EXPECT_LT(joints[XR_HAND_JOINT_MIDDLE_TIP_EXT].pose.position.z, 0.4f - 0.1f);
  }
  // The left hand has no track in the scenario: not active.
  li.time = times[3];
  ASSERT_EQ(locate(left, &li, &loc), XR_SUCCESS);
  EXPECT_FALSE(loc.isActive);
  // Strictness: wrong joint count, bad time.
  loc.jointCount = 25;
  EXPECT_EQ(locate(right, &li, &loc), XR_ERROR_VALIDATION_FAILURE);
  loc.jointCount = XR_HAND_JOINT_COUNT_EXT;
  li.time = 0;
  EXPECT_EQ(locate(right, &li, &loc), XR_ERROR_TIME_INVALID);
}

TEST(Scenario, FistCurlsTheFingersIntoThePalm) {
  using namespace drape::mock;
  std::array<XrPosef, kHandJointCount> open, open0, fist;
  std::array<float, kHandJointCount> r;
  generate_hand(1, pose_identity(), 0.f, &open, &r);
  generate_hand(1, pose_identity(), 0.f, &open0, &r, 0.f);
  generate_hand(1, pose_identity(), 0.f, &fist, &r, 1.f);
  auto dist = [](const XrPosef& a, const XrPosef& b) { return len(sub(a.position, b.position)); };
  for (int j = 0; j < kHandJointCount; ++j) EXPECT_EQ(dist(open[j], open0[j]), 0.f) << j;
  const XrPosef& palm = open[XR_HAND_JOINT_PALM_EXT];
  for (int tip : {XR_HAND_JOINT_INDEX_TIP_EXT, XR_HAND_JOINT_MIDDLE_TIP_EXT,
                  XR_HAND_JOINT_RING_TIP_EXT, XR_HAND_JOINT_LITTLE_TIP_EXT}) {
    EXPECT_GT(dist(open[tip], palm), 0.08f) << tip;
    EXPECT_LT(dist(fist[tip], palm), 0.06f) << tip;
  }
  EXPECT_EQ(dist(fist[XR_HAND_JOINT_PALM_EXT], palm), 0.f);
  EXPECT_EQ(dist(fist[XR_HAND_JOINT_THUMB_TIP_EXT], open[XR_HAND_JOINT_THUMB_TIP_EXT]), 0.f);
}

TEST_F(MockRuntime, ActionsFollowScenarioControllerInputs) {
  std::string sc = write_scenario("actions.json", R"({
    "controllers": {
      "right": [
        {"frame": 0, "grip": {"position": [0.25, 1.1, 0.3]}, "inputs": {"trigger/value": 0.0, "a/click": false}},
        {"frame": 4, "grip": {"position": [0.25, 1.1, 0.3]}, "inputs": {"trigger/value": 1.0, "a/click": true}}
      ]
    }
  })");
  setenv("DRAPE_MOCK_SCENARIO", sc.c_str(), 1);
  create();
  XrActionSetCreateInfo asi{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::strcpy(asi.actionSetName, "gameplay");
  std::strcpy(asi.localizedActionSetName, "Gameplay");
  XrActionSet set;
  ASSERT_EQ(xrCreateActionSet(instance_, &asi, &set), XR_SUCCESS);
  XrActionSet dup;
  EXPECT_EQ(xrCreateActionSet(instance_, &asi, &dup), XR_ERROR_NAME_DUPLICATED);
  XrPath hands[2] = {path("/user/hand/left"), path("/user/hand/right")};
  auto make = [&](const char* name, XrActionType t) {
    XrActionCreateInfo ai{XR_TYPE_ACTION_CREATE_INFO};
    std::strcpy(ai.actionName, name);
    std::strcpy(ai.localizedActionName, name);
    ai.actionType = t;
    ai.countSubactionPaths = 2;
    ai.subactionPaths = hands;
    XrAction a = XR_NULL_HANDLE;
    EXPECT_EQ(xrCreateAction(set, &ai, &a), XR_SUCCESS);
    return a;
  };
  XrAction squeeze = make("squeeze", XR_ACTION_TYPE_FLOAT_INPUT);
  XrAction press = make("press", XR_ACTION_TYPE_BOOLEAN_INPUT);
  XrAction grip = make("grip", XR_ACTION_TYPE_POSE_INPUT);
  XrAction buzz = make("buzz", XR_ACTION_TYPE_VIBRATION_OUTPUT);
  std::vector<XrActionSuggestedBinding> b = {
      {squeeze, path("/user/hand/right/input/trigger/value")},
      {press, path("/user/hand/right/input/a/click")},
      {grip, path("/user/hand/right/input/grip/pose")},
      {buzz, path("/user/hand/right/output/haptic")}};
  XrInteractionProfileSuggestedBinding sb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
  sb.interactionProfile = path("/interaction_profiles/oculus/touch_controller");
  sb.countSuggestedBindings = static_cast<uint32_t>(b.size());
  sb.suggestedBindings = b.data();
  ASSERT_EQ(xrSuggestInteractionProfileBindings(instance_, &sb), XR_SUCCESS);
  // The simple controller has no a/click; an unknown profile is unsupported.
  XrInteractionProfileSuggestedBinding bad = sb;
  bad.interactionProfile = path("/interaction_profiles/khr/simple_controller");
  EXPECT_EQ(xrSuggestInteractionProfileBindings(instance_, &bad), XR_ERROR_PATH_UNSUPPORTED);
  bad.interactionProfile = path("/interaction_profiles/acme/teapot");
  EXPECT_EQ(xrSuggestInteractionProfileBindings(instance_, &bad), XR_ERROR_PATH_UNSUPPORTED);
  create_headless_session();
  XrActionStateGetInfo gi{XR_TYPE_ACTION_STATE_GET_INFO};
  gi.action = squeeze;
  XrActionStateFloat fst{XR_TYPE_ACTION_STATE_FLOAT};
  EXPECT_EQ(xrGetActionStateFloat(session_, &gi, &fst), XR_ERROR_ACTIONSET_NOT_ATTACHED);
  XrSessionActionSetsAttachInfo at{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  at.countActionSets = 1;
  at.actionSets = &set;
  ASSERT_EQ(xrAttachSessionActionSets(session_, &at), XR_SUCCESS);
  EXPECT_EQ(xrAttachSessionActionSets(session_, &at), XR_ERROR_ACTIONSETS_ALREADY_ATTACHED);
  EXPECT_EQ(xrSuggestInteractionProfileBindings(instance_, &sb),
            XR_ERROR_ACTIONSETS_ALREADY_ATTACHED);
  XrInteractionProfileState ps{XR_TYPE_INTERACTION_PROFILE_STATE};
  ASSERT_EQ(xrGetCurrentInteractionProfile(session_, hands[1], &ps), XR_SUCCESS);
  EXPECT_EQ(ps.interactionProfile, sb.interactionProfile);
  begin();
  XrActiveActionSet active{set, XR_NULL_PATH};
  XrActionsSyncInfo sync{XR_TYPE_ACTIONS_SYNC_INFO};
  sync.countActiveActionSets = 1;
  sync.activeActionSets = &active;
  XrSpace st = stage();
  XrActionSpaceCreateInfo asc{XR_TYPE_ACTION_SPACE_CREATE_INFO};
  asc.action = grip;
  asc.subactionPath = hands[1];
  asc.poseInActionSpace.orientation.w = 1;
  XrSpace grip_space;
  ASSERT_EQ(xrCreateActionSpace(session_, &asc, &grip_space), XR_SUCCESS);
  asc.action = squeeze;
  XrSpace wrong;
  EXPECT_EQ(xrCreateActionSpace(session_, &asc, &wrong), XR_ERROR_ACTION_TYPE_MISMATCH);
  for (int f = 0; f <= 4; ++f) {
    XrTime t = frame();
    ASSERT_EQ(xrSyncActions(session_, &sync), XR_SUCCESS);
    gi.action = squeeze;
    gi.subactionPath = hands[1];
    ASSERT_EQ(xrGetActionStateFloat(session_, &gi, &fst), XR_SUCCESS);
    EXPECT_TRUE(fst.isActive);
    EXPECT_NEAR(fst.currentState, f / 4.f, 1e-6) << "frame " << f;
    gi.action = press;
    XrActionStateBoolean bst{XR_TYPE_ACTION_STATE_BOOLEAN};
    ASSERT_EQ(xrGetActionStateBoolean(session_, &gi, &bst), XR_SUCCESS);
    EXPECT_EQ(bst.currentState, f == 4 ? XR_TRUE : XR_FALSE) << "frame " << f;
    EXPECT_EQ(bst.changedSinceLastSync, f == 4 ? XR_TRUE : XR_FALSE);
    XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
    ASSERT_EQ(xrLocateSpace(grip_space, st, t, &loc), XR_SUCCESS);
    EXPECT_TRUE(loc.locationFlags & XR_SPACE_LOCATION_POSITION_VALID_BIT);
    EXPECT_NEAR(loc.pose.position.x, 0.25f, 1e-5);
    EXPECT_NEAR(loc.pose.position.z, 0.3f, 1e-5);
  }
  // Left hand has no bindings: inactive. Type mismatch and undeclared subaction path.
  gi.action = squeeze;
  gi.subactionPath = hands[0];
  ASSERT_EQ(xrGetActionStateFloat(session_, &gi, &fst), XR_SUCCESS);
  EXPECT_FALSE(fst.isActive);
  XrActionStateBoolean bst{XR_TYPE_ACTION_STATE_BOOLEAN};
  EXPECT_EQ(xrGetActionStateBoolean(session_, &gi, &bst), XR_ERROR_ACTION_TYPE_MISMATCH);
  gi.subactionPath = path("/user/head");
  EXPECT_EQ(xrGetActionStateFloat(session_, &gi, &fst), XR_ERROR_PATH_UNSUPPORTED);
  // Haptics accepted; bound sources listed.
  XrHapticVibration vib{XR_TYPE_HAPTIC_VIBRATION};
  vib.amplitude = 0.5f;
  vib.duration = XR_MIN_HAPTIC_DURATION;
  XrHapticActionInfo hi{XR_TYPE_HAPTIC_ACTION_INFO};
  hi.action = buzz;
  hi.subactionPath = hands[1];
  EXPECT_EQ(xrApplyHapticFeedback(session_, &hi, reinterpret_cast<XrHapticBaseHeader*>(&vib)),
            XR_SUCCESS);
  hi.action = squeeze;
  EXPECT_EQ(xrApplyHapticFeedback(session_, &hi, reinterpret_cast<XrHapticBaseHeader*>(&vib)),
            XR_ERROR_ACTION_TYPE_MISMATCH);
  XrBoundSourcesForActionEnumerateInfo be{XR_TYPE_BOUND_SOURCES_FOR_ACTION_ENUMERATE_INFO};
  be.action = press;
  uint32_t n = 0;
  XrPath src[4];
  ASSERT_EQ(xrEnumerateBoundSourcesForAction(session_, &be, 4, &n, src), XR_SUCCESS);
  ASSERT_EQ(n, 1u);
  EXPECT_EQ(src[0], path("/user/hand/right/input/a/click"));
}

TEST_F(MockRuntime, ScriptedSessionLossAndRecovery) {
  setenv("DRAPE_MOCK_LOSE_SESSION_AT_FRAME", "3", 1);
  create();
  create_headless_session();
  begin();
  frame();
  frame();
  frame();
  drain_states();
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  EXPECT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_ERROR_SESSION_LOST);
  EXPECT_EQ(drain_states(), (std::vector<XrSessionState>{XR_SESSION_STATE_LOSS_PENDING}));
  EXPECT_EQ(xrBeginFrame(session_, nullptr), XR_ERROR_SESSION_LOST);
  ASSERT_EQ(xrDestroySession(session_), XR_SUCCESS);
  session_ = XR_NULL_HANDLE;
  // A new session can be created on the same instance and runs.
  create_headless_session();
  EXPECT_EQ(drain_states(),
            (std::vector<XrSessionState>{XR_SESSION_STATE_IDLE, XR_SESSION_STATE_READY}));
}

TEST_F(MockRuntime, BadScenarioFailsInstanceCreation) {
  std::string sc =
      write_scenario("bad.json", R"({"hands": {"right": [{"frame": 0, "pinch": 0.5}]}})");
  setenv("DRAPE_MOCK_SCENARIO", sc.c_str(), 1);
  XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
  std::strcpy(ci.applicationInfo.applicationName, "drape_mock_test");
  ci.applicationInfo.apiVersion = XR_CURRENT_API_VERSION;
  EXPECT_EQ(xrCreateInstance(&ci, &instance_), XR_ERROR_RUNTIME_FAILURE);
  instance_ = XR_NULL_HANDLE;
}

TEST(Scenario, ErrorsNameTheFileAndField) {
  struct Case {
    const char* text;
    const char* field;
  };
  const Case cases[] = {
      {R"({"hands": {"right": [{"frame": 0, "pinch": 0.5}]}})", "hands.right[0]"},
      {R"({"hands": {"middle": []}})", "hands.middle"},
      {R"({"head": [{"frame": 3, "position": [0,1,0]}, {"frame": 1, "position": [0,1,0]}]})",
       "head[1].frame"},
      {R"({"controllers": {"left": [{"frame": 0, "inputs": {"trigger/value": "x"}}]}})",
       "controllers.left[0].inputs.trigger/value"},
      {R"({"end_after_frames": -2})", "end_after_frames"},
      {R"({"audio": [{"frame": 3}]})", "audio[0].wav"},
      {R"({"events": [{"frame": 3, "type": "explode"}]})", "events[0].type"},
      {R"({"bogus": 1})", "bogus"},
      {R"({"head": [)", "invalid JSON"},
  };
  int i = 0;
  for (const Case& c : cases) {
    std::string p = write_scenario("case" + std::to_string(i++) + ".json", c.text);
    drape::mock::Scenario s;
    std::string err;
    EXPECT_FALSE(drape::mock::load_scenario(p, &s, &err)) << c.text;
    EXPECT_NE(err.find(p), std::string::npos) << err;
    EXPECT_NE(err.find(c.field), std::string::npos) << err;
  }
  drape::mock::Scenario s;
  std::string err;
  EXPECT_FALSE(drape::mock::load_scenario(temp_dir() + "/missing.json", &s, &err));
  EXPECT_NE(err.find("missing.json"), std::string::npos);
}

TEST(Scenario, BundledScenariosLoad) {
  int n = 0;
  for (auto& e :
       std::filesystem::directory_iterator(std::string(DRAPE_SOURCE_DIR) + "/assets/scenarios")) {
    if (e.path().extension() != ".json") continue;
    drape::mock::Scenario s;
    std::string err;
    EXPECT_TRUE(drape::mock::load_scenario(e.path().string(), &s, &err)) << err;
    ++n;
  }
  EXPECT_GT(n, 0);
}

}  // namespace
