// Test clients' Vulkan through XR_KHR_vulkan_enable2, as an application sets it up: the
// runtime's graphics requirements, the Vulkan 1.1 instance and the device it chooses, created
// through the runtime, with one graphics queue family. Shared by the mock runtime's Vulkan test
// and the window test's client. Include after the Vulkan and OpenXR platform headers
// (XR_USE_GRAPHICS_API_VULKAN).
#pragma once

#include <string>
#include <vector>

struct XrVulkanHandover {
  XrGraphicsRequirementsVulkan2KHR requirements{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR};
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice phys = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  uint32_t family = 0;  // the graphics queue family
};

// Fills `out`; returns an empty string, or what failed.
inline std::string create_vulkan_through_xr(XrInstance inst, XrSystemId sys,
                                            XrVulkanHandover& out) {
  auto proc = [inst](const char* name) {
    PFN_xrVoidFunction fn = nullptr;
    return xrGetInstanceProcAddr(inst, name, &fn) == XR_SUCCESS ? fn : nullptr;
  };
  auto reqs = reinterpret_cast<PFN_xrGetVulkanGraphicsRequirements2KHR>(
      proc("xrGetVulkanGraphicsRequirements2KHR"));
  auto mk_inst = reinterpret_cast<PFN_xrCreateVulkanInstanceKHR>(proc("xrCreateVulkanInstanceKHR"));
  auto get_dev =
      reinterpret_cast<PFN_xrGetVulkanGraphicsDevice2KHR>(proc("xrGetVulkanGraphicsDevice2KHR"));
  auto mk_dev = reinterpret_cast<PFN_xrCreateVulkanDeviceKHR>(proc("xrCreateVulkanDeviceKHR"));
  if (!reqs || !mk_inst || !get_dev || !mk_dev) return "XR_KHR_vulkan_enable2 functions missing";
  if (reqs(inst, sys, &out.requirements) != XR_SUCCESS)
    return "xrGetVulkanGraphicsRequirements2KHR";

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo vci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  vci.pApplicationInfo = &app;
  XrVulkanInstanceCreateInfoKHR xvci{XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR};
  xvci.systemId = sys;
  xvci.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xvci.vulkanCreateInfo = &vci;
  VkResult vr = VK_SUCCESS;
  if (mk_inst(inst, &xvci, &out.instance, &vr) != XR_SUCCESS || vr != VK_SUCCESS)
    return "xrCreateVulkanInstanceKHR";
  XrVulkanGraphicsDeviceGetInfoKHR dgi{XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR};
  dgi.systemId = sys;
  dgi.vulkanInstance = out.instance;
  if (get_dev(inst, &dgi, &out.phys) != XR_SUCCESS) return "xrGetVulkanGraphicsDevice2KHR";

  uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(out.phys, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> qf(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(out.phys, &nq, qf.data());
  out.family = 0;
  while (out.family < nq && !(qf[out.family].queueFlags & VK_QUEUE_GRAPHICS_BIT)) ++out.family;
  if (out.family >= nq) return "no graphics queue family";
  float prio = 1;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = out.family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &prio;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  XrVulkanDeviceCreateInfoKHR xdci{XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR};
  xdci.systemId = sys;
  xdci.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xdci.vulkanPhysicalDevice = out.phys;
  xdci.vulkanCreateInfo = &dci;
  if (mk_dev(inst, &xdci, &out.device, &vr) != XR_SUCCESS || vr != VK_SUCCESS)
    return "xrCreateVulkanDeviceKHR";
  return "";
}
