// Instance and device selection (render/vk_context.hpp).
#include "render/vk_context.hpp"

#include <cstdlib>
#include <cstring>

namespace drape::render {
namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL on_debug_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                VkDebugUtilsMessageTypeFlagsEXT,
                                                const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                void* user) {
  if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    static_cast<VulkanContext*>(user)->record_message(
        severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
        data && data->pMessage ? data->pMessage : "(no text)");
  }
  return VK_FALSE;
}

bool has_layer(const char* name) {
  uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  for (const auto& l : layers)
    if (!std::strcmp(l.layerName, name)) return true;
  return false;
}

bool has_instance_extension(const char* name, const char* layer = nullptr) {
  uint32_t n = 0;
  vkEnumerateInstanceExtensionProperties(layer, &n, nullptr);
  std::vector<VkExtensionProperties> exts(n);
  vkEnumerateInstanceExtensionProperties(layer, &n, exts.data());
  for (const auto& e : exts)
    if (!std::strcmp(e.extensionName, name)) return true;
  return false;
}

bool has_device_extension(VkPhysicalDevice pd, const char* name) {
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> exts(n);
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, exts.data());
  for (const auto& e : exts)
    if (!std::strcmp(e.extensionName, name)) return true;
  return false;
}

int graphics_family(VkPhysicalDevice pd) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> fams(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, fams.data());
  for (uint32_t i = 0; i < n; ++i)
    if (fams[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) return static_cast<int>(i);
  return -1;
}

sim::Error vk_error(const std::string& what, VkResult r) {
  return sim::Error{"vulkan: " + what + " failed: " + vk_result_name(r)};
}

}  // namespace

const char* vk_result_name(VkResult r) {
  switch (r) {
    case VK_SUCCESS:
      return "VK_SUCCESS";
    case VK_NOT_READY:
      return "VK_NOT_READY";
    case VK_TIMEOUT:
      return "VK_TIMEOUT";
    case VK_SUBOPTIMAL_KHR:
      return "VK_SUBOPTIMAL_KHR";
    case VK_ERROR_OUT_OF_HOST_MEMORY:
      return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
      return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED:
      return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST:
      return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT:
      return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT:
      return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER:
      return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_FORMAT_NOT_SUPPORTED:
      return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    case VK_ERROR_SURFACE_LOST_KHR:
      return "VK_ERROR_SURFACE_LOST_KHR";
    case VK_ERROR_OUT_OF_DATE_KHR:
      return "VK_ERROR_OUT_OF_DATE_KHR";
    default:
      return "VkResult(other)";
  }
}

void VulkanContext::record_message(bool error, const char* text) {
  std::lock_guard<std::mutex> lock(mutex_);
  (error ? counts_.errors : counts_.warnings)++;
  if (counts_.messages.size() < 8) counts_.messages.emplace_back(text);
}

ValidationCounts VulkanContext::validation() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counts_;
}

