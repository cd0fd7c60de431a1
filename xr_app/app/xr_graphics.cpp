// The OpenXR app's graphics: Vulkan handover and swapchains (see xr_graphics.hpp).
#include "xr_app/app/xr_graphics.hpp"

#include <algorithm>

namespace drape::app {

bool XrGraphics::create_vk_instance(XrInstance instance, XrSystemId system) {
  auto reqs = xr_function<PFN_xrGetVulkanGraphicsRequirements2KHR>(
      instance, "xrGetVulkanGraphicsRequirements2KHR");
  auto mk_inst = xr_function<PFN_xrCreateVulkanInstanceKHR>(instance, "xrCreateVulkanInstanceKHR");
  if (!reqs || !mk_inst) {
    rep_.r.error = "XR_KHR_vulkan_enable2 functions missing";
    return false;
  }
  XrGraphicsRequirementsVulkan2KHR rq{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR};
  if (!rep_.ok(reqs(instance, system, &rq), "xrGetVulkanGraphicsRequirements2KHR")) return false;
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "drape";
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo vci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  vci.pApplicationInfo = &app;
  XrVulkanInstanceCreateInfoKHR xi{XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR};
  xi.systemId = system;
  xi.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xi.vulkanCreateInfo = &vci;
  VkResult vr = VK_SUCCESS;
  if (!rep_.ok(mk_inst(instance, &xi, &vk_.instance, &vr), "xrCreateVulkanInstanceKHR"))
    return false;
  if (vr != VK_SUCCESS) {
    rep_.r.error = "vkCreateInstance failed: " + std::to_string(vr);
    return false;
  }
  return true;
}

bool XrGraphics::create_device(XrInstance instance, XrSystemId system) {
  auto get_dev =
      xr_function<PFN_xrGetVulkanGraphicsDevice2KHR>(instance, "xrGetVulkanGraphicsDevice2KHR");
  auto mk_dev = xr_function<PFN_xrCreateVulkanDeviceKHR>(instance, "xrCreateVulkanDeviceKHR");
  if (!get_dev || !mk_dev) {
    rep_.r.error = "XR_KHR_vulkan_enable2 functions missing";
    return false;
  }
  if (!create_vk_instance(instance, system)) return false;
  XrVulkanGraphicsDeviceGetInfoKHR gi{XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR};
  gi.systemId = system;
  gi.vulkanInstance = vk_.instance;
  if (!rep_.ok(get_dev(instance, &gi, &vk_.physical), "xrGetVulkanGraphicsDevice2KHR"))
    return false;
  uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(vk_.physical, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> qf(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(vk_.physical, &nq, qf.data());
  vk_.queue_family = 0;
  while (vk_.queue_family < nq && !(qf[vk_.queue_family].queueFlags & VK_QUEUE_GRAPHICS_BIT))
    ++vk_.queue_family;
  if (vk_.queue_family == nq) {
    rep_.r.error = "no graphics queue";
    return false;
  }
  float prio = 1;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = vk_.queue_family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &prio;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  XrVulkanDeviceCreateInfoKHR xd{XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR};
  xd.systemId = system;
  xd.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xd.vulkanPhysicalDevice = vk_.physical;
  xd.vulkanCreateInfo = &dci;
  VkResult vr = VK_SUCCESS;
  if (!rep_.ok(mk_dev(instance, &xd, &vk_.device, &vr), "xrCreateVulkanDeviceKHR")) return false;
  if (vr != VK_SUCCESS) {
    rep_.r.error = "vkCreateDevice failed: " + std::to_string(vr);
    return false;
  }
  return true;
}

XrGraphicsBindingVulkan2KHR XrGraphics::binding() const {
  XrGraphicsBindingVulkan2KHR gb{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
  gb.instance = vk_.instance;
  gb.physicalDevice = vk_.physical;
  gb.device = vk_.device;
  gb.queueFamilyIndex = vk_.queue_family;
  return gb;
}

void XrGraphics::destroy_device() {
  if (vk_.device) vkDestroyDevice(vk_.device, nullptr);
  vk_.device = VK_NULL_HANDLE;
  if (vk_.instance) vkDestroyInstance(vk_.instance, nullptr);
  vk_.instance = VK_NULL_HANDLE;
}

bool XrGraphics::create_swapchains(XrInstance instance, XrSystemId system, XrSession session,
                                   int eye_size, bool depth) {
  // sRGB colour: the first of these the runtime offers, else its first format.
  uint32_t nf = 0;
  xrEnumerateSwapchainFormats(session, 0, &nf, nullptr);
  std::vector<int64_t> formats(nf);
  xrEnumerateSwapchainFormats(session, nf, &nf, formats.data());
  format_ = formats.empty() ? int64_t{VK_FORMAT_R8G8B8A8_SRGB} : formats[0];
  for (int64_t want : {int64_t{VK_FORMAT_R8G8B8A8_SRGB}, int64_t{VK_FORMAT_B8G8R8A8_SRGB}}) {
    bool found = false;
    for (int64_t f : formats) found = found || f == want;
    if (found) {
      format_ = want;
      break;
    }
  }
  uint32_t nv = 0;
  xrEnumerateViewConfigurationViews(instance, system, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0,
                                    &nv, nullptr);
  std::vector<XrViewConfigurationView> vcv(nv, {XR_TYPE_VIEW_CONFIGURATION_VIEW});
  xrEnumerateViewConfigurationViews(instance, system, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, nv,
                                    &nv, vcv.data());
  if (nv < 2) {
    rep_.r.error = "the system has no stereo view configuration";
    return false;
  }
  depth_format_ = VK_FORMAT_UNDEFINED;
  if (depth)
    for (int64_t want : {int64_t{VK_FORMAT_D32_SFLOAT}, int64_t{VK_FORMAT_D16_UNORM}})
      if (depth_format_ == VK_FORMAT_UNDEFINED &&
          std::find(formats.begin(), formats.end(), want) != formats.end())
        depth_format_ = want;
  if (depth && depth_format_ == VK_FORMAT_UNDEFINED)
    rep_.note("depth: the runtime offers neither D32_SFLOAT nor D16_UNORM swapchains; no depth");
  for (int e = 0; e < 2; ++e) {
    Eye& eye = eyes_[e];
    eye.width = eye_size > 0 ? static_cast<uint32_t>(eye_size) : vcv[e].recommendedImageRectWidth;
    eye.height = eye_size > 0 ? static_cast<uint32_t>(eye_size) : vcv[e].recommendedImageRectHeight;
    if (!create_chain(session, format_,
                      XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_SAMPLED_BIT,
                      eye.width, eye.height, eye.chain, eye.images))
      return false;
    if (depth_format_ != VK_FORMAT_UNDEFINED &&
        !create_chain(
            session, depth_format_,
            XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT,
            eye.width, eye.height, eye.depth_chain, eye.depth_images))
      return false;
  }
  if (depth_format_ != VK_FORMAT_UNDEFINED)
    rep_.note(std::string("depth: ") +
              (depth_format_ == VK_FORMAT_D32_SFLOAT ? "D32_SFLOAT" : "D16_UNORM") +
              " swapchain per eye");
  return true;
}

bool XrGraphics::create_chain(XrSession session, int64_t format, uint64_t usage, uint32_t w,
                              uint32_t h, XrSwapchain& chain,
                              std::vector<XrSwapchainImageVulkan2KHR>& images) {
  XrSwapchainCreateInfo sc{XR_TYPE_SWAPCHAIN_CREATE_INFO};
  sc.usageFlags = usage;
  sc.format = format;
  sc.sampleCount = 1;
  sc.width = w;
  sc.height = h;
  sc.faceCount = sc.arraySize = sc.mipCount = 1;
  if (!rep_.ok(xrCreateSwapchain(session, &sc, &chain), "xrCreateSwapchain")) return false;
  uint32_t ni = 0;
  xrEnumerateSwapchainImages(chain, 0, &ni, nullptr);
  images.assign(ni, {XR_TYPE_SWAPCHAIN_IMAGE_VULKAN2_KHR});
  return rep_.ok(xrEnumerateSwapchainImages(
                     chain, ni, &ni, reinterpret_cast<XrSwapchainImageBaseHeader*>(images.data())),
                 "xrEnumerateSwapchainImages");
}

void XrGraphics::destroy_swapchains() {
  if (vk_.device != VK_NULL_HANDLE) vkDeviceWaitIdle(vk_.device);
  for (auto& e : eyes_) {
    if (e.chain != XR_NULL_HANDLE) xrDestroySwapchain(e.chain);
    if (e.depth_chain != XR_NULL_HANDLE) xrDestroySwapchain(e.depth_chain);
    e = Eye{};
  }
}

bool XrGraphics::acquire_one(Report& rep, XrSwapchain chain, uint32_t& idx) {
  if (!rep.ok(xrAcquireSwapchainImage(chain, nullptr, &idx), "xrAcquireSwapchainImage"))
    return false;
  XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
  wi.timeout = XR_INFINITE_DURATION;
  return rep.ok(xrWaitSwapchainImage(chain, &wi), "xrWaitSwapchainImage");
}

bool XrGraphics::acquire(uint32_t idx[2], uint32_t didx[2]) {
  for (int e = 0; e < 2; ++e) {
    if (!acquire_one(rep_, eyes_[e].chain, idx[e])) return false;
    didx[e] = 0;
    if (eyes_[e].depth_chain != XR_NULL_HANDLE && !acquire_one(rep_, eyes_[e].depth_chain, didx[e]))
      return false;
  }
  return true;
}

bool XrGraphics::release() {
  for (auto& eye : eyes_)
    for (XrSwapchain chain : {eye.chain, eye.depth_chain})
      if (chain != XR_NULL_HANDLE &&
          !rep_.ok(xrReleaseSwapchainImage(chain, nullptr), "xrReleaseSwapchainImage"))
        return false;
  return true;
}

}  // namespace drape::app
