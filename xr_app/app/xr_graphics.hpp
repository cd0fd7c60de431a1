// The OpenXR app's graphics (hello_xr's graphics plugin): the Vulkan instance and device made
// through the runtime (XR_KHR_vulkan_enable2), the session's graphics binding, and one sRGB
// swapchain per eye (and a depth swapchain per eye where the runtime takes depth).
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
  XrSwapchain depth_chain = XR_NULL_HANDLE;  // same size; none without depth
  std::vector<XrSwapchainImageVulkan2KHR> depth_images;
};

class XrGraphics {
 public:
  explicit XrGraphics(Report& rep) : rep_(rep) {}

  // The Vulkan instance and device, made through the runtime for this system.
  bool create_device(XrInstance instance, XrSystemId system);
  const VulkanDevice& device() const { return vk_; }
  XrGraphicsBindingVulkan2KHR binding() const;
  void destroy_device();

  // One swapchain per eye: eye_size px square, else the runtime's recommended size. With
  // `depth` (XR_KHR_composition_layer_depth enabled) also a depth swapchain per eye, of
  // D32_SFLOAT or else D16_UNORM as the runtime offers (none when it offers neither).
  bool create_swapchains(XrInstance instance, XrSystemId system, XrSession session, int eye_size,
                         bool depth);
  // Waits for the device to idle first (the renderer's last frame).
  void destroy_swapchains();
  // Acquires and waits both eyes' images (their indices in idx; the depth images' in didx).
  bool acquire(uint32_t idx[2], uint32_t didx[2]);
  bool release();
  const Eye& eye(int e) const { return eyes_[e]; }
  VkFormat format() const { return static_cast<VkFormat>(format_); }
  bool has_depth() const { return eyes_[0].depth_chain != XR_NULL_HANDLE; }
  VkFormat depth_format() const { return static_cast<VkFormat>(depth_format_); }

 private:
  bool create_vk_instance(XrInstance instance, XrSystemId system);
  bool create_chain(XrSession session, int64_t format, uint64_t usage, uint32_t w, uint32_t h,
                    XrSwapchain& chain, std::vector<XrSwapchainImageVulkan2KHR>& images);
  static bool acquire_one(Report& rep, XrSwapchain chain, uint32_t& idx);
  Report& rep_;
  VulkanDevice vk_;
  Eye eyes_[2];
  int64_t format_ = VK_FORMAT_R8G8B8A8_SRGB;
  int64_t depth_format_ = VK_FORMAT_UNDEFINED;
};

}  // namespace drape::app
