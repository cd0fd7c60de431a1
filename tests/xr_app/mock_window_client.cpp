// A small OpenXR client for mock_window_test.sh (window mode of the mock runtime): it submits
// a projection layer with XR_KHR_composition_layer_depth (a plane 0.8 m away over the left half
// of each eye, nothing on the right half, and the right hand's joints as small squares) and
// prints, per frame, what it reads back as an app
// would: the right hand's thumb-to-index gap and its thumb's gaps to the other fingertips and
// palm normal (XR_EXT_hand_tracking), the select action (khr/simple_controller), the right
// thumbstick and its click (oculus/touch_controller) and interaction profile changes. It runs until
// the session exits.
#define XR_USE_GRAPHICS_API_VULKAN
#include <vulkan/vulkan.h>
// (Vulkan first: openxr_platform.h uses its types)
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "xr_vulkan_handover.hpp"

namespace {

#define CHECK(x)                                                                 \
  do {                                                                           \
    if (!(x)) {                                                                  \
      std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #x); \
      std::exit(1);                                                              \
    }                                                                            \
  } while (0)
#define XR(x) CHECK((x) == XR_SUCCESS)

template <class F>
F proc(XrInstance inst, const char* name) {
  PFN_xrVoidFunction fn = nullptr;
  XR(xrGetInstanceProcAddr(inst, name, &fn));
  return reinterpret_cast<F>(fn);
}

constexpr int kSize = 512;
constexpr float kNear = 0.1f, kFar = 100.f, kPlane = 0.8f;

struct Gpu {
  VkDevice dev;
  VkQueue queue;
  VkCommandPool pool;
  VkPhysicalDevice phys;
};

// A host-visible buffer filled with `bytes`.
VkBuffer make_buffer(const Gpu& g, const std::vector<unsigned char>& bytes, VkDeviceMemory* mem) {
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = bytes.size();
  bi.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  VkBuffer b;
  CHECK(vkCreateBuffer(g.dev, &bi, nullptr, &b) == VK_SUCCESS);
  VkMemoryRequirements mr;
  vkGetBufferMemoryRequirements(g.dev, b, &mr);
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(g.phys, &mp);
  uint32_t type = 0;
  const VkMemoryPropertyFlags want =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  while (type < mp.memoryTypeCount && !((mr.memoryTypeBits & (1u << type)) &&
                                        (mp.memoryTypes[type].propertyFlags & want) == want))
    ++type;
  CHECK(type < mp.memoryTypeCount);
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = mr.size;
  ai.memoryTypeIndex = type;
  CHECK(vkAllocateMemory(g.dev, &ai, nullptr, mem) == VK_SUCCESS);
  CHECK(vkBindBufferMemory(g.dev, b, *mem, 0) == VK_SUCCESS);
  void* p;
  CHECK(vkMapMemory(g.dev, *mem, 0, bytes.size(), 0, &p) == VK_SUCCESS);
  std::memcpy(p, bytes.data(), bytes.size());
  vkUnmapMemory(g.dev, *mem);
  return b;
}

void fill(const Gpu& g, VkDeviceMemory mem, const std::vector<unsigned char>& bytes) {
  void* p;
  CHECK(vkMapMemory(g.dev, mem, 0, bytes.size(), 0, &p) == VK_SUCCESS);
  std::memcpy(p, bytes.data(), bytes.size());
  vkUnmapMemory(g.dev, mem);
}

float depth_value(float z) {  // of a view distance z, for kNear at 0 and kFar at 1
  return (1 / z - 1 / kNear) / (1 / kFar - 1 / kNear);
}

// Draws a 7x7 white square with depth test at the projection of p (stage) through `view`.
void draw_joint(const XrView& view, const XrVector3f& p, std::vector<unsigned char>* rgba,
                std::vector<unsigned char>* zbytes) {
  const XrQuaternionf& q = view.pose.orientation;
  XrVector3f d{p.x - view.pose.position.x, p.y - view.pose.position.y, p.z - view.pose.position.z};
  // d rotated by the conjugate of q: d + 2w(u x d) + 2u x (u x d), u = -q.xyz.
  XrVector3f u{-q.x, -q.y, -q.z};
  auto cross = [](XrVector3f a, XrVector3f b) {
    return XrVector3f{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  };
  XrVector3f c = cross(u, d), cc = cross(u, c);
  XrVector3f l{d.x + 2 * q.w * c.x + 2 * cc.x, d.y + 2 * q.w * c.y + 2 * cc.y,
               d.z + 2 * q.w * c.z + 2 * cc.z};
  if (l.z > -kNear) return;
  const float z = -l.z, tx = l.x / z, ty = l.y / z;
  const float tl = std::tan(view.fov.angleLeft), tr = std::tan(view.fov.angleRight);
  const float tu = std::tan(view.fov.angleUp), td = std::tan(view.fov.angleDown);
  const int px = static_cast<int>((tx - tl) / (tr - tl) * kSize);
  const int py = static_cast<int>((tu - ty) / (tu - td) * kSize);
  const float dv = depth_value(z);
  for (int y = py - 3; y <= py + 3; ++y)
    for (int x = px - 3; x <= px + 3; ++x) {
      if (x < 0 || y < 0 || x >= kSize || y >= kSize) continue;
      float* old = reinterpret_cast<float*>(&(*zbytes)[(y * kSize + x) * 4]);
      if (dv >= *old) continue;
      *old = dv;
      std::memset(&(*rgba)[(y * kSize + x) * 4], 255, 4);
    }
}

// Copies `buf` into `img` (in its attachment layout before and after).
void upload(const Gpu& g, VkBuffer buf, VkImage img, bool depth) {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = g.pool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb;
  CHECK(vkAllocateCommandBuffers(g.dev, &ai, &cb) == VK_SUCCESS);
  VkCommandBufferBeginInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkBeginCommandBuffer(cb, &cbi);
  const VkImageAspectFlags aspect = depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
  const VkImageLayout att = depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL
                                  : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = img;
  b.subresourceRange = {aspect, 0, 1, 0, 1};
  b.oldLayout = att;
  b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                       nullptr, 0, nullptr, 1, &b);
  VkBufferImageCopy region{};
  region.imageSubresource = {aspect, 0, 0, 1};
  region.imageExtent = {kSize, kSize, 1};
  vkCmdCopyBufferToImage(cb, buf, img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  b.newLayout = att;
  b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  b.dstAccessMask = 0;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0,
                       nullptr, 0, nullptr, 1, &b);
  vkEndCommandBuffer(cb);
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  CHECK(vkQueueSubmit(g.queue, 1, &si, VK_NULL_HANDLE) == VK_SUCCESS);
  vkQueueWaitIdle(g.queue);
  vkFreeCommandBuffers(g.dev, g.pool, 1, &cb);
}

struct Chain {
  XrSwapchain sc;
  std::vector<XrSwapchainImageVulkan2KHR> images;
};

Chain make_chain(XrSession s, int64_t format, XrSwapchainUsageFlags usage) {
  XrSwapchainCreateInfo ci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
  ci.usageFlags = usage | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT;
  ci.format = format;
  ci.sampleCount = 1;
  ci.width = ci.height = kSize;
  ci.faceCount = ci.arraySize = ci.mipCount = 1;
  Chain c;
  XR(xrCreateSwapchain(s, &ci, &c.sc));
  uint32_t n = 0;
  XR(xrEnumerateSwapchainImages(c.sc, 0, &n, nullptr));
  c.images.assign(n, {XR_TYPE_SWAPCHAIN_IMAGE_VULKAN2_KHR});
  XR(xrEnumerateSwapchainImages(c.sc, n, &n,
                                reinterpret_cast<XrSwapchainImageBaseHeader*>(c.images.data())));
  return c;
}

}  // namespace

