// Vulkan instance, physical device, device and queue for the renderer: created here (preferring a
// real GPU, falling back to Mesa lavapipe) or handed over by the caller (the XR runtime's, from
// xrCreateVulkanInstanceKHR / xrCreateVulkanDeviceKHR). Validation messages are counted.
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "sim/core/types.hpp"

namespace drape::render {

// A failure as a message (empty when all went well).
struct Status {
  std::string error;
  bool ok() const { return error.empty(); }
  explicit operator bool() const { return ok(); }
};

const char* vk_result_name(VkResult r);

// Devices created by someone else (the XR runtime): the renderer uses, never destroys, them.
struct ExternalDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queue_family = 0;
  uint32_t queue_index = 0;
};

struct ContextOptions {
  bool validation = false;    // VK_LAYER_KHRONOS_validation + a counting messenger
  std::string device_filter;  // substring of the device name (drape render --vk-device)
  bool prefer_cpu = false;    // pick lavapipe even when a GPU is present (golden images)
  std::vector<std::string> instance_extensions;  // e.g. the surface extensions GLFW asks for
  bool swapchain = false;  // enable VK_KHR_swapchain on the device (mirror window)
};

struct ValidationCounts {
  uint32_t errors = 0, warnings = 0;
  std::vector<std::string> messages;  // the first few, for test output
};

// Instance + device + queue. Move-only; destroys what it created.
class VulkanContext {
 public:
  static sim::Result<std::unique_ptr<VulkanContext>> create(const ContextOptions& opt);
  static sim::Result<std::unique_ptr<VulkanContext>> adopt(const ExternalDevice& ext);
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  // What the XR path must ask the runtime for (XrVulkanInstanceCreateInfoKHR etc.).
  static uint32_t api_version() { return VK_API_VERSION_1_1; }

  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t queue_family = 0;
  std::string device_name;
  bool is_cpu = false;
  bool owns = true;
  VkPhysicalDeviceMemoryProperties memory{};

  ValidationCounts validation() const;
  void record_message(bool error, const char* text);

 private:
  VulkanContext() = default;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  mutable std::mutex mutex_;
  ValidationCounts counts_;
};

}  // namespace drape::render
