// The OpenXR app's graphics (hello_xr's graphics plugin): the Vulkan instance and device made
// through the runtime (XR_KHR_vulkan_enable2), the session's graphics binding, and one sRGB
// swapchain per eye.
#pragma once

#include <cstdint>
#include <vector>

#include "xr_app/app/xr_common.hpp"

namespace drape::app {

// The Vulkan device the runtime chose, for the session and the renderer.
struct VulkanDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queue_family = 0;
};

// One eye's swapchain.
struct Eye {
  XrSwapchain chain = XR_NULL_HANDLE;
  uint32_t width = 0, height = 0;
  std::vector<XrSwapchainImageVulkan2KHR> images;
};

class XrGraphics {
 public:
  explicit XrGraphics(Report& rep) : rep_(rep) {}

  // The Vulkan instance and device, made through the runtime for this system.
  bool create_device(XrInstance instance, XrSystemId system);
  const VulkanDevice& device() const { return vk_; }
  XrGraphicsBindingVulkan2KHR binding() const;
  void destroy_device();

  // One swapchain per eye: eye_size px square, else the runtime's recommended size.
  bool create_swapchains(XrInstance instance, XrSystemId system, XrSession session, int eye_size);
  // Waits for the device to idle first (the renderer's last frame).
  void destroy_swapchains();
  // Acquires and waits both eyes' images (their indices in idx).
  bool acquire(uint32_t idx[2]);
  bool release();
  const Eye& eye(int e) const { return eyes_[e]; }
  VkFormat format() const { return static_cast<VkFormat>(format_); }

 private:
  bool create_vk_instance(XrInstance instance, XrSystemId system);
  Report& rep_;
  VulkanDevice vk_;
  Eye eyes_[2];
  int64_t format_ = VK_FORMAT_R8G8B8A8_SRGB;
};

}  // namespace drape::app
