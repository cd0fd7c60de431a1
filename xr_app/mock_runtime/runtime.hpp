// Internal state of the mock OpenXR runtime: handle registry, instance, session, spaces,
// actions, swapchains. Every entry point takes the global lock (the runtime is small and the
// applications it serves call it from one or two threads).
#pragma once

#define XR_USE_GRAPHICS_API_VULKAN
#include <vulkan/vulkan.h>
// (Vulkan first: openxr_platform.h uses its types)
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "xr_app/mock_runtime/scenario.hpp"

namespace drape::mock {

enum class Kind { Instance, Session, Space, ActionSet, Action, Swapchain, HandTracker };

struct Object {
  explicit Object(Kind k) : kind(k) {}
  virtual ~Object() = default;
  Kind kind;
  uint64_t handle = 0;
  uint64_t parent = 0;
};

struct Instance;
struct Session;
struct Window;  // window.cpp: the desktop window of window mode

struct ActionSet : Object {
  static constexpr Kind kKind = Kind::ActionSet;
  ActionSet() : Object(kKind) {}
  std::string name, localized;
  uint32_t priority = 0;
  bool attached = false;
};

struct ActionStateSlot {
  float value[2] = {0, 0};
  bool active = false;
  bool changed = false;
  XrTime last_change = 0;
};

struct Action : Object {
  static constexpr Kind kKind = Kind::Action;
  Action() : Object(kKind) {}
  std::string name, localized;
  XrActionType type = XR_ACTION_TYPE_BOOLEAN_INPUT;
  std::vector<XrPath> subaction_paths;
  uint64_t action_set = 0;
  // interaction profile path -> bound component paths
  std::map<XrPath, std::vector<XrPath>> suggested;
  // state per top-level user path (XR_NULL_PATH = combined)
  std::map<XrPath, ActionStateSlot> state;
};

enum class SpaceKind { Reference, Action };

struct Space : Object {
  static constexpr Kind kKind = Kind::Space;
  Space() : Object(kKind) {}
  SpaceKind space_kind = SpaceKind::Reference;
  XrReferenceSpaceType ref = XR_REFERENCE_SPACE_TYPE_STAGE;
  uint64_t action = 0;
  XrPath subaction = XR_NULL_PATH;
  XrPosef offset{{0, 0, 0, 1}, {0, 0, 0}};
};

struct SwapchainImage {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
};

struct Swapchain : Object {
  static constexpr Kind kKind = Kind::Swapchain;
  Swapchain() : Object(kKind) {}
  ~Swapchain() override;
  XrSwapchainCreateInfo info{};
  VkDevice device = VK_NULL_HANDLE;
  std::vector<SwapchainImage> images;
  std::deque<uint32_t> acquired;  // acquired, in order
  bool waited = false;            // the oldest acquired image has been waited on
  uint32_t next = 0;
  int64_t last_released = -1;
  bool depth = false;
};

struct HandTracker : Object {
  static constexpr Kind kKind = Kind::HandTracker;
  HandTracker() : Object(kKind) {}
  XrHandEXT hand = XR_HAND_LEFT_EXT;
};

struct Session : Object {
  static constexpr Kind kKind = Kind::Session;
  Session() : Object(kKind) {}
  ~Session() override;
  XrSessionState state = XR_SESSION_STATE_UNKNOWN;
  bool running = false;
  bool headless = false;
  bool lost = false;
  bool exit_requested = false;
  bool ending = false;  // STOPPING queued
  // Vulkan binding
  VkInstance vk_instance = VK_NULL_HANDLE;
  VkPhysicalDevice vk_physical = VK_NULL_HANDLE;
  VkDevice vk_device = VK_NULL_HANDLE;
  uint32_t queue_family = 0, queue_index = 0;
  VkCommandPool cmd_pool = VK_NULL_HANDLE;
  // frame loop
  int64_t frames_waited = 0;  // index of the next frame xrWaitFrame hands out
  int64_t frames_begun = 0;
  bool frame_waited = false;  // a waited frame not yet begun
  bool frame_begun = false;
  XrTime epoch = 0;        // display time of frame 0
  int64_t real_epoch = 0;  // monotonic ns when frame 0 was handed out (paced mode)
  // actions
  std::vector<uint64_t> attached_sets;
  XrPath profile[2] = {XR_NULL_PATH, XR_NULL_PATH};
  bool profile_event_sent = false;
  bool synced_once = false;
  std::shared_ptr<Window> window;  // window mode only (DRAPE_MOCK_WINDOW)
};

struct Instance : Object {
  static constexpr Kind kKind = Kind::Instance;
  Instance() : Object(kKind) {}
  std::string app_name;
  std::set<std::string> extensions;
  bool system_got = false;
  bool gfx_requirements_called = false;
  VkInstance vk_instance = VK_NULL_HANDLE;        // last created/queried through the extension
  VkPhysicalDevice vk_physical = VK_NULL_HANDLE;  // the device the runtime chose
  std::deque<XrEventDataBuffer> events;
  std::vector<std::string> paths{""};  // XrPath i -> string (0 = XR_NULL_PATH)
  std::unordered_map<std::string, XrPath> path_ids;
  Scenario scenario;
  int64_t end_after_frames = -1;
  bool fast = false;
  std::string write_dir;
  int write_every = 1;
  int64_t frames_composed = 0;
  int64_t frames_with_layers = 0;
  int64_t frames_written = 0;
  bool suggested_any = false;
  std::set<size_t> fired_events;  // scenario events already fired (once per instance)
  bool window_mode = false;       // DRAPE_MOCK_WINDOW=1: live input from a desktop window
  std::map<XrPath, std::set<uint64_t>> suggested_profiles;  // profile -> actions
};

// ---- registry (all under g_lock) ----
extern std::recursive_mutex g_lock;
uint64_t register_object(std::unique_ptr<Object> obj, uint64_t parent);
Object* find_object(uint64_t handle);
template <class T>
T* lookup(uint64_t handle) {
  Object* o = find_object(handle);
  if (!o || o->kind != T::kKind) return nullptr;
  return static_cast<T*>(o);
}
template <class T, class H>
T* lookup(H h) {
  return lookup<T>(reinterpret_cast<uint64_t>(h));
}
template <class H>
H to_handle(uint64_t v) {
  return reinterpret_cast<H>(v);
}
template <class H>
uint64_t from_handle(H h) {
  return reinterpret_cast<uint64_t>(h);
}
void destroy_object(uint64_t handle);  // and all its children
void for_each_child(uint64_t parent, Kind kind, const std::function<void(Object*)>& fn);
void for_each_of_kind(Kind kind, const std::function<void(Object*)>& fn);
Instance* instance_of(const Object* o);

// ---- helpers shared by the files ----
XrPath intern_path(Instance* inst, const std::string& s);
std::string path_string(Instance* inst, XrPath p);
void push_event(Instance* inst, const void* ev, size_t size);
void queue_state(Session* s, XrSessionState state);
XrTime now_ns();
double frame_of_time(const Session* s, XrTime t);
constexpr int64_t kFramePeriodNs = 11111111;  // 90 Hz
constexpr float kIpd = 0.063f;
constexpr float kHalfFov = 0.785398f;  // 45 degrees, all four sides of both views
void log(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

template <class T>
XrResult two_call(uint32_t capacity, uint32_t* count, T* out, const std::vector<T>& items) {
  if (!count) return XR_ERROR_VALIDATION_FAILURE;
  *count = static_cast<uint32_t>(items.size());
  if (capacity == 0) return XR_SUCCESS;
  if (!out) return XR_ERROR_VALIDATION_FAILURE;
  if (capacity < items.size()) return XR_ERROR_SIZE_INSUFFICIENT;
  for (size_t i = 0; i < items.size(); ++i) out[i] = items[i];
  return XR_SUCCESS;
}
XrResult two_call_string(uint32_t capacity, uint32_t* count, char* out, const std::string& s);

// Pose of a space in STAGE at a time; false when it is not locatable.
bool space_pose_in_stage(Session* s, Space* sp, XrTime t, XrPosef* out, bool* tracked);

// Entry points implemented in input.cpp and vulkan.cpp, resolved by name in runtime.cpp.
void* input_proc(const std::string& name);
void* vulkan_proc(const std::string& name);
// Frame readback (vulkan.cpp): writes the left eye of a projection layer to PNG.
void write_layer_png(Session* s, const XrCompositionLayerProjection* layer,
                     const std::string& path);
// Reads back a sub-image of a colour swapchain's last released image as RGBA (alpha 255).
bool read_color(Session* s, const XrSwapchainSubImage& sub, std::vector<unsigned char>* rgba);
// Reads one texel (x, y inside the sub-image's rect) of a depth swapchain's last released image.
bool read_depth_texel(Session* s, const XrSwapchainSubImage& sub, int x, int y, float* depth);
void update_actions_on_sync(Session* s, Instance* inst);  // input.cpp
// The interaction profiles the app suggested bindings for (attached sets), in the runtime's
// order of preference (input.cpp).
std::vector<XrPath> suggested_profiles(Session* s);
// The XrCompositionLayerDepthInfoKHR chained to a projection view (when the app enabled
// XR_KHR_composition_layer_depth), else null.
const XrCompositionLayerDepthInfoKHR* depth_info(Instance* inst,
                                                 const XrCompositionLayerProjectionView& view);
// Queues STOPPING (after VISIBLE/SYNCHRONIZED as needed), once.
void begin_stopping(Session* s);
bool action_pose(Session* s, Action* a, XrPath subaction, XrTime t, XrPosef* out, bool* tracked);

}  // namespace drape::mock