// The right Touch controller's thumbstick and its click (the window's arrows and Enter).
void stick_actions(XrInstance inst, XrActionSet set, XrAction* stick, XrAction* click) {
  XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
  aci.actionType = XR_ACTION_TYPE_VECTOR2F_INPUT;
  std::strcpy(aci.actionName, "stick");
  std::strcpy(aci.localizedActionName, "Stick");
  XR(xrCreateAction(set, &aci, stick));
  aci.actionType = XR_ACTION_TYPE_BOOLEAN_INPUT;
  std::strcpy(aci.actionName, "stick_click");
  std::strcpy(aci.localizedActionName, "Stick click");
  XR(xrCreateAction(set, &aci, click));
  XrPath touch, stick_path, click_path;
  XR(xrStringToPath(inst, "/interaction_profiles/oculus/touch_controller", &touch));
  XR(xrStringToPath(inst, "/user/hand/right/input/thumbstick", &stick_path));
  XR(xrStringToPath(inst, "/user/hand/right/input/thumbstick/click", &click_path));
  XrActionSuggestedBinding tb[2] = {{*stick, stick_path}, {*click, click_path}};
  XrInteractionProfileSuggestedBinding isb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
  isb.interactionProfile = touch;
  isb.countSuggestedBindings = 2;
  isb.suggestedBindings = tb;
  XR(xrSuggestInteractionProfileBindings(inst, &isb));
}