sim::Result<std::unique_ptr<VulkanContext>> VulkanContext::create(const ContextOptions& opt) {
  std::unique_ptr<VulkanContext> ctx(new VulkanContext());
  std::vector<const char*> layers, exts;
  constexpr const char* kValidation = "VK_LAYER_KHRONOS_validation";
  if (opt.validation) {
    if (!has_layer(kValidation))
      return sim::Error{"vulkan: validation requested but " + std::string(kValidation) +
                        " is not installed (Debian: vulkan-validationlayers)"};
    layers.push_back(kValidation);
    exts.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  for (const auto& e : opt.instance_extensions) {
    if (!has_instance_extension(e.c_str()))
      return sim::Error{"vulkan: instance extension " + e + " is not available"};
    exts.push_back(e.c_str());
  }
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "drape";
  app.pEngineName = "drape_render";
  app.apiVersion = api_version();
  VkDebugUtilsMessengerCreateInfoEXT dbg{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  dbg.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  dbg.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  dbg.pfnUserCallback = on_debug_message;
  dbg.pUserData = ctx.get();
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = static_cast<uint32_t>(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  ici.enabledExtensionCount = static_cast<uint32_t>(exts.size());
  ici.ppEnabledExtensionNames = exts.data();
  if (opt.validation) ici.pNext = &dbg;  // also catches messages of vkCreate/DestroyInstance
  VkResult r = vkCreateInstance(&ici, nullptr, &ctx->instance);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    return sim::Error{
        "vulkan: no Vulkan 1.1 driver found (install mesa-vulkan-drivers for the "
        "lavapipe CPU device, or a GPU driver)"};
  if (r != VK_SUCCESS) return vk_error("vkCreateInstance", r);
  if (opt.validation) {
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(ctx->instance, "vkCreateDebugUtilsMessengerEXT"));
    if (create_messenger) create_messenger(ctx->instance, &dbg, nullptr, &ctx->messenger_);
  }

  uint32_t n = 0;
  vkEnumeratePhysicalDevices(ctx->instance, &n, nullptr);
  std::vector<VkPhysicalDevice> devs(n);
  vkEnumeratePhysicalDevices(ctx->instance, &n, devs.data());
  if (n == 0)
    return sim::Error{
        "vulkan: no Vulkan device found (no GPU driver and no lavapipe: install "
        "mesa-vulkan-drivers; check VK_ICD_FILENAMES)"};
  const std::string& filter = opt.device_filter;
  int best = -1, best_score = -1;
  std::string seen;
  for (uint32_t i = 0; i < n; ++i) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(devs[i], &p);
    seen += std::string(seen.empty() ? "" : ", ") + p.deviceName;
    if (p.apiVersion < VK_API_VERSION_1_1 || graphics_family(devs[i]) < 0) continue;
    if (!filter.empty() && std::string(p.deviceName).find(filter) == std::string::npos) continue;
    if (opt.swapchain && !has_device_extension(devs[i], VK_KHR_SWAPCHAIN_EXTENSION_NAME)) continue;
    int score = 0;
    switch (p.deviceType) {
      case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
        score = 4;
        break;
      case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
        score = 3;
        break;
      case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
        score = 2;
        break;
      case VK_PHYSICAL_DEVICE_TYPE_CPU:
        score = opt.prefer_cpu ? 10 : 1;
        break;
      default:
        score = 0;
    }
    if (score > best_score) best = static_cast<int>(i), best_score = score;
  }
  if (best < 0)
    return sim::Error{"vulkan: no suitable device (Vulkan 1.1, graphics queue" +
                      std::string(filter.empty() ? "" : ", name containing '" + filter + "'") +
                      ") among: " + seen};
  ctx->physical = devs[best];
  ctx->queue_family = static_cast<uint32_t>(graphics_family(ctx->physical));
  const float prio = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = ctx->queue_family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &prio;
  std::vector<const char*> dexts;
  if (opt.swapchain) dexts.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = static_cast<uint32_t>(dexts.size());
  dci.ppEnabledExtensionNames = dexts.data();
  r = vkCreateDevice(ctx->physical, &dci, nullptr, &ctx->device);
  if (r != VK_SUCCESS) return vk_error("vkCreateDevice", r);
  vkGetDeviceQueue(ctx->device, ctx->queue_family, 0, &ctx->queue);
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(ctx->physical, &p);
  ctx->device_name = p.deviceName;
  ctx->is_cpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  vkGetPhysicalDeviceMemoryProperties(ctx->physical, &ctx->memory);
  return ctx;
}

sim::Result<std::unique_ptr<VulkanContext>> VulkanContext::adopt(const ExternalDevice& ext) {
  if (!ext.instance || !ext.physical_device || !ext.device)
    return sim::Error{
        "vulkan: handed-over device is incomplete (instance, physical device and "
        "device must all be set)"};
  std::unique_ptr<VulkanContext> ctx(new VulkanContext());
  ctx->owns = false;
  ctx->instance = ext.instance;
  ctx->physical = ext.physical_device;
  ctx->device = ext.device;
  ctx->queue_family = ext.queue_family;
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(ctx->physical, &n, nullptr);
  std::vector<VkQueueFamilyProperties> fams(n);
  vkGetPhysicalDeviceQueueFamilyProperties(ctx->physical, &n, fams.data());
  if (ext.queue_family >= n || !(fams[ext.queue_family].queueFlags & VK_QUEUE_GRAPHICS_BIT) ||
      ext.queue_index >= fams[ext.queue_family].queueCount)
    return sim::Error{"vulkan: handed-over queue family " + std::to_string(ext.queue_family) +
                      " / index " + std::to_string(ext.queue_index) + " is not a graphics queue"};
  vkGetDeviceQueue(ctx->device, ext.queue_family, ext.queue_index, &ctx->queue);
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(ctx->physical, &p);
  ctx->device_name = p.deviceName;
  ctx->is_cpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  vkGetPhysicalDeviceMemoryProperties(ctx->physical, &ctx->memory);
  return ctx;
}

VulkanContext::~VulkanContext() {
  if (!owns) return;
  if (device) vkDestroyDevice(device, nullptr);
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance, messenger_, nullptr);
  }
  if (instance) vkDestroyInstance(instance, nullptr);
}

}  // namespace drape::render
