// The mock OpenXR runtime: loader negotiation, xrGetInstanceProcAddr, instance, system,
// paths, events, session state machine, reference spaces, views and the frame loop.
#include "xr_app/mock_runtime/runtime.hpp"

#include <openxr/openxr_reflection.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <thread>

#include "xr_app/mock_runtime/loader_negotiation.hpp"
#include "xr_app/mock_runtime/window.hpp"

namespace drape::mock {

std::recursive_mutex g_lock;
namespace {
std::unordered_map<uint64_t, std::unique_ptr<Object>> g_objects;
uint64_t g_next_handle = 0x1000;
}  // namespace

uint64_t register_object(std::unique_ptr<Object> obj, uint64_t parent) {
  uint64_t h = g_next_handle++;
  obj->handle = h;
  obj->parent = parent;
  g_objects[h] = std::move(obj);
  return h;
}

Object* find_object(uint64_t handle) {
  auto it = g_objects.find(handle);
  return it == g_objects.end() ? nullptr : it->second.get();
}

void destroy_object(uint64_t handle) {
  std::vector<uint64_t> children;
  for (auto& [h, o] : g_objects)
    if (o->parent == handle) children.push_back(h);
  // Destroy swapchains before the session's command pool etc.: children in handle order.
  std::sort(children.begin(), children.end());
  for (uint64_t c : children) destroy_object(c);
  g_objects.erase(handle);
}

void for_each_child(uint64_t parent, Kind kind, const std::function<void(Object*)>& fn) {
  for (auto& [h, o] : g_objects)
    if (o->parent == parent && o->kind == kind) fn(o.get());
}

void for_each_of_kind(Kind kind, const std::function<void(Object*)>& fn) {
  for (auto& [h, o] : g_objects)
    if (o->kind == kind) fn(o.get());
}

Instance* instance_of(const Object* o) {
  while (o && o->kind != Kind::Instance) o = find_object(o->parent);
  return o ? static_cast<Instance*>(const_cast<Object*>(o)) : nullptr;
}

void log(const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  std::fprintf(stderr, "[drape-mock] ");
  std::vfprintf(stderr, fmt, ap);
  std::fprintf(stderr, "\n");
  va_end(ap);
}

XrTime now_ns() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<XrTime>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

double frame_of_time(const Session* s, XrTime t) {
  if (s->epoch == 0) return 0;
  return static_cast<double>(t - s->epoch) / static_cast<double>(kFramePeriodNs);
}

namespace {
bool valid_path_string(const char* p) {
  size_t n = std::strlen(p);
  if (n == 0 || n >= XR_MAX_PATH_LENGTH || p[0] != '/' || p[n - 1] == '/') return false;
  size_t comp_start = 1;
  for (size_t i = 1; i <= n; ++i) {
    if (i == n || p[i] == '/') {
      size_t len = i - comp_start;
      if (len == 0) return false;
      bool only_dots = true;
      for (size_t k = comp_start; k < i; ++k) only_dots = only_dots && p[k] == '.';
      if (only_dots) return false;
      comp_start = i + 1;
      continue;
    }
    char c = p[i];
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.'))
      return false;
  }
  return true;
}
}  // namespace

XrPath intern_path(Instance* inst, const std::string& s) {
  auto it = inst->path_ids.find(s);
  if (it != inst->path_ids.end()) return it->second;
  XrPath id = inst->paths.size();
  inst->paths.push_back(s);
  inst->path_ids[s] = id;
  return id;
}

std::string path_string(Instance* inst, XrPath p) {
  if (p == XR_NULL_PATH || p >= inst->paths.size()) return "";
  return inst->paths[p];
}

void push_event(Instance* inst, const void* ev, size_t size) {
  XrEventDataBuffer buf{};
  std::memcpy(&buf, ev, std::min(size, sizeof(buf)));
  if (inst->events.size() >= 256) {
    inst->events.pop_front();
    XrEventDataEventsLost lost{XR_TYPE_EVENT_DATA_EVENTS_LOST};
    lost.lostEventCount = 1;
    XrEventDataBuffer lb{};
    std::memcpy(&lb, &lost, sizeof(lost));
    inst->events.push_front(lb);
  }
  inst->events.push_back(buf);
}

void queue_state(Session* s, XrSessionState state) {
  s->state = state;
  XrEventDataSessionStateChanged ev{XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED};
  ev.session = to_handle<XrSession>(s->handle);
  ev.state = state;
  ev.time = now_ns();
  push_event(instance_of(s), &ev, sizeof(ev));
}

XrResult two_call_string(uint32_t capacity, uint32_t* count, char* out, const std::string& s) {
  if (!count) return XR_ERROR_VALIDATION_FAILURE;
  *count = static_cast<uint32_t>(s.size() + 1);
  if (capacity == 0) return XR_SUCCESS;
  if (!out) return XR_ERROR_VALIDATION_FAILURE;
  if (capacity < s.size() + 1) return XR_ERROR_SIZE_INSUFFICIENT;
  std::memcpy(out, s.c_str(), s.size() + 1);
  return XR_SUCCESS;
}

namespace {

constexpr XrSystemId kSystemId = 1;
constexpr uint32_t kRecommendedSize = 1024, kMaxSize = 4096;
constexpr uint32_t kMaxLayers = 16;

struct ExtensionInfo {
  const char* name;
  uint32_t version;
};
const ExtensionInfo kExtensions[] = {
    {XR_KHR_VULKAN_ENABLE_EXTENSION_NAME, XR_KHR_vulkan_enable_SPEC_VERSION},
    {XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME, XR_KHR_vulkan_enable2_SPEC_VERSION},
    {XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_EXT_hand_tracking_SPEC_VERSION},
    {XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME, XR_KHR_composition_layer_depth_SPEC_VERSION},
    {XR_MND_HEADLESS_EXTENSION_NAME, XR_MND_headless_SPEC_VERSION},
};

#define DRAPE_LOCK std::lock_guard<std::recursive_mutex> guard_(g_lock)

Session* live_session(XrSession h, XrResult* err) {
  Session* s = lookup<Session>(h);
  if (!s) {
    *err = XR_ERROR_HANDLE_INVALID;
    return nullptr;
  }
  if (s->lost) {
    *err = XR_ERROR_SESSION_LOST;
    return nullptr;
  }
  return s;
}

// ------------------------------------------------------------------ instance
XrResult XRAPI_CALL EnumerateApiLayerProperties(uint32_t cap, uint32_t* count,
                                                XrApiLayerProperties* props) {
  return two_call<XrApiLayerProperties>(cap, count, props, {});
}

XrResult XRAPI_CALL EnumerateInstanceExtensionProperties(const char* layer, uint32_t cap,
                                                         uint32_t* count,
                                                         XrExtensionProperties* props) {
  if (layer && layer[0]) return XR_ERROR_API_LAYER_NOT_PRESENT;
  if (!count) return XR_ERROR_VALIDATION_FAILURE;
  const uint32_t n = sizeof(kExtensions) / sizeof(kExtensions[0]);
  *count = n;
  if (cap == 0) return XR_SUCCESS;
  if (!props) return XR_ERROR_VALIDATION_FAILURE;
  if (cap < n) return XR_ERROR_SIZE_INSUFFICIENT;
  for (uint32_t i = 0; i < n; ++i) {
    if (props[i].type != XR_TYPE_EXTENSION_PROPERTIES) return XR_ERROR_VALIDATION_FAILURE;
    std::snprintf(props[i].extensionName, XR_MAX_EXTENSION_NAME_SIZE, "%s", kExtensions[i].name);
    props[i].extensionVersion = kExtensions[i].version;
  }
  return XR_SUCCESS;
}

int64_t env_int(const char* name, int64_t def) {
  const char* v = std::getenv(name);
  if (!v || !*v) return def;
  char* end = nullptr;
  long long x = std::strtoll(v, &end, 10);
  if (!end || *end) {
    log("ignoring %s=%s (not an integer)", name, v);
    return def;
  }
  return x;
}

XrResult XRAPI_CALL CreateInstance(const XrInstanceCreateInfo* info, XrInstance* out) {
  DRAPE_LOCK;
  if (!info || !out || info->type != XR_TYPE_INSTANCE_CREATE_INFO)
    return XR_ERROR_VALIDATION_FAILURE;
  if (info->createFlags != 0) return XR_ERROR_VALIDATION_FAILURE;
  if (XR_VERSION_MAJOR(info->applicationInfo.apiVersion) != 1 ||
      info->applicationInfo.apiVersion > XR_CURRENT_API_VERSION)
    return XR_ERROR_API_VERSION_UNSUPPORTED;
  if (info->applicationInfo.applicationName[0] == 0) return XR_ERROR_NAME_INVALID;
  if (info->enabledExtensionCount > 0 && !info->enabledExtensionNames)
    return XR_ERROR_VALIDATION_FAILURE;
  auto inst = std::make_unique<Instance>();
  for (uint32_t i = 0; i < info->enabledExtensionCount; ++i) {
    const char* e = info->enabledExtensionNames[i];
    if (!e) return XR_ERROR_VALIDATION_FAILURE;
    bool known = false;
    for (const auto& k : kExtensions) known = known || std::strcmp(k.name, e) == 0;
    if (!known) return XR_ERROR_EXTENSION_NOT_PRESENT;
    inst->extensions.insert(e);
  }
  inst->app_name = info->applicationInfo.applicationName;
  if (const char* sc = std::getenv("DRAPE_MOCK_SCENARIO"); sc && *sc) {
    std::string err;
    if (!load_scenario(sc, &inst->scenario, &err)) {
      log("scenario error: %s", err.c_str());
      return XR_ERROR_RUNTIME_FAILURE;
    }
    log("scenario %s", sc);
  }
  inst->end_after_frames = env_int("DRAPE_MOCK_END_AFTER_FRAMES", inst->scenario.end_after_frames);
  inst->fast = env_int("DRAPE_MOCK_FAST", inst->scenario.fast ? 1 : 0) != 0;
  inst->write_dir = inst->scenario.write_frames_dir;
  inst->write_every = inst->scenario.write_every;
  if (const char* w = std::getenv("DRAPE_MOCK_WRITE_FRAMES"); w && *w) inst->write_dir = w;
  inst->write_every = static_cast<int>(env_int("DRAPE_MOCK_WRITE_EVERY", inst->write_every));
  if (inst->write_every < 1) inst->write_every = 1;
  inst->window_mode = window_requested();
  if (inst->window_mode && inst->fast) {
    log("DRAPE_MOCK_WINDOW: frames are paced at 90 Hz (DRAPE_MOCK_FAST ignored)");
    inst->fast = false;
  }
  if (int64_t f = env_int("DRAPE_MOCK_LOSE_SESSION_AT_FRAME", -1); f >= 0)
    inst->scenario.events.push_back({f, "session_loss"});
  if (!inst->write_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(inst->write_dir, ec);
    if (ec) {
      log("cannot create frame directory %s: %s", inst->write_dir.c_str(), ec.message().c_str());
      return XR_ERROR_RUNTIME_FAILURE;
    }
  }
  *out = to_handle<XrInstance>(register_object(std::move(inst), 0));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL DestroyInstance(XrInstance h) {
  DRAPE_LOCK;
  Instance* inst = lookup<Instance>(h);
  if (!inst) return XR_ERROR_HANDLE_INVALID;
  std::fprintf(stderr, "frames composed: %lld\n", static_cast<long long>(inst->frames_composed));
  log("frames with layers: %lld, frames written: %lld",
      static_cast<long long>(inst->frames_with_layers),
      static_cast<long long>(inst->frames_written));
  destroy_object(inst->handle);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL GetInstanceProperties(XrInstance h, XrInstanceProperties* p) {
  DRAPE_LOCK;
  if (!lookup<Instance>(h)) return XR_ERROR_HANDLE_INVALID;
  if (!p || p->type != XR_TYPE_INSTANCE_PROPERTIES) return XR_ERROR_VALIDATION_FAILURE;
  p->runtimeVersion = XR_MAKE_VERSION(0, 1, 0);
  std::snprintf(p->runtimeName, XR_MAX_RUNTIME_NAME_SIZE, "drape mock runtime");
  return XR_SUCCESS;
}

XrResult XRAPI_CALL PollEvent(XrInstance h, XrEventDataBuffer* ev) {
  DRAPE_LOCK;
  Instance* inst = lookup<Instance>(h);
  if (!inst) return XR_ERROR_HANDLE_INVALID;
  if (!ev || ev->type != XR_TYPE_EVENT_DATA_BUFFER) return XR_ERROR_VALIDATION_FAILURE;
  if (inst->events.empty()) return XR_EVENT_UNAVAILABLE;
  *ev = inst->events.front();
  inst->events.pop_front();
  return XR_SUCCESS;
}

XrResult XRAPI_CALL ResultToString(XrInstance h, XrResult value,
                                   char buffer[XR_MAX_RESULT_STRING_SIZE]) {
  DRAPE_LOCK;
  if (!lookup<Instance>(h)) return XR_ERROR_HANDLE_INVALID;
  if (!buffer) return XR_ERROR_VALIDATION_FAILURE;
#define DRAPE_RESULT_CASE(name, val)                               \
  case name:                                                       \
    std::snprintf(buffer, XR_MAX_RESULT_STRING_SIZE, "%s", #name); \
    return XR_SUCCESS;
  switch (value) { XR_LIST_ENUM_XrResult(DRAPE_RESULT_CASE) default : break; }
#undef DRAPE_RESULT_CASE
  std::snprintf(buffer, XR_MAX_RESULT_STRING_SIZE, "XR_%s_%d",
                value < 0 ? "UNKNOWN_FAILURE" : "UNKNOWN_SUCCESS", static_cast<int>(value));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL StructureTypeToString(XrInstance h, XrStructureType value,
                                          char buffer[XR_MAX_STRUCTURE_NAME_SIZE]) {
  DRAPE_LOCK;
  if (!lookup<Instance>(h)) return XR_ERROR_HANDLE_INVALID;
  if (!buffer) return XR_ERROR_VALIDATION_FAILURE;
#define DRAPE_TYPE_CASE(name, val)                                  \
  case name:                                                        \
    std::snprintf(buffer, XR_MAX_STRUCTURE_NAME_SIZE, "%s", #name); \
    return XR_SUCCESS;
  switch (value) { XR_LIST_ENUM_XrStructureType(DRAPE_TYPE_CASE) default : break; }
#undef DRAPE_TYPE_CASE
  std::snprintf(buffer, XR_MAX_STRUCTURE_NAME_SIZE, "XR_UNKNOWN_STRUCTURE_TYPE_%d",
                static_cast<int>(value));
  return XR_SUCCESS;
}

// ------------------------------------------------------------------ system
XrResult XRAPI_CALL GetSystem(XrInstance h, const XrSystemGetInfo* info, XrSystemId* id) {
  DRAPE_LOCK;
  Instance* inst = lookup<Instance>(h);
  if (!inst) return XR_ERROR_HANDLE_INVALID;
  if (!info || !id || info->type != XR_TYPE_SYSTEM_GET_INFO) return XR_ERROR_VALIDATION_FAILURE;
  if (info->formFactor == XR_FORM_FACTOR_HANDHELD_DISPLAY) return XR_ERROR_FORM_FACTOR_UNSUPPORTED;
  if (info->formFactor != XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY) return XR_ERROR_VALIDATION_FAILURE;
  inst->system_got = true;
  *id = kSystemId;
  return XR_SUCCESS;
}

XrResult check_system(XrInstance h, XrSystemId id, Instance** out) {
  Instance* inst = lookup<Instance>(h);
  if (!inst) return XR_ERROR_HANDLE_INVALID;
  if (id != kSystemId || !inst->system_got) return XR_ERROR_SYSTEM_INVALID;
  if (out) *out = inst;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL GetSystemProperties(XrInstance h, XrSystemId id, XrSystemProperties* p) {
  DRAPE_LOCK;
  Instance* inst = nullptr;
  if (XrResult r = check_system(h, id, &inst); r != XR_SUCCESS) return r;
  if (!p || p->type != XR_TYPE_SYSTEM_PROPERTIES) return XR_ERROR_VALIDATION_FAILURE;
  p->systemId = id;
  p->vendorId = 0xD7A9;
  std::snprintf(p->systemName, XR_MAX_SYSTEM_NAME_SIZE, "Drape mock HMD (%s)",
                inst->window_mode ? "window" : "headless");
  p->graphicsProperties.maxSwapchainImageWidth = kMaxSize;
  p->graphicsProperties.maxSwapchainImageHeight = kMaxSize;
  p->graphicsProperties.maxLayerCount = kMaxLayers;
  p->trackingProperties.orientationTracking = XR_TRUE;
  p->trackingProperties.positionTracking = XR_TRUE;
  for (auto* n = static_cast<XrBaseOutStructure*>(p->next); n; n = n->next) {
    if (n->type == XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT) {
      reinterpret_cast<XrSystemHandTrackingPropertiesEXT*>(n)->supportsHandTracking =
          inst->extensions.count(XR_EXT_HAND_TRACKING_EXTENSION_NAME) ? XR_TRUE : XR_FALSE;
    }
  }
  return XR_SUCCESS;
}

XrResult XRAPI_CALL EnumerateEnvironmentBlendModes(XrInstance h, XrSystemId id,
                                                   XrViewConfigurationType vt, uint32_t cap,
                                                   uint32_t* count, XrEnvironmentBlendMode* out) {
  DRAPE_LOCK;
  if (XrResult r = check_system(h, id, nullptr); r != XR_SUCCESS) return r;
  if (vt != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO)
    return XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
  return two_call<XrEnvironmentBlendMode>(cap, count, out, {XR_ENVIRONMENT_BLEND_MODE_OPAQUE});
}

XrResult XRAPI_CALL EnumerateViewConfigurations(XrInstance h, XrSystemId id, uint32_t cap,
                                                uint32_t* count, XrViewConfigurationType* out) {
  DRAPE_LOCK;
  if (XrResult r = check_system(h, id, nullptr); r != XR_SUCCESS) return r;
  return two_call<XrViewConfigurationType>(cap, count, out,
                                           {XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO});
}

XrResult XRAPI_CALL GetViewConfigurationProperties(XrInstance h, XrSystemId id,
                                                   XrViewConfigurationType vt,
                                                   XrViewConfigurationProperties* p) {
  DRAPE_LOCK;
  if (XrResult r = check_system(h, id, nullptr); r != XR_SUCCESS) return r;
  if (!p || p->type != XR_TYPE_VIEW_CONFIGURATION_PROPERTIES) return XR_ERROR_VALIDATION_FAILURE;
  if (vt != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO)
    return XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
  p->viewConfigurationType = vt;
  p->fovMutable = XR_FALSE;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL EnumerateViewConfigurationViews(XrInstance h, XrSystemId id,
                                                    XrViewConfigurationType vt, uint32_t cap,
                                                    uint32_t* count,
                                                    XrViewConfigurationView* views) {
  DRAPE_LOCK;
  if (XrResult r = check_system(h, id, nullptr); r != XR_SUCCESS) return r;
  if (vt != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO)
    return XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
  if (!count) return XR_ERROR_VALIDATION_FAILURE;
  *count = 2;
  if (cap == 0) return XR_SUCCESS;
  if (!views) return XR_ERROR_VALIDATION_FAILURE;
  if (cap < 2) return XR_ERROR_SIZE_INSUFFICIENT;
  for (int i = 0; i < 2; ++i) {
    if (views[i].type != XR_TYPE_VIEW_CONFIGURATION_VIEW) return XR_ERROR_VALIDATION_FAILURE;
    views[i].recommendedImageRectWidth = kRecommendedSize;
    views[i].recommendedImageRectHeight = kRecommendedSize;
    views[i].maxImageRectWidth = kMaxSize;
    views[i].maxImageRectHeight = kMaxSize;
    views[i].recommendedSwapchainSampleCount = 1;
    views[i].maxSwapchainSampleCount = 1;
  }
  return XR_SUCCESS;
}

// ------------------------------------------------------------------ session
bool init_session_vulkan_wrapper(Session* s);

XrResult XRAPI_CALL CreateSession(XrInstance h, const XrSessionCreateInfo* info, XrSession* out) {
  DRAPE_LOCK;
  Instance* inst = lookup<Instance>(h);
  if (!inst) return XR_ERROR_HANDLE_INVALID;
  if (!info || !out || info->type != XR_TYPE_SESSION_CREATE_INFO)
    return XR_ERROR_VALIDATION_FAILURE;
  if (info->createFlags != 0) return XR_ERROR_VALIDATION_FAILURE;
  if (XrResult r = check_system(h, info->systemId, nullptr); r != XR_SUCCESS) return r;
  for (auto& [hh, o] : g_objects)
    if (o->kind == Kind::Session && o->parent == inst->handle) return XR_ERROR_LIMIT_REACHED;
  auto s = std::make_unique<Session>();
  const XrGraphicsBindingVulkanKHR* vk = nullptr;
  for (auto* n = static_cast<const XrBaseInStructure*>(info->next); n; n = n->next) {
    if (n->type == XR_TYPE_GRAPHICS_BINDING_VULKAN_KHR)
      vk = reinterpret_cast<const XrGraphicsBindingVulkanKHR*>(n);
  }
  bool has_vk_ext = inst->extensions.count(XR_KHR_VULKAN_ENABLE_EXTENSION_NAME) ||
                    inst->extensions.count(XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME);
  if (vk) {
    if (!has_vk_ext) return XR_ERROR_VALIDATION_FAILURE;
    if (!inst->gfx_requirements_called) return XR_ERROR_GRAPHICS_REQUIREMENTS_CALL_MISSING;
    if (vk->instance == VK_NULL_HANDLE || vk->physicalDevice == VK_NULL_HANDLE ||
        vk->device == VK_NULL_HANDLE)
      return XR_ERROR_GRAPHICS_DEVICE_INVALID;
    s->vk_instance = vk->instance;
    s->vk_physical = vk->physicalDevice;
    s->vk_device = vk->device;
    s->queue_family = vk->queueFamilyIndex;
    s->queue_index = vk->queueIndex;
  } else {
    if (!inst->extensions.count(XR_MND_HEADLESS_EXTENSION_NAME))
      return XR_ERROR_GRAPHICS_DEVICE_INVALID;
    s->headless = true;
  }
  Session* sp = s.get();
  uint64_t handle = register_object(std::move(s), inst->handle);
  if (!sp->headless && !init_session_vulkan_wrapper(sp)) {
    destroy_object(handle);
    return XR_ERROR_GRAPHICS_DEVICE_INVALID;
  }
  if (inst->window_mode && sp->headless) {
    log("DRAPE_MOCK_WINDOW: a headless session (XR_MND_headless) has no window");
  } else if (inst->window_mode) {
    std::string why;
    sp->window = open_window(sp, &why);
    if (!sp->window) {
      log("DRAPE_MOCK_WINDOW: cannot open the window: %s", why.c_str());
      destroy_object(handle);
      return XR_ERROR_RUNTIME_FAILURE;
    }
  }
  queue_state(sp, XR_SESSION_STATE_IDLE);
  queue_state(sp, XR_SESSION_STATE_READY);
  *out = to_handle<XrSession>(handle);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL DestroySession(XrSession h) {
  DRAPE_LOCK;
  Session* s = lookup<Session>(h);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  // Drop this session's pending events.
  Instance* inst = instance_of(s);
  std::deque<XrEventDataBuffer> keep;
  for (auto& e : inst->events) {
    if (e.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED &&
        reinterpret_cast<XrEventDataSessionStateChanged*>(&e)->session == h)
      continue;
    keep.push_back(e);
  }
  inst->events.swap(keep);
  destroy_object(s->handle);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL BeginSession(XrSession h, const XrSessionBeginInfo* info) {
  DRAPE_LOCK;
  XrResult err;
  Session* s = live_session(h, &err);
  if (!s) return err;
  if (!info || info->type != XR_TYPE_SESSION_BEGIN_INFO) return XR_ERROR_VALIDATION_FAILURE;
  if (s->running) return XR_ERROR_SESSION_RUNNING;
  if (info->primaryViewConfigurationType != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO)
    return XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
  if (s->state != XR_SESSION_STATE_READY) return XR_ERROR_SESSION_NOT_READY;
  s->running = true;
  s->frames_waited = 0;
  s->frame_waited = s->frame_begun = false;
  s->real_epoch = now_ns();
  s->epoch = s->real_epoch + 2 * kFramePeriodNs;
  return XR_SUCCESS;
}

}  // namespace

void begin_stopping(Session* s) {
  if (s->ending) return;
  s->ending = true;
  if (s->state == XR_SESSION_STATE_FOCUSED) queue_state(s, XR_SESSION_STATE_VISIBLE);
  if (s->state == XR_SESSION_STATE_VISIBLE) queue_state(s, XR_SESSION_STATE_SYNCHRONIZED);
  queue_state(s, XR_SESSION_STATE_STOPPING);
}

namespace {

XrResult XRAPI_CALL EndSession(XrSession h) {
  DRAPE_LOCK;
  XrResult err;
  Session* s = live_session(h, &err);
  if (!s) return err;
  if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
  if (s->state != XR_SESSION_STATE_STOPPING) return XR_ERROR_SESSION_NOT_STOPPING;
  s->running = false;
  s->frame_waited = s->frame_begun = false;
  queue_state(s, XR_SESSION_STATE_IDLE);
  queue_state(s, XR_SESSION_STATE_EXITING);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL RequestExitSession(XrSession h) {
  DRAPE_LOCK;
  XrResult err;
  Session* s = live_session(h, &err);
  if (!s) return err;
  if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
  s->exit_requested = true;
  begin_stopping(s);
  return XR_SUCCESS;
}

// ------------------------------------------------------------------ spaces
XrResult XRAPI_CALL EnumerateReferenceSpaces(XrSession h, uint32_t cap, uint32_t* count,
                                             XrReferenceSpaceType* out) {
  DRAPE_LOCK;
  XrResult err;
  if (!live_session(h, &err)) return err;
  return two_call<XrReferenceSpaceType>(
      cap, count, out,
      {XR_REFERENCE_SPACE_TYPE_VIEW, XR_REFERENCE_SPACE_TYPE_LOCAL, XR_REFERENCE_SPACE_TYPE_STAGE});
}

bool valid_pose(const XrPosef& p) {
  const XrQuaternionf& q = p.orientation;
  float n = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
  return std::abs(n - 1.f) < 1e-3f && std::isfinite(p.position.x) && std::isfinite(p.position.y) &&
         std::isfinite(p.position.z);
}

XrResult XRAPI_CALL CreateReferenceSpace(XrSession h, const XrReferenceSpaceCreateInfo* info,
                                         XrSpace* out) {
  DRAPE_LOCK;
  XrResult err;
  Session* s = live_session(h, &err);
  if (!s) return err;
  if (!info || !out || info->type != XR_TYPE_REFERENCE_SPACE_CREATE_INFO)
    return XR_ERROR_VALIDATION_FAILURE;
  if (info->referenceSpaceType != XR_REFERENCE_SPACE_TYPE_VIEW &&
      info->referenceSpaceType != XR_REFERENCE_SPACE_TYPE_LOCAL &&
      info->referenceSpaceType != XR_REFERENCE_SPACE_TYPE_STAGE)
    return XR_ERROR_REFERENCE_SPACE_UNSUPPORTED;
  if (!valid_pose(info->poseInReferenceSpace)) return XR_ERROR_POSE_INVALID;
  auto sp = std::make_unique<Space>();
  sp->space_kind = SpaceKind::Reference;
  sp->ref = info->referenceSpaceType;
  sp->offset = info->poseInReferenceSpace;
  *out = to_handle<XrSpace>(register_object(std::move(sp), s->handle));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL GetReferenceSpaceBoundsRect(XrSession h, XrReferenceSpaceType t,
                                                XrExtent2Df* bounds) {
  DRAPE_LOCK;
  XrResult err;
  if (!live_session(h, &err)) return err;
  if (!bounds) return XR_ERROR_VALIDATION_FAILURE;
  if (t == XR_REFERENCE_SPACE_TYPE_STAGE) {
    *bounds = {3.f, 3.f};
    return XR_SUCCESS;
  }
  if (t == XR_REFERENCE_SPACE_TYPE_VIEW || t == XR_REFERENCE_SPACE_TYPE_LOCAL) {
    *bounds = {0.f, 0.f};
    return XR_SPACE_BOUNDS_UNAVAILABLE;
  }
  return XR_ERROR_REFERENCE_SPACE_UNSUPPORTED;
}

XrResult XRAPI_CALL DestroySpace(XrSpace h) {
  DRAPE_LOCK;
  if (!lookup<Space>(h)) return XR_ERROR_HANDLE_INVALID;
  destroy_object(from_handle(h));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL LocateSpace(XrSpace space, XrSpace base, XrTime time, XrSpaceLocation* loc) {
  DRAPE_LOCK;
  Space* a = lookup<Space>(space);
  Space* b = lookup<Space>(base);
  if (!a || !b) return XR_ERROR_HANDLE_INVALID;
  if (!loc || loc->type != XR_TYPE_SPACE_LOCATION) return XR_ERROR_VALIDATION_FAILURE;
  if (time <= 0) return XR_ERROR_TIME_INVALID;
  Session* s = lookup<Session>(a->parent);
  if (!s || a->parent != b->parent) return XR_ERROR_VALIDATION_FAILURE;
  if (s->lost) return XR_ERROR_SESSION_LOST;
  XrSpaceVelocity* vel = nullptr;
  for (auto* n = static_cast<XrBaseOutStructure*>(loc->next); n; n = n->next)
    if (n->type == XR_TYPE_SPACE_VELOCITY) vel = reinterpret_cast<XrSpaceVelocity*>(n);
  XrPosef pa, pb;
  bool ta = true, tb = true;
  bool ok = space_pose_in_stage(s, a, time, &pa, &ta) && space_pose_in_stage(s, b, time, &pb, &tb);
  if (!ok) {
    loc->locationFlags = 0;
    loc->pose = pose_identity();
    if (vel) vel->velocityFlags = 0;
    return XR_SUCCESS;
  }
  loc->pose = pose_mul(pose_inverse(pb), pa);
  loc->locationFlags =
      XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT;
  if (ta && tb)
    loc->locationFlags |=
        XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT | XR_SPACE_LOCATION_POSITION_TRACKED_BIT;
  if (vel) {
    vel->velocityFlags = XR_SPACE_VELOCITY_LINEAR_VALID_BIT | XR_SPACE_VELOCITY_ANGULAR_VALID_BIT;
    vel->linearVelocity = {0, 0, 0};
    vel->angularVelocity = {0, 0, 0};
  }
  return XR_SUCCESS;
}

// ------------------------------------------------------------------ views
XrResult XRAPI_CALL LocateViews(XrSession h, const XrViewLocateInfo* info, XrViewState* state,
                                uint32_t cap, uint32_t* count, XrView* views) {
  DRAPE_LOCK;
  XrResult err;
  Session* s = live_session(h, &err);
  if (!s) return err;
  if (!info || info->type != XR_TYPE_VIEW_LOCATE_INFO || !state ||
      state->type != XR_TYPE_VIEW_STATE || !count)
    return XR_ERROR_VALIDATION_FAILURE;
  if (info->viewConfigurationType != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO)
    return XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
  if (info->displayTime <= 0) return XR_ERROR_TIME_INVALID;
  Space* base = lookup<Space>(info->space);
  if (!base || base->parent != s->handle) return XR_ERROR_HANDLE_INVALID;
  *count = 2;
  if (cap == 0) return XR_SUCCESS;
  if (!views) return XR_ERROR_VALIDATION_FAILURE;
  if (cap < 2) return XR_ERROR_SIZE_INSUFFICIENT;
  for (uint32_t i = 0; i < 2; ++i)
    if (views[i].type != XR_TYPE_VIEW) return XR_ERROR_VALIDATION_FAILURE;
  XrPosef pb;
  bool tb = true;
  if (!space_pose_in_stage(s, base, info->displayTime, &pb, &tb)) {
    state->viewStateFlags = 0;
    return XR_SUCCESS;
  }
  Instance* inst = instance_of(s);
  XrPosef head = inst->scenario.head_pose(frame_of_time(s, info->displayTime));
  XrPosef inv = pose_inverse(pb);
  for (uint32_t i = 0; i < 2; ++i) {
    XrPosef eye{{0, 0, 0, 1}, {i == 0 ? -kIpd / 2 : kIpd / 2, 0, 0}};
    views[i].pose = pose_mul(inv, pose_mul(head, eye));
    views[i].fov = {-kHalfFov, kHalfFov, kHalfFov, -kHalfFov};
  }
  state->viewStateFlags = XR_VIEW_STATE_ORIENTATION_VALID_BIT | XR_VIEW_STATE_POSITION_VALID_BIT |
                          XR_VIEW_STATE_ORIENTATION_TRACKED_BIT |
                          XR_VIEW_STATE_POSITION_TRACKED_BIT;
  return XR_SUCCESS;
}

// ------------------------------------------------------------------ frame loop
void fire_scenario_events(Session* s, Instance* inst, int64_t frame) {
  for (size_t i = 0; i < inst->scenario.events.size(); ++i) {
    const ScriptedEvent& e = inst->scenario.events[i];
    if (e.frame > frame || inst->fired_events.count(i)) continue;
    inst->fired_events.insert(i);
    if (e.type == "session_loss") {
      log("scripted session loss at frame %lld", static_cast<long long>(frame));
      queue_state(s, XR_SESSION_STATE_LOSS_PENDING);
      s->lost = true;
      s->running = false;
    } else if (e.type == "request_exit") {
      begin_stopping(s);
    }
  }
  for (const AudioCue& c : inst->scenario.audio)
    if (c.frame == frame)
      log("audio cue at frame %lld: %s", static_cast<long long>(frame), c.wav.c_str());
}

XrResult XRAPI_CALL WaitFrame(XrSession h, const XrFrameWaitInfo* info, XrFrameState* state) {
  int64_t sleep_until = 0;
  {
    DRAPE_LOCK;
    XrResult err;
    Session* s = live_session(h, &err);
    if (!s) return err;
    if ((info && info->type != XR_TYPE_FRAME_WAIT_INFO) || !state ||
        state->type != XR_TYPE_FRAME_STATE)
      return XR_ERROR_VALIDATION_FAILURE;
    if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
    Instance* inst = instance_of(s);
    int64_t i = s->frames_waited++;
    if (i == 0) {
      queue_state(s, XR_SESSION_STATE_SYNCHRONIZED);
      queue_state(s, XR_SESSION_STATE_VISIBLE);
      queue_state(s, XR_SESSION_STATE_FOCUSED);
    }
    fire_scenario_events(s, inst, i);
    if (s->lost) return XR_ERROR_SESSION_LOST;
    if (s->window) window_wait_frame(s, i);
    s->frame_waited = true;
    state->predictedDisplayTime = s->epoch + i * kFramePeriodNs;
    state->predictedDisplayPeriod = kFramePeriodNs;
    state->shouldRender =
        (s->state == XR_SESSION_STATE_VISIBLE || s->state == XR_SESSION_STATE_FOCUSED) ? XR_TRUE
                                                                                       : XR_FALSE;
    if (!inst->fast) sleep_until = s->real_epoch + i * kFramePeriodNs;
  }
  if (sleep_until > 0) {
    int64_t wait = sleep_until - now_ns();
    if (wait > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(wait));
  }
  return XR_SUCCESS;
}

XrResult XRAPI_CALL BeginFrame(XrSession h, const XrFrameBeginInfo* info) {
  DRAPE_LOCK;
  XrResult err;
  Session* s = live_session(h, &err);
  if (!s) return err;
  if (info && info->type != XR_TYPE_FRAME_BEGIN_INFO) return XR_ERROR_VALIDATION_FAILURE;
  if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
  if (!s->frame_waited) return XR_ERROR_CALL_ORDER_INVALID;
  s->frame_waited = false;
  s->frames_begun++;
  if (s->frame_begun) return XR_FRAME_DISCARDED;
  s->frame_begun = true;
  return XR_SUCCESS;
}

}  // namespace

const XrCompositionLayerDepthInfoKHR* depth_info(Instance* inst,
                                                 const XrCompositionLayerProjectionView& view) {
  if (!inst->extensions.count(XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME)) return nullptr;
  for (auto* n = static_cast<const XrBaseInStructure*>(view.next); n; n = n->next)
    if (n->type == XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR)
      return reinterpret_cast<const XrCompositionLayerDepthInfoKHR*>(n);
  return nullptr;
}

namespace {

XrResult check_sub_image(Session* s, const XrSwapchainSubImage& sub) {
  Swapchain* sc = lookup<Swapchain>(sub.swapchain);
  if (!sc || sc->parent != s->handle) return XR_ERROR_HANDLE_INVALID;
  if (sc->last_released < 0) return XR_ERROR_LAYER_INVALID;
  const XrRect2Di& r = sub.imageRect;
  if (r.offset.x < 0 || r.offset.y < 0 || r.extent.width <= 0 || r.extent.height <= 0 ||
      static_cast<uint32_t>(r.offset.x + r.extent.width) > sc->info.width ||
      static_cast<uint32_t>(r.offset.y + r.extent.height) > sc->info.height)
    return XR_ERROR_SWAPCHAIN_RECT_INVALID;
  if (sub.imageArrayIndex >= sc->info.arraySize) return XR_ERROR_VALIDATION_FAILURE;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL EndFrame(XrSession h, const XrFrameEndInfo* info) {
  DRAPE_LOCK;
  XrResult err;
  Session* s = live_session(h, &err);
  if (!s) return err;
  if (!info || info->type != XR_TYPE_FRAME_END_INFO) return XR_ERROR_VALIDATION_FAILURE;
  if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
  if (!s->frame_begun) return XR_ERROR_CALL_ORDER_INVALID;
  if (info->displayTime <= 0) return XR_ERROR_TIME_INVALID;
  if (info->environmentBlendMode != XR_ENVIRONMENT_BLEND_MODE_OPAQUE)
    return XR_ERROR_ENVIRONMENT_BLEND_MODE_UNSUPPORTED;
  if (info->layerCount > kMaxLayers) return XR_ERROR_LAYER_LIMIT_EXCEEDED;
  if (info->layerCount > 0 && !info->layers) return XR_ERROR_LAYER_INVALID;
  const XrCompositionLayerProjection* first_projection = nullptr;
  Instance* inst = instance_of(s);
  for (uint32_t i = 0; i < info->layerCount; ++i) {
    const XrCompositionLayerBaseHeader* l = info->layers[i];
    if (!l) return XR_ERROR_LAYER_INVALID;
    Space* sp = lookup<Space>(l->space);
    if (!sp || sp->parent != s->handle) return XR_ERROR_HANDLE_INVALID;
    if (l->type == XR_TYPE_COMPOSITION_LAYER_PROJECTION) {
      auto* p = reinterpret_cast<const XrCompositionLayerProjection*>(l);
      if (p->viewCount != 2 || !p->views) return XR_ERROR_VALIDATION_FAILURE;
      for (uint32_t v = 0; v < 2; ++v) {
        if (p->views[v].type != XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW)
          return XR_ERROR_VALIDATION_FAILURE;
        if (!valid_pose(p->views[v].pose)) return XR_ERROR_POSE_INVALID;
        if (XrResult r = check_sub_image(s, p->views[v].subImage); r != XR_SUCCESS) return r;
        if (const XrCompositionLayerDepthInfoKHR* d = depth_info(inst, p->views[v])) {
          if (XrResult r = check_sub_image(s, d->subImage); r != XR_SUCCESS) return r;
          if (!(d->minDepth >= 0.f && d->minDepth <= d->maxDepth && d->maxDepth <= 1.f &&
                d->nearZ > 0.f && d->farZ > 0.f && d->nearZ != d->farZ))
            return XR_ERROR_VALIDATION_FAILURE;
        }
      }
      if (!first_projection) first_projection = p;
    } else if (l->type == XR_TYPE_COMPOSITION_LAYER_QUAD) {
      auto* q = reinterpret_cast<const XrCompositionLayerQuad*>(l);
      if (!valid_pose(q->pose)) return XR_ERROR_POSE_INVALID;
      if (XrResult r = check_sub_image(s, q->subImage); r != XR_SUCCESS) return r;
    } else {
      return XR_ERROR_LAYER_INVALID;
    }
  }
  s->frame_begun = false;
  int64_t n = ++inst->frames_composed;
  if (info->layerCount > 0) ++inst->frames_with_layers;
  if (first_projection && !inst->write_dir.empty() && !s->headless &&
      (n - 1) % inst->write_every == 0) {
    char name[64];
    std::snprintf(name, sizeof(name), "/frame_%06lld.png", static_cast<long long>(n - 1));
    write_layer_png(s, first_projection, inst->write_dir + name);
    ++inst->frames_written;
  }
  if (s->window && first_projection) window_end_frame(s, first_projection);
  if (inst->end_after_frames > 0 && n >= inst->end_after_frames) begin_stopping(s);
  return XR_SUCCESS;
}

// ------------------------------------------------------------------ paths
XrResult XRAPI_CALL StringToPath(XrInstance h, const char* str, XrPath* out) {
  DRAPE_LOCK;
  Instance* inst = lookup<Instance>(h);
  if (!inst) return XR_ERROR_HANDLE_INVALID;
  if (!str || !out) return XR_ERROR_VALIDATION_FAILURE;
  if (!valid_path_string(str)) return XR_ERROR_PATH_FORMAT_INVALID;
  *out = intern_path(inst, str);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL PathToString(XrInstance h, XrPath p, uint32_t cap, uint32_t* count, char* buf) {
  DRAPE_LOCK;
  Instance* inst = lookup<Instance>(h);
  if (!inst) return XR_ERROR_HANDLE_INVALID;
  if (p == XR_NULL_PATH || p >= inst->paths.size()) return XR_ERROR_PATH_INVALID;
  return two_call_string(cap, count, buf, inst->paths[p]);
}

XrResult XRAPI_CALL GetInstanceProcAddr(XrInstance instance, const char* name,
                                        PFN_xrVoidFunction* function);

#define DRAPE_ENTRY(fn) \
  { "xr" #fn, reinterpret_cast<void*>(&fn) }
const std::unordered_map<std::string, void*>& core_table() {
  static const std::unordered_map<std::string, void*> t = {
      DRAPE_ENTRY(GetInstanceProcAddr),
      DRAPE_ENTRY(EnumerateApiLayerProperties),
      DRAPE_ENTRY(EnumerateInstanceExtensionProperties),
      DRAPE_ENTRY(CreateInstance),
      DRAPE_ENTRY(DestroyInstance),
      DRAPE_ENTRY(GetInstanceProperties),
      DRAPE_ENTRY(PollEvent),
      DRAPE_ENTRY(ResultToString),
      DRAPE_ENTRY(StructureTypeToString),
      DRAPE_ENTRY(GetSystem),
      DRAPE_ENTRY(GetSystemProperties),
      DRAPE_ENTRY(EnumerateEnvironmentBlendModes),
      DRAPE_ENTRY(EnumerateViewConfigurations),
      DRAPE_ENTRY(GetViewConfigurationProperties),
      DRAPE_ENTRY(EnumerateViewConfigurationViews),
      DRAPE_ENTRY(CreateSession),
      DRAPE_ENTRY(DestroySession),
      DRAPE_ENTRY(BeginSession),
      DRAPE_ENTRY(EndSession),
      DRAPE_ENTRY(RequestExitSession),
      DRAPE_ENTRY(EnumerateReferenceSpaces),
      DRAPE_ENTRY(CreateReferenceSpace),
      DRAPE_ENTRY(GetReferenceSpaceBoundsRect),
      DRAPE_ENTRY(DestroySpace),
      DRAPE_ENTRY(LocateSpace),
      DRAPE_ENTRY(LocateViews),
      DRAPE_ENTRY(WaitFrame),
      DRAPE_ENTRY(BeginFrame),
      DRAPE_ENTRY(EndFrame),
      DRAPE_ENTRY(StringToPath),
      DRAPE_ENTRY(PathToString),
  };
  return t;
}
#undef DRAPE_ENTRY

XrResult XRAPI_CALL GetInstanceProcAddr(XrInstance instance, const char* name,
                                        PFN_xrVoidFunction* function) {
  if (!name || !function) return XR_ERROR_VALIDATION_FAILURE;
  *function = nullptr;
  std::string n(name);
  DRAPE_LOCK;
  if (instance == XR_NULL_HANDLE) {
    if (n != "xrEnumerateInstanceExtensionProperties" && n != "xrEnumerateApiLayerProperties" &&
        n != "xrCreateInstance")
      return XR_ERROR_HANDLE_INVALID;
  } else if (!lookup<Instance>(instance)) {
    return XR_ERROR_HANDLE_INVALID;
  }
  void* fn = nullptr;
  auto& t = core_table();
  if (auto it = t.find(n); it != t.end()) fn = it->second;
  if (!fn) fn = input_proc(n);
  if (!fn) fn = vulkan_proc(n);
  if (!fn) return XR_ERROR_FUNCTION_UNSUPPORTED;
  // Extension functions are only available when their extension is enabled.
  if (instance != XR_NULL_HANDLE) {
    Instance* inst = lookup<Instance>(instance);
    auto need = [&](const char* ext) { return inst->extensions.count(ext) > 0; };
    bool ok = true;
    if (n.find("HandTracker") != std::string::npos || n == "xrLocateHandJointsEXT")
      ok = need(XR_EXT_HAND_TRACKING_EXTENSION_NAME);
    else if (n == "xrGetVulkanInstanceExtensionsKHR" || n == "xrGetVulkanDeviceExtensionsKHR" ||
             n == "xrGetVulkanGraphicsDeviceKHR")
      ok = need(XR_KHR_VULKAN_ENABLE_EXTENSION_NAME);
    else if (n == "xrCreateVulkanInstanceKHR" || n == "xrCreateVulkanDeviceKHR" ||
             n == "xrGetVulkanGraphicsDevice2KHR" || n == "xrGetVulkanGraphicsRequirements2KHR")
      ok = need(XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME);
    else if (n == "xrGetVulkanGraphicsRequirementsKHR")
      ok = need(XR_KHR_VULKAN_ENABLE_EXTENSION_NAME);
    if (!ok) return XR_ERROR_FUNCTION_UNSUPPORTED;
  }
  *function = reinterpret_cast<PFN_xrVoidFunction>(fn);
  return XR_SUCCESS;
}

}  // namespace

bool init_session_vulkan(Session* s);  // vulkan.cpp
namespace {
bool init_session_vulkan_wrapper(Session* s) {
  return init_session_vulkan(s);
}
}  // namespace

void* GetInstanceProcAddrExported() {
  return reinterpret_cast<void*>(&GetInstanceProcAddr);
}

bool space_pose_in_stage(Session* s, Space* sp, XrTime t, XrPosef* out, bool* tracked) {
  Instance* inst = instance_of(s);
  *tracked = true;
  if (sp->space_kind == SpaceKind::Reference) {
    XrPosef base = pose_identity();
    if (sp->ref == XR_REFERENCE_SPACE_TYPE_VIEW) {
      base = inst->scenario.head_pose(frame_of_time(s, t));
    } else if (sp->ref == XR_REFERENCE_SPACE_TYPE_LOCAL) {
      // LOCAL: origin at the head position of frame 0, STAGE orientation.
      base.position = inst->scenario.head_pose(0).position;
    }
    *out = pose_mul(base, sp->offset);
    return true;
  }
  Action* a = lookup<Action>(sp->action);
  if (!a) return false;
  XrPosef p;
  if (!action_pose(s, a, sp->subaction, t, &p, tracked)) return false;
  *out = pose_mul(p, sp->offset);
  return true;
}

}  // namespace drape::mock

// The one exported symbol.
extern "C" __attribute__((visibility("default"))) XrResult XRAPI_CALL
xrNegotiateLoaderRuntimeInterface(const drape::mock::XrNegotiateLoaderInfo* loaderInfo,
                                  drape::mock::XrNegotiateRuntimeRequest* runtimeRequest) {
  using namespace drape::mock;
  if (!loaderInfo || !runtimeRequest) return XR_ERROR_INITIALIZATION_FAILED;
  if (loaderInfo->structType != kLoaderInterfaceStructLoaderInfo ||
      loaderInfo->structVersion != kLoaderInfoStructVersion ||
      loaderInfo->structSize != sizeof(XrNegotiateLoaderInfo))
    return XR_ERROR_INITIALIZATION_FAILED;
  if (runtimeRequest->structType != kLoaderInterfaceStructRuntimeRequest ||
      runtimeRequest->structVersion != kRuntimeInfoStructVersion ||
      runtimeRequest->structSize != sizeof(XrNegotiateRuntimeRequest))
    return XR_ERROR_INITIALIZATION_FAILED;
  if (loaderInfo->minInterfaceVersion > kCurrentLoaderRuntimeVersion ||
      loaderInfo->maxInterfaceVersion < kCurrentLoaderRuntimeVersion)
    return XR_ERROR_INITIALIZATION_FAILED;
  if (XR_VERSION_MAJOR(loaderInfo->maxApiVersion) < 1 ||
      XR_VERSION_MAJOR(loaderInfo->minApiVersion) > 1)
    return XR_ERROR_INITIALIZATION_FAILED;
  runtimeRequest->runtimeInterfaceVersion = kCurrentLoaderRuntimeVersion;
  runtimeRequest->runtimeApiVersion = XR_CURRENT_API_VERSION;
  runtimeRequest->getInstanceProcAddr =
      reinterpret_cast<PFN_xrGetInstanceProcAddr>(drape::mock::GetInstanceProcAddrExported());
  return XR_SUCCESS;
}