// One line of what the client reads: the right hand's thumb-index gap and pinch point, its
// thumb's gaps to the middle, ring and little tips, the index-little spread, the palm's normal
// (its joint's -y) and position; the select action; the thumbstick and its click.
void print_hand(long frame, bool active, const XrHandJointLocationEXT* joints,
                const XrActionStateBoolean& sel, const XrActionStateVector2f& st,
                const XrActionStateBoolean& stc) {
  if (!active) {
    std::printf("frame=%ld hand not tracked select=%d\n", frame, sel.currentState ? 1 : 0);
    return;
  }
  auto at = [&](int j) { return joints[j].pose.position; };
  auto dist = [&](const XrVector3f& p, const XrVector3f& q) {
    return std::sqrt((p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y) +
                     (p.z - q.z) * (p.z - q.z));
  };
  const XrVector3f t = at(XR_HAND_JOINT_THUMB_TIP_EXT), i = at(XR_HAND_JOINT_INDEX_TIP_EXT);
  const XrVector3f palm = at(XR_HAND_JOINT_PALM_EXT);
  const XrQuaternionf& o = joints[XR_HAND_JOINT_PALM_EXT].pose.orientation;
  const float nx = -2 * (o.x * o.y - o.w * o.z), ny = -(1 - 2 * (o.x * o.x + o.z * o.z)),
              nz = -2 * (o.y * o.z + o.w * o.x);
  std::printf(
      "frame=%ld pinch_gap=%.3f pinch_point=%.3f,%.3f,%.3f select=%d active=%d "
      "gaps=%.3f,%.3f,%.3f spread=%.3f palm_normal=%.2f,%.2f,%.2f palm=%.3f,%.3f,%.3f "
      "stick=%.2f,%.2f,%d\n",
      frame, dist(t, i), (t.x + i.x) / 2, (t.y + i.y) / 2, (t.z + i.z) / 2,
      sel.currentState ? 1 : 0, sel.isActive ? 1 : 0, dist(t, at(XR_HAND_JOINT_MIDDLE_TIP_EXT)),
      dist(t, at(XR_HAND_JOINT_RING_TIP_EXT)), dist(t, at(XR_HAND_JOINT_LITTLE_TIP_EXT)),
      dist(i, at(XR_HAND_JOINT_LITTLE_TIP_EXT)), nx, ny, nz, palm.x, palm.y, palm.z,
      st.currentState.x, st.currentState.y, stc.currentState ? 1 : 0);
}

