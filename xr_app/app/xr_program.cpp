// The OpenXR program: instance, session, events and the frame loop (see xr_program.hpp).
#include "xr_app/app/xr_program.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

namespace drape::app {

namespace {
XRAPI_ATTR XrBool32 XRAPI_CALL debug_callback(XrDebugUtilsMessageSeverityFlagsEXT,
                                              XrDebugUtilsMessageTypeFlagsEXT,
                                              const XrDebugUtilsMessengerCallbackDataEXT* data,
                                              void* user) {
  auto* r = static_cast<XrAppResult*>(user);
  ++r->validation_messages;
  if (r->log.size() < 200)
    r->log.push_back(std::string("validation: ") + (data && data->message ? data->message : ""));
  return XR_FALSE;
}

bool has_extension(const std::vector<XrExtensionProperties>& props, const char* name) {
  for (const auto& p : props)
    if (!std::strcmp(p.extensionName, name)) return true;
  return false;
}

// The instance extensions of the runtime (layer nullptr) or of an API layer.
std::vector<XrExtensionProperties> instance_extensions(const char* layer) {
  uint32_t n = 0;
  if (XR_FAILED(xrEnumerateInstanceExtensionProperties(layer, 0, &n, nullptr))) return {};
  std::vector<XrExtensionProperties> props(n, {XR_TYPE_EXTENSION_PROPERTIES});
  xrEnumerateInstanceExtensionProperties(layer, n, &n, props.data());
  return props;
}
}  // namespace

XrProgram::XrProgram(const XrAppOptions& opt, XrAppResult* res)
    : opt_(opt), rep_(*res, opt.verbose), graphics_(rep_), input_(rep_) {}

XrProgram::~XrProgram() {
  teardown();
}

void XrProgram::set_state(XrAppState s) {
  if (state_ == s) return;
  rep_.note(std::string("state ") + to_string(state_) + " -> " + to_string(s));
  state_ = s;
}

// The loader's explicitly enabled layers (the core validation layer) offer debug utils too.
bool XrProgram::offers_debug_utils_through_layers() {
  for (const auto& layer : opt_.api_layers)
    if (!layer.empty() &&
        has_extension(instance_extensions(layer.c_str()), XR_EXT_DEBUG_UTILS_EXTENSION_NAME))
      return true;
  return false;
}

bool XrProgram::create_instance() {
  uint32_t n = 0;
  XrResult x = xrEnumerateInstanceExtensionProperties(nullptr, 0, &n, nullptr);
  if (XR_FAILED(x)) {
    rep_.r.error =
        "no OpenXR runtime (xrEnumerateInstanceExtensionProperties: " + std::to_string(x) +
        "); set XR_RUNTIME_JSON or install a runtime (docs/xr.md)";
    rep_.note(rep_.r.error);
    set_state(XrAppState::kNoRuntime);
    return false;
  }
  const auto props = instance_extensions(nullptr);
  const bool has_vk2 = has_extension(props, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME);
  has_hands_ext_ = has_extension(props, XR_EXT_HAND_TRACKING_EXTENSION_NAME);
  has_depth_ext_ = has_extension(props, XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME);
  has_debug_ext_ = has_extension(props, XR_EXT_DEBUG_UTILS_EXTENSION_NAME) ||
                   offers_debug_utils_through_layers();
  if (!has_vk2) {
    rep_.r.error = "the OpenXR runtime does not offer XR_KHR_vulkan_enable2";
    set_state(XrAppState::kFailed);
    return false;
  }
  std::vector<const char*> exts = {XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME};
  if (has_hands_ext_) exts.push_back(XR_EXT_HAND_TRACKING_EXTENSION_NAME);
  if (has_depth_ext_) exts.push_back(XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME);
  if (has_debug_ext_) exts.push_back(XR_EXT_DEBUG_UTILS_EXTENSION_NAME);
  XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
  std::snprintf(ci.applicationInfo.applicationName, XR_MAX_APPLICATION_NAME_SIZE, "drape");
  ci.applicationInfo.applicationVersion = 1;
  std::snprintf(ci.applicationInfo.engineName, XR_MAX_ENGINE_NAME_SIZE, "drape");
  ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
  ci.enabledExtensionCount = static_cast<uint32_t>(exts.size());
  ci.enabledExtensionNames = exts.data();
  x = xrCreateInstance(&ci, &instance_);
  if (XR_FAILED(x)) {
    rep_.r.error = "xrCreateInstance failed (" + std::to_string(x) + ")";
    rep_.note(rep_.r.error);
    set_state(x == XR_ERROR_RUNTIME_UNAVAILABLE ? XrAppState::kNoRuntime : XrAppState::kFailed);
    return false;
  }
  rep_.instance = instance_;
  if (has_debug_ext_) create_debug_messenger();
  XrInstanceProperties ip{XR_TYPE_INSTANCE_PROPERTIES};
  if (XR_SUCCEEDED(xrGetInstanceProperties(instance_, &ip))) rep_.r.runtime_name = ip.runtimeName;
  rep_.note("runtime: " + rep_.r.runtime_name);
  if (!get_system()) return false;
  set_state(XrAppState::kInstance);
  return true;
}

// Validation messages (XR_EXT_debug_utils) are counted in the result.
void XrProgram::create_debug_messenger() {
  auto create =
      xr_function<PFN_xrCreateDebugUtilsMessengerEXT>(instance_, "xrCreateDebugUtilsMessengerEXT");
  XrDebugUtilsMessengerCreateInfoEXT mi{XR_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mi.messageSeverities = XR_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                         XR_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mi.messageTypes = XR_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                    XR_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    XR_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT |
                    XR_DEBUG_UTILS_MESSAGE_TYPE_CONFORMANCE_BIT_EXT;
  mi.userCallback = &debug_callback;
  mi.userData = &rep_.r;
  if (create) create(instance_, &mi, &messenger_);
}

// The head-mounted system (waiting up to 5 s for a headset to be plugged in) and whether it
// tracks hands.
bool XrProgram::get_system() {
  XrSystemGetInfo gi{XR_TYPE_SYSTEM_GET_INFO};
  gi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  XrResult x = XR_SUCCESS;
  for (int attempt = 0;; ++attempt) {
    x = xrGetSystem(instance_, &gi, &system_);
    if (x != XR_ERROR_FORM_FACTOR_UNAVAILABLE || attempt >= 20) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  if (!rep_.ok(x, "xrGetSystem")) return false;
  if (has_hands_ext_) {
    XrSystemHandTrackingPropertiesEXT ht{XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT};
    XrSystemProperties sp{XR_TYPE_SYSTEM_PROPERTIES, &ht};
    if (XR_SUCCEEDED(xrGetSystemProperties(instance_, system_, &sp)))
      rep_.r.hand_tracking = ht.supportsHandTracking == XR_TRUE;
  }
  return true;
}

bool XrProgram::create_device_and_content() {
  if (!graphics_.create_device(instance_, system_)) return false;
  content_ = make_draping_session(graphics_.device(), opt_, rep_);
  return rep_.r.error.empty();  // e.g. a command map file that does not load
}

bool XrProgram::create_session() {
  const XrGraphicsBindingVulkan2KHR gb = graphics_.binding();
  XrSessionCreateInfo ci{XR_TYPE_SESSION_CREATE_INFO, &gb};
  ci.systemId = system_;
  if (!rep_.ok(xrCreateSession(instance_, &ci, &session_), "xrCreateSession")) return false;
  ++rep_.r.sessions;
  session_frame_ = 0;
  set_state(XrAppState::kSessionIdle);
  // STAGE (floor at y = 0) when offered, LOCAL otherwise.
  uint32_t n = 0;
  xrEnumerateReferenceSpaces(session_, 0, &n, nullptr);
  std::vector<XrReferenceSpaceType> types(n);
  xrEnumerateReferenceSpaces(session_, n, &n, types.data());
  bool stage = false;
  for (auto t : types) stage = stage || t == XR_REFERENCE_SPACE_TYPE_STAGE;
  XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rs.referenceSpaceType = stage ? XR_REFERENCE_SPACE_TYPE_STAGE : XR_REFERENCE_SPACE_TYPE_LOCAL;
  rs.poseInReferenceSpace.orientation.w = 1;
  if (!stage) rs.poseInReferenceSpace.position.y = -1.6f;  // LOCAL: put the floor below the head
  if (!rep_.ok(xrCreateReferenceSpace(session_, &rs, &space_), "xrCreateReferenceSpace"))
    return false;
  rep_.note(stage ? "space: STAGE" : "space: LOCAL (no STAGE)");
  if (!input_.has_actions()) input_.create_actions(instance_);
  input_.attach(instance_, session_, rep_.r.hand_tracking);
  return graphics_.create_swapchains(instance_, system_, session_, opt_.eye_size,
                                     has_depth_ext_ && content_ != nullptr);
}

void XrProgram::destroy_session() {
  if (content_) content_->forget_targets();
  graphics_.destroy_swapchains();
  input_.detach(instance_);
  if (space_) xrDestroySpace(space_);
  space_ = XR_NULL_HANDLE;
  if (session_) xrDestroySession(session_);
  session_ = XR_NULL_HANDLE;
  running_ = false;
}

void XrProgram::teardown() {
  destroy_session();
  if (content_) content_->finish();
  content_.reset();
  graphics_.destroy_device();
  input_.destroy_actions();
  if (messenger_) {
    auto destroy = xr_function<PFN_xrDestroyDebugUtilsMessengerEXT>(
        instance_, "xrDestroyDebugUtilsMessengerEXT");
    if (destroy) destroy(messenger_);
    messenger_ = XR_NULL_HANDLE;
  }
  if (instance_) xrDestroyInstance(instance_);
  instance_ = XR_NULL_HANDLE;
  rep_.instance = XR_NULL_HANDLE;
}

bool XrProgram::handle_events() {
  XrEventDataBuffer ev{XR_TYPE_EVENT_DATA_BUFFER};
  while (xrPollEvent(instance_, &ev) == XR_SUCCESS) {
    if (ev.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED) {
      if (!on_session_state(reinterpret_cast<XrEventDataSessionStateChanged*>(&ev)->state))
        return false;
    } else if (ev.type == XR_TYPE_EVENT_DATA_INSTANCE_LOSS_PENDING) {
      rep_.r.error = "instance loss pending";
      set_state(XrAppState::kFailed);
      return false;
    }
    ev = {XR_TYPE_EVENT_DATA_BUFFER};
  }
  return true;
}

bool XrProgram::on_session_state(XrSessionState s) {
  switch (s) {
    case XR_SESSION_STATE_READY: {
      XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
      bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
      if (rep_.ok(xrBeginSession(session_, &bi), "xrBeginSession")) {
        running_ = true;
        set_state(XrAppState::kSessionRunning);
      }
      return true;
    }
    case XR_SESSION_STATE_STOPPING:
      set_state(XrAppState::kSessionStopping);
      rep_.ok(xrEndSession(session_), "xrEndSession");
      running_ = false;
      return true;
    case XR_SESSION_STATE_EXITING:
      set_state(XrAppState::kExiting);
      return false;
    case XR_SESSION_STATE_LOSS_PENDING:  // the session is re-created
      ++rep_.r.sessions_lost;
      set_state(XrAppState::kSessionLost);
      if (content_) content_->session_lost();
      destroy_session();
      if (rep_.r.sessions_lost > opt_.max_session_restarts) {
        rep_.r.error = "session lost too often";
        return false;
      }
      return create_session();
    default:
      return true;
  }
}

bool XrProgram::render_layer(const XrFrameState& fs, int64_t frame, FrameLaps& laps,
                             uint32_t& layer_count) {
  XrView views[2] = {{XR_TYPE_VIEW}, {XR_TYPE_VIEW}};
  XrViewState vs{XR_TYPE_VIEW_STATE};
  XrViewLocateInfo vl{XR_TYPE_VIEW_LOCATE_INFO};
  vl.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  vl.displayTime = fs.predictedDisplayTime;
  vl.space = space_;
  uint32_t nv = 0;
  const XrResult x = xrLocateViews(session_, &vl, &vs, 2, &nv, views);
  laps.lap("xr.locate_views");
  const bool located = XR_SUCCEEDED(x) &&
                       (vs.viewStateFlags & XR_VIEW_STATE_ORIENTATION_VALID_BIT) &&
                       (vs.viewStateFlags & XR_VIEW_STATE_POSITION_VALID_BIT);
  if (!located) return true;
  if (content_) content_->wait_for_pose(frame);
  laps.lap("pose_wait");
  if (content_) content_->record_probes(frame);
  laps.lap("probes");
  // Both eyes: acquire and wait both swapchain images, draw them with one geometry build and
  // one submission, release both.
  uint32_t idx[2] = {0, 0}, didx[2] = {0, 0};
  if (!graphics_.acquire(idx, didx)) return false;
  laps.lap("xr.acquire");
  if (content_) {
    EyeTarget eyes[2];
    for (int e = 0; e < 2; ++e) {
      const Eye& eye = graphics_.eye(e);
      eyes[e] = {views[e], eye.images[idx[e]].image, graphics_.format(), eye.width, eye.height};
      if (graphics_.has_depth()) {
        eyes[e].depth_image = eye.depth_images[didx[e]].image;
        eyes[e].depth_format = graphics_.depth_format();
      }
    }
    content_->draw(frame, eyes, laps);
  }
  if (!graphics_.release()) return false;
  for (int e = 0; e < 2; ++e) {
    const Eye& eye = graphics_.eye(e);
    views_[e].pose = views[e].pose;
    views_[e].fov = views[e].fov;
    views_[e].subImage.swapchain = eye.chain;
    views_[e].subImage.imageRect = {
        {0, 0}, {static_cast<int32_t>(eye.width), static_cast<int32_t>(eye.height)}};
    // The depth drawn with this eye (0 at kNearZ, 1 at kFarZ) for the compositor.
    views_[e].next = nullptr;
    if (content_ && graphics_.has_depth()) {
      depth_[e].subImage.swapchain = eye.depth_chain;
      depth_[e].subImage.imageRect = views_[e].subImage.imageRect;
      depth_[e].minDepth = 0.0f;
      depth_[e].maxDepth = 1.0f;
      depth_[e].nearZ = kNearZ;
      depth_[e].farZ = kFarZ;
      views_[e].next = &depth_[e];
    }
  }
  laps.lap("xr.release");
  layer_.space = space_;
  layer_.viewCount = 2;
  layer_.views = views_;
  layer_count = 1;
  return true;
}

bool XrProgram::frame() {
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  const auto tw = Clock::now();
  XrResult x = xrWaitFrame(session_, nullptr, &fs);
  if (x == XR_ERROR_SESSION_LOST) return true;  // LOSS_PENDING arrives through the event queue
  if (!rep_.ok(x, "xrWaitFrame")) return false;
  const auto t0 = Clock::now();
  const double cpu0 = thread_cpu_ms(), pcpu0 = process_cpu_ms();
  FrameLaps laps(t0);
  laps.add("xr.wait_frame", ms_between(tw, t0));
  const int64_t this_frame = session_frame_++;
  if (content_) content_->frame_started();
  x = xrBeginFrame(session_, nullptr);
  if (x == XR_ERROR_SESSION_LOST) return true;
  if (!rep_.ok(x, "xrBeginFrame")) return false;
  laps.lap("xr.begin_frame");

  HandInput in;
  input_.read_frame(session_, space_, fs.predictedDisplayTime, in, rep_.r.max_trigger);
  laps.lap("input");
  if (content_) {
    input_.read_controllers(session_, space_, fs.predictedDisplayTime, in);
    content_->interact(this_frame, in);
  }
  laps.lap("interact");
  if (in.joints_active[1]) {  // the right hand's thumb-index gap
    ++rep_.r.hand_frames_tracked;
    const auto& a = in.joints[1][XR_HAND_JOINT_THUMB_TIP_EXT].pose.position;
    const auto& b = in.joints[1][XR_HAND_JOINT_INDEX_TIP_EXT].pose.position;
    const float d = std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) +
                              (a.z - b.z) * (a.z - b.z));
    rep_.r.min_pinch_gap_m = std::min(rep_.r.min_pinch_gap_m, d);
  }

  uint32_t layer_count = 0;
  if (fs.shouldRender && !render_layer(fs, this_frame, laps, layer_count)) return false;
  const XrCompositionLayerBaseHeader* layers[1] = {
      reinterpret_cast<XrCompositionLayerBaseHeader*>(&layer_)};
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  ei.displayTime = fs.predictedDisplayTime;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  ei.layerCount = layer_count;
  ei.layers = layers;
  x = xrEndFrame(session_, &ei);
  if (x == XR_ERROR_SESSION_LOST) return true;
  if (!rep_.ok(x, "xrEndFrame")) return false;
  laps.lap("xr.end_frame");
  const auto t_end = Clock::now();
  rep_.r.frame_ms.push_back(ms_between(t0, t_end));
  if (content_) content_->frame_ended(t_end);
  laps.record(rep_.r.profile_ms);
  rep_.r.profile_ms["frame.cpu"].push_back(thread_cpu_ms() - cpu0);
  rep_.r.profile_ms["frame.process_cpu"].push_back(process_cpu_ms() - pcpu0);
  ++rep_.r.frames;
  if (layer_count) ++rep_.r.frames_rendered;
  if (opt_.max_frames > 0 && rep_.r.frames >= opt_.max_frames && !exit_requested_) {
    exit_requested_ = true;
    rep_.ok(xrRequestExitSession(session_), "xrRequestExitSession");
  }
  return true;
}

void XrProgram::run() {
  if (!create_instance()) return;
  if (!create_device_and_content() || !create_session()) {
    set_state(XrAppState::kFailed);
    return;
  }
  while (handle_events() && state_ != XrAppState::kFailed) {
    if (!running_) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));  // wait for READY / EXITING
      continue;
    }
    if (!frame()) {
      set_state(XrAppState::kFailed);
      break;
    }
  }
}

}  // namespace drape::app