int main() {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const char* exts[] = {XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME,
                        XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME,
                        XR_EXT_HAND_TRACKING_EXTENSION_NAME};
  XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
  std::strcpy(ci.applicationInfo.applicationName, "drape_mock_window_client");
  ci.applicationInfo.apiVersion = XR_CURRENT_API_VERSION;
  ci.enabledExtensionCount = 3;
  ci.enabledExtensionNames = exts;
  XrInstance inst;
  XR(xrCreateInstance(&ci, &inst));
  XrSystemGetInfo gi{XR_TYPE_SYSTEM_GET_INFO};
  gi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  XrSystemId sys;
  XR(xrGetSystem(inst, &gi, &sys));

  // Vulkan through XR_KHR_vulkan_enable2.
  XrVulkanHandover h;
  if (std::string e = create_vulkan_through_xr(inst, sys, h); !e.empty()) {
    std::fprintf(stderr, "Vulkan through the runtime: %s failed\n", e.c_str());
    return 1;
  }
  VkInstance vk = h.instance;
  const uint32_t family = h.family;
  Gpu g{};
  g.phys = h.phys;
  g.dev = h.device;
  vkGetDeviceQueue(g.dev, family, 0, &g.queue);
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.queueFamilyIndex = family;
  CHECK(vkCreateCommandPool(g.dev, &pci, nullptr, &g.pool) == VK_SUCCESS);

  XrGraphicsBindingVulkan2KHR bind{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
  bind.instance = vk;
  bind.physicalDevice = g.phys;
  bind.device = g.dev;
  bind.queueFamilyIndex = family;
  XrSessionCreateInfo sci{XR_TYPE_SESSION_CREATE_INFO, &bind};
  sci.systemId = sys;
  XrSession session;
  XR(xrCreateSession(inst, &sci, &session));

  // Actions: select on the right hand of khr/simple_controller.
  XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::strcpy(asci.actionSetName, "main");
  std::strcpy(asci.localizedActionSetName, "Main");
  XrActionSet set;
  XR(xrCreateActionSet(inst, &asci, &set));
  XrPath right_hand, select_path, simple;
  XR(xrStringToPath(inst, "/user/hand/right", &right_hand));
  XR(xrStringToPath(inst, "/user/hand/right/input/select/click", &select_path));
  XR(xrStringToPath(inst, "/interaction_profiles/khr/simple_controller", &simple));
  XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
  aci.actionType = XR_ACTION_TYPE_BOOLEAN_INPUT;
  std::strcpy(aci.actionName, "select");
  std::strcpy(aci.localizedActionName, "Select");
  XrAction select;
  XR(xrCreateAction(set, &aci, &select));
  XrActionSuggestedBinding sb{select, select_path};
  XrInteractionProfileSuggestedBinding isb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
  isb.interactionProfile = simple;
  isb.countSuggestedBindings = 1;
  isb.suggestedBindings = &sb;
  XR(xrSuggestInteractionProfileBindings(inst, &isb));
  XrAction stick, stick_click;
  stick_actions(inst, set, &stick, &stick_click);
  XrSessionActionSetsAttachInfo at{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  at.countActionSets = 1;
  at.actionSets = &set;
  XR(xrAttachSessionActionSets(session, &at));

  auto create_tracker = proc<PFN_xrCreateHandTrackerEXT>(inst, "xrCreateHandTrackerEXT");
  auto locate_joints = proc<PFN_xrLocateHandJointsEXT>(inst, "xrLocateHandJointsEXT");
  XrHandTrackerCreateInfoEXT hci{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
  hci.hand = XR_HAND_RIGHT_EXT;
  hci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
  XrHandTrackerEXT tracker;
  XR(create_tracker(session, &hci, &tracker));

  XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_STAGE;
  rs.poseInReferenceSpace.orientation.w = 1;
  XrSpace stage;
  XR(xrCreateReferenceSpace(session, &rs, &stage));

  Chain color =
      make_chain(session, VK_FORMAT_R8G8B8A8_SRGB, XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT);
  Chain depth =
      make_chain(session, VK_FORMAT_D32_SFLOAT, XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  // Left half: an orange plane with a grid at kPlane; right half: dark blue, nothing (far).
  std::vector<unsigned char> rgba(kSize * kSize * 4), zbytes(kSize * kSize * 4);
  const float d_plane = depth_value(kPlane);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      unsigned char* p = &rgba[(y * kSize + x) * 4];
      bool plane = x < kSize / 2, grid = (x % 32 == 0) || (y % 32 == 0);
      p[0] = plane ? (grid ? 90 : 230) : 20;
      p[1] = plane ? (grid ? 40 : 140) : 30;
      p[2] = plane ? (grid ? 10 : 40) : 70;
      p[3] = 255;
      float d = plane ? d_plane : 1.f;
      std::memcpy(&zbytes[(y * kSize + x) * 4], &d, 4);
    }
  VkDeviceMemory cmem, zmem;
  VkBuffer cbuf = make_buffer(g, rgba, &cmem), zbuf = make_buffer(g, zbytes, &zmem);

  XrCompositionLayerDepthInfoKHR dinfo[2];
  XrCompositionLayerProjectionView views[2];
  for (int i = 0; i < 2; ++i) {
    dinfo[i] = {XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR};
    dinfo[i].subImage.swapchain = depth.sc;
    dinfo[i].subImage.imageRect = {{0, 0}, {kSize, kSize}};
    dinfo[i].minDepth = 0;
    dinfo[i].maxDepth = 1;
    dinfo[i].nearZ = kNear;
    dinfo[i].farZ = kFar;
    views[i] = {XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW, &dinfo[i]};
    views[i].subImage.swapchain = color.sc;
    views[i].subImage.imageRect = {{0, 0}, {kSize, kSize}};
  }
  XrCompositionLayerProjection layer{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
  layer.space = stage;
  layer.viewCount = 2;
  layer.views = views;
  const XrCompositionLayerBaseHeader* layers[] = {
      reinterpret_cast<XrCompositionLayerBaseHeader*>(&layer)};

  bool running = false, exiting = false;
  for (long frame = 0; !exiting; ++frame) {
    XrEventDataBuffer ev{XR_TYPE_EVENT_DATA_BUFFER};
    while (xrPollEvent(inst, &ev) == XR_SUCCESS) {
      if (ev.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED) {
        auto* sc = reinterpret_cast<XrEventDataSessionStateChanged*>(&ev);
        const char* names[] = {"UNKNOWN", "IDLE",     "READY",        "SYNCHRONIZED", "VISIBLE",
                               "FOCUSED", "STOPPING", "LOSS_PENDING", "EXITING"};
        std::printf("state %s\n", sc->state <= 8 ? names[sc->state] : "?");
        if (sc->state == XR_SESSION_STATE_READY) {
          XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
          bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
          XR(xrBeginSession(session, &bi));
          running = true;
        } else if (sc->state == XR_SESSION_STATE_STOPPING) {
          XR(xrEndSession(session));
          running = false;
        } else if (sc->state == XR_SESSION_STATE_EXITING) {
          exiting = true;
        }
      } else if (ev.type == XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED) {
        XrInteractionProfileState ps{XR_TYPE_INTERACTION_PROFILE_STATE};
        XR(xrGetCurrentInteractionProfile(session, right_hand, &ps));
        char buf[XR_MAX_PATH_LENGTH] = "none";
        uint32_t n = 0;
        if (ps.interactionProfile != XR_NULL_PATH)
          XR(xrPathToString(inst, ps.interactionProfile, sizeof(buf), &n, buf));
        std::printf("profile changed: %s\n", buf);
      }
      ev = {XR_TYPE_EVENT_DATA_BUFFER};
    }
    if (!running) continue;
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    XR(xrWaitFrame(session, nullptr, &fs));
    XR(xrBeginFrame(session, nullptr));
    XrActiveActionSet active{set, XR_NULL_PATH};
    XrActionsSyncInfo si{XR_TYPE_ACTIONS_SYNC_INFO};
    si.countActiveActionSets = 1;
    si.activeActionSets = &active;
    CHECK(XR_SUCCEEDED(xrSyncActions(session, &si)));
    XrActionStateGetInfo sgi{XR_TYPE_ACTION_STATE_GET_INFO};
    sgi.action = select;
    XrActionStateBoolean sel{XR_TYPE_ACTION_STATE_BOOLEAN};
    XR(xrGetActionStateBoolean(session, &sgi, &sel));
    sgi.action = stick;
    XrActionStateVector2f st{XR_TYPE_ACTION_STATE_VECTOR2F};
    XR(xrGetActionStateVector2f(session, &sgi, &st));
    sgi.action = stick_click;
    XrActionStateBoolean stc{XR_TYPE_ACTION_STATE_BOOLEAN};
    XR(xrGetActionStateBoolean(session, &sgi, &stc));
    XrHandJointLocationEXT joints[XR_HAND_JOINT_COUNT_EXT];
    XrHandJointLocationsEXT locs{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
    locs.jointCount = XR_HAND_JOINT_COUNT_EXT;
    locs.jointLocations = joints;
    XrHandJointsLocateInfoEXT li{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
    li.baseSpace = stage;
    li.time = fs.predictedDisplayTime;
    XR(locate_joints(tracker, &li, &locs));
    print_hand(frame, locs.isActive, joints, sel, st, stc);
    XrViewLocateInfo vli{XR_TYPE_VIEW_LOCATE_INFO};
    vli.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
    vli.displayTime = fs.predictedDisplayTime;
    vli.space = stage;
    XrViewState vs{XR_TYPE_VIEW_STATE};
    XrView xv[2] = {{XR_TYPE_VIEW}, {XR_TYPE_VIEW}};
    uint32_t nv = 0;
    XR(xrLocateViews(session, &vli, &vs, 2, &nv, xv));
    // The app draws the right hand's joints (in the left eye's projection, with depth), as an
    // app draws its hands: the runtime must not take them for the surface under the cursor.
    std::vector<unsigned char> rgba_frame = rgba, z_frame = zbytes;
    if (locs.isActive)
      for (const XrHandJointLocationEXT& j : joints)
        draw_joint(xv[0], j.pose.position, &rgba_frame, &z_frame);
    fill(g, cmem, rgba_frame);
    fill(g, zmem, z_frame);
    XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
    ei.displayTime = fs.predictedDisplayTime;
    ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    if (fs.shouldRender) {
      for (Chain* c : {&color, &depth}) {
        uint32_t idx;
        XR(xrAcquireSwapchainImage(c->sc, nullptr, &idx));
        XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
        wi.timeout = XR_INFINITE_DURATION;
        XR(xrWaitSwapchainImage(c->sc, &wi));
        upload(g, c == &color ? cbuf : zbuf, c->images[idx].image, c == &depth);
        XR(xrReleaseSwapchainImage(c->sc, nullptr));
      }
      for (int i = 0; i < 2; ++i) {
        views[i].pose = xv[i].pose;
        views[i].fov = xv[i].fov;
      }
      ei.layerCount = 1;
      ei.layers = layers;
    }
    XR(xrEndFrame(session, &ei));
  }
  XR(xrDestroySession(session));
  XR(xrDestroyInstance(inst));
  vkDestroyBuffer(g.dev, cbuf, nullptr);
  vkDestroyBuffer(g.dev, zbuf, nullptr);
  vkFreeMemory(g.dev, cmem, nullptr);
  vkFreeMemory(g.dev, zmem, nullptr);
  vkDestroyCommandPool(g.dev, g.pool, nullptr);
  vkDestroyDevice(g.dev, nullptr);
  vkDestroyInstance(vk, nullptr);
  return 0;
}
