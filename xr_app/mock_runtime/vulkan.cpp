// The mock runtime's graphics side: XR_KHR_vulkan_enable / XR_KHR_vulkan_enable2 (real Vulkan
// objects, lavapipe preferred), swapchains of VkImages the runtime creates on the
// application's device, and the read-back of composed frames to PNG.
#include <cstring>
#include <vector>

#include "xr_app/mock_runtime/runtime.hpp"

namespace drape::mock {

namespace {
#define DRAPE_LOCK std::lock_guard<std::recursive_mutex> guard_(g_lock)

const int64_t kColorFormats[] = {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_B8G8R8A8_SRGB,
                                 VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_B8G8R8A8_UNORM};
const int64_t kDepthFormats[] = {VK_FORMAT_D32_SFLOAT, VK_FORMAT_D16_UNORM};

bool is_depth(int64_t f) {
  for (int64_t d : kDepthFormats)
    if (d == f) return true;
  return false;
}

XrResult check_system(XrInstance h, XrSystemId id, Instance** out) {
  Instance* inst = lookup<Instance>(h);
  if (!inst) return XR_ERROR_HANDLE_INVALID;
  if (id != 1 || !inst->system_got) return XR_ERROR_SYSTEM_INVALID;
  *out = inst;
  return XR_SUCCESS;
}

VkPhysicalDevice choose_device(VkInstance vk) {
  uint32_t n = 0;
  if (vkEnumeratePhysicalDevices(vk, &n, nullptr) != VK_SUCCESS || n == 0) return VK_NULL_HANDLE;
  std::vector<VkPhysicalDevice> devs(n);
  vkEnumeratePhysicalDevices(vk, &n, devs.data());
  for (VkPhysicalDevice d : devs) {  // lavapipe (CPU) first: deterministic headless output
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    if (p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) return d;
  }
  return devs[0];
}

XrResult requirements(XrInstance h, XrSystemId id, XrGraphicsRequirementsVulkanKHR* req) {
  Instance* inst;
  if (XrResult r = check_system(h, id, &inst); r != XR_SUCCESS) return r;
  if (!req || req->type != XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN_KHR)
    return XR_ERROR_VALIDATION_FAILURE;
  req->minApiVersionSupported = XR_MAKE_VERSION(1, 0, 0);
  req->maxApiVersionSupported = XR_MAKE_VERSION(1, 3, 0);
  inst->gfx_requirements_called = true;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL GetVulkanGraphicsRequirementsKHR(XrInstance h, XrSystemId id,
                                                     XrGraphicsRequirementsVulkanKHR* req) {
  DRAPE_LOCK;
  return requirements(h, id, req);
}

XrResult XRAPI_CALL GetVulkanGraphicsRequirements2KHR(XrInstance h, XrSystemId id,
                                                      XrGraphicsRequirementsVulkan2KHR* req) {
  DRAPE_LOCK;
  return requirements(h, id, req);
}

XrResult XRAPI_CALL GetVulkanInstanceExtensionsKHR(XrInstance h, XrSystemId id, uint32_t cap,
                                                   uint32_t* count, char* buf) {
  DRAPE_LOCK;
  Instance* inst;
  if (XrResult r = check_system(h, id, &inst); r != XR_SUCCESS) return r;
  return two_call_string(cap, count, buf, "");
}

XrResult XRAPI_CALL GetVulkanDeviceExtensionsKHR(XrInstance h, XrSystemId id, uint32_t cap,
                                                 uint32_t* count, char* buf) {
  DRAPE_LOCK;
  Instance* inst;
  if (XrResult r = check_system(h, id, &inst); r != XR_SUCCESS) return r;
  return two_call_string(cap, count, buf, "");
}

XrResult XRAPI_CALL GetVulkanGraphicsDeviceKHR(XrInstance h, XrSystemId id, VkInstance vk,
                                               VkPhysicalDevice* out) {
  DRAPE_LOCK;
  Instance* inst;
  if (XrResult r = check_system(h, id, &inst); r != XR_SUCCESS) return r;
  if (vk == VK_NULL_HANDLE || !out) return XR_ERROR_VALIDATION_FAILURE;
  VkPhysicalDevice d = choose_device(vk);
  if (d == VK_NULL_HANDLE) return XR_ERROR_RUNTIME_FAILURE;
  inst->vk_instance = vk;
  inst->vk_physical = d;
  *out = d;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL GetVulkanGraphicsDevice2KHR(XrInstance h,
                                                const XrVulkanGraphicsDeviceGetInfoKHR* info,
                                                VkPhysicalDevice* out) {
  DRAPE_LOCK;
  if (!lookup<Instance>(h)) return XR_ERROR_HANDLE_INVALID;
  if (!info || info->type != XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR || !out)
    return XR_ERROR_VALIDATION_FAILURE;
  Instance* inst;
  if (XrResult r = check_system(h, info->systemId, &inst); r != XR_SUCCESS) return r;
  if (info->vulkanInstance == VK_NULL_HANDLE) return XR_ERROR_VALIDATION_FAILURE;
  VkPhysicalDevice d = choose_device(info->vulkanInstance);
  if (d == VK_NULL_HANDLE) return XR_ERROR_RUNTIME_FAILURE;
  inst->vk_instance = info->vulkanInstance;
  inst->vk_physical = d;
  *out = d;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL CreateVulkanInstanceKHR(XrInstance h, const XrVulkanInstanceCreateInfoKHR* info,
                                            VkInstance* out, VkResult* vk_result) {
  DRAPE_LOCK;
  if (!lookup<Instance>(h)) return XR_ERROR_HANDLE_INVALID;
  if (!info || info->type != XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR || !out || !vk_result ||
      !info->pfnGetInstanceProcAddr || !info->vulkanCreateInfo || info->createFlags != 0)
    return XR_ERROR_VALIDATION_FAILURE;
  Instance* inst;
  if (XrResult r = check_system(h, info->systemId, &inst); r != XR_SUCCESS) return r;
  auto create = reinterpret_cast<PFN_vkCreateInstance>(
      info->pfnGetInstanceProcAddr(VK_NULL_HANDLE, "vkCreateInstance"));
  if (!create) return XR_ERROR_RUNTIME_FAILURE;
  *vk_result = create(info->vulkanCreateInfo, info->vulkanAllocator, out);
  if (*vk_result == VK_SUCCESS) inst->vk_instance = *out;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL CreateVulkanDeviceKHR(XrInstance h, const XrVulkanDeviceCreateInfoKHR* info,
                                          VkDevice* out, VkResult* vk_result) {
  DRAPE_LOCK;
  if (!lookup<Instance>(h)) return XR_ERROR_HANDLE_INVALID;
  if (!info || info->type != XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR || !out || !vk_result ||
      !info->pfnGetInstanceProcAddr || !info->vulkanCreateInfo ||
      info->vulkanPhysicalDevice == VK_NULL_HANDLE || info->createFlags != 0)
    return XR_ERROR_VALIDATION_FAILURE;
  Instance* inst;
  if (XrResult r = check_system(h, info->systemId, &inst); r != XR_SUCCESS) return r;
  if (inst->vk_instance == VK_NULL_HANDLE) return XR_ERROR_CALL_ORDER_INVALID;
  if (inst->vk_physical != VK_NULL_HANDLE && info->vulkanPhysicalDevice != inst->vk_physical)
    return XR_ERROR_GRAPHICS_DEVICE_INVALID;
  auto create = reinterpret_cast<PFN_vkCreateDevice>(
      info->pfnGetInstanceProcAddr(inst->vk_instance, "vkCreateDevice"));
  if (!create) return XR_ERROR_RUNTIME_FAILURE;
  *vk_result =
      create(info->vulkanPhysicalDevice, info->vulkanCreateInfo, info->vulkanAllocator, out);
  return XR_SUCCESS;
}

// ------------------------------------------------------------------ one-shot commands
VkCommandBuffer begin_commands(Session* s) {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = s->cmd_pool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  if (vkAllocateCommandBuffers(s->vk_device, &ai, &cb) != VK_SUCCESS) return VK_NULL_HANDLE;
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cb, &bi);
  return cb;
}

bool submit_and_wait(Session* s, VkCommandBuffer cb) {
  vkEndCommandBuffer(cb);
  VkQueue q = VK_NULL_HANDLE;
  vkGetDeviceQueue(s->vk_device, s->queue_family, s->queue_index, &q);
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  bool ok =
      vkQueueSubmit(q, 1, &si, VK_NULL_HANDLE) == VK_SUCCESS && vkQueueWaitIdle(q) == VK_SUCCESS;
  vkFreeCommandBuffers(s->vk_device, s->cmd_pool, 1, &cb);
  return ok;
}

void barrier(VkCommandBuffer cb, VkImage img, VkImageAspectFlags aspect, uint32_t mips,
             uint32_t layers, VkImageLayout from, VkImageLayout to, VkAccessFlags src,
             VkAccessFlags dst) {
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.srcAccessMask = src;
  b.dstAccessMask = dst;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = img;
  b.subresourceRange = {aspect, 0, mips, 0, layers};
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                       0, 0, nullptr, 0, nullptr, 1, &b);
}

uint32_t memory_type(Session* s, uint32_t bits, VkMemoryPropertyFlags want) {
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(s->vk_physical, &mp);
  for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
    if ((bits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want) return i;
  for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
    if (bits & (1u << i)) return i;
  return UINT32_MAX;
}

// ------------------------------------------------------------------ swapchains
XrResult XRAPI_CALL EnumerateSwapchainFormats(XrSession h, uint32_t cap, uint32_t* count,
                                              int64_t* out) {
  DRAPE_LOCK;
  Session* s = lookup<Session>(h);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (s->lost) return XR_ERROR_SESSION_LOST;
  std::vector<int64_t> f;
  if (!s->headless) {
    f.assign(std::begin(kColorFormats), std::end(kColorFormats));
    f.insert(f.end(), std::begin(kDepthFormats), std::end(kDepthFormats));
  }
  return two_call<int64_t>(cap, count, out, f);
}

XrResult XRAPI_CALL CreateSwapchain(XrSession h, const XrSwapchainCreateInfo* info,
                                    XrSwapchain* out) {
  DRAPE_LOCK;
  Session* s = lookup<Session>(h);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (s->lost) return XR_ERROR_SESSION_LOST;
  if (!info || !out || info->type != XR_TYPE_SWAPCHAIN_CREATE_INFO)
    return XR_ERROR_VALIDATION_FAILURE;
  if (s->headless) return XR_ERROR_FEATURE_UNSUPPORTED;
  if (info->createFlags & XR_SWAPCHAIN_CREATE_PROTECTED_CONTENT_BIT)
    return XR_ERROR_FEATURE_UNSUPPORTED;
  bool known = false;
  for (int64_t f : kColorFormats) known = known || f == info->format;
  for (int64_t f : kDepthFormats) known = known || f == info->format;
  if (!known) return XR_ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED;
  if (info->width == 0 || info->height == 0 || info->width > 4096 || info->height > 4096 ||
      info->arraySize == 0 || info->arraySize > 16 || info->mipCount == 0 || info->mipCount > 13 ||
      info->usageFlags == 0)
    return XR_ERROR_VALIDATION_FAILURE;
  if (info->faceCount != 1 || info->sampleCount != 1) return XR_ERROR_FEATURE_UNSUPPORTED;
  bool depth = is_depth(info->format);
  if (depth && (info->usageFlags & (XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT |
                                    XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT)))
    return XR_ERROR_FEATURE_UNSUPPORTED;
  if (!depth && (info->usageFlags & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT))
    return XR_ERROR_FEATURE_UNSUPPORTED;

  auto sc = std::make_unique<Swapchain>();
  sc->info = *info;
  sc->info.next = nullptr;
  sc->device = s->vk_device;
  sc->depth = depth;
  VkImageUsageFlags usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  if (info->usageFlags & XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT)
    usage |= VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  if (info->usageFlags & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT)
    usage |= VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
  if (info->usageFlags & XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT)
    usage |= VK_IMAGE_USAGE_STORAGE_BIT;
  if (info->usageFlags & XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT)
    usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  if (info->usageFlags & XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT)
    usage |= VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  if (info->usageFlags & XR_SWAPCHAIN_USAGE_SAMPLED_BIT) usage |= VK_IMAGE_USAGE_SAMPLED_BIT;
  if (info->usageFlags & XR_SWAPCHAIN_USAGE_INPUT_ATTACHMENT_BIT_MND)
    usage |= VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT;
  const uint32_t count = (info->createFlags & XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT) ? 1 : 3;
  Swapchain* scp = sc.get();
  uint64_t handle = register_object(std::move(sc), s->handle);
  VkCommandBuffer cb = begin_commands(s);
  bool ok = cb != VK_NULL_HANDLE;
  for (uint32_t i = 0; ok && i < count; ++i) {
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    if (info->usageFlags & XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT)
      ci.flags |= VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT;
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = static_cast<VkFormat>(info->format);
    ci.extent = {info->width, info->height, 1};
    ci.mipLevels = info->mipCount;
    ci.arrayLayers = info->arraySize;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = usage;
    ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    SwapchainImage im;
    if (vkCreateImage(s->vk_device, &ci, nullptr, &im.image) != VK_SUCCESS) {
      ok = false;
      break;
    }
    VkMemoryRequirements mr;
    vkGetImageMemoryRequirements(s->vk_device, im.image, &mr);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = mr.size;
    mai.memoryTypeIndex = memory_type(s, mr.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (mai.memoryTypeIndex == UINT32_MAX ||
        vkAllocateMemory(s->vk_device, &mai, nullptr, &im.memory) != VK_SUCCESS ||
        vkBindImageMemory(s->vk_device, im.image, im.memory, 0) != VK_SUCCESS) {
      scp->images.push_back(im);
      ok = false;
      break;
    }
    scp->images.push_back(im);
    // Acquired images are in COLOR_ATTACHMENT_OPTIMAL (DEPTH_STENCIL_ATTACHMENT_OPTIMAL for
    // depth), as XR_KHR_vulkan_enable specifies.
    barrier(cb, im.image, depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT,
            info->mipCount, info->arraySize, VK_IMAGE_LAYOUT_UNDEFINED,
            depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL
                  : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
            0,
            depth ? VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT
                  : VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
  }
  if (cb != VK_NULL_HANDLE) ok = submit_and_wait(s, cb) && ok;
  if (!ok) {
    destroy_object(handle);
    return XR_ERROR_RUNTIME_FAILURE;
  }
  *out = to_handle<XrSwapchain>(handle);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL DestroySwapchain(XrSwapchain h) {
  DRAPE_LOCK;
  if (!lookup<Swapchain>(h)) return XR_ERROR_HANDLE_INVALID;
  destroy_object(from_handle(h));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL EnumerateSwapchainImages(XrSwapchain h, uint32_t cap, uint32_t* count,
                                             XrSwapchainImageBaseHeader* images) {
  DRAPE_LOCK;
  Swapchain* sc = lookup<Swapchain>(h);
  if (!sc) return XR_ERROR_HANDLE_INVALID;
  if (!count) return XR_ERROR_VALIDATION_FAILURE;
  *count = static_cast<uint32_t>(sc->images.size());
  if (cap == 0) return XR_SUCCESS;
  if (!images) return XR_ERROR_VALIDATION_FAILURE;
  if (cap < sc->images.size()) return XR_ERROR_SIZE_INSUFFICIENT;
  auto* vk = reinterpret_cast<XrSwapchainImageVulkanKHR*>(images);
  for (size_t i = 0; i < sc->images.size(); ++i)
    if (vk[i].type != XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR) return XR_ERROR_VALIDATION_FAILURE;
  for (size_t i = 0; i < sc->images.size(); ++i) vk[i].image = sc->images[i].image;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL AcquireSwapchainImage(XrSwapchain h, const XrSwapchainImageAcquireInfo* info,
                                          uint32_t* index) {
  DRAPE_LOCK;
  Swapchain* sc = lookup<Swapchain>(h);
  if (!sc) return XR_ERROR_HANDLE_INVALID;
  if ((info && info->type != XR_TYPE_SWAPCHAIN_IMAGE_ACQUIRE_INFO) || !index)
    return XR_ERROR_VALIDATION_FAILURE;
  if (sc->acquired.size() >= sc->images.size()) return XR_ERROR_CALL_ORDER_INVALID;
  if ((sc->info.createFlags & XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT) && sc->last_released >= 0)
    return XR_ERROR_CALL_ORDER_INVALID;
  *index = sc->next;
  sc->acquired.push_back(sc->next);
  sc->next = (sc->next + 1) % static_cast<uint32_t>(sc->images.size());
  return XR_SUCCESS;
}

XrResult XRAPI_CALL WaitSwapchainImage(XrSwapchain h, const XrSwapchainImageWaitInfo* info) {
  DRAPE_LOCK;
  Swapchain* sc = lookup<Swapchain>(h);
  if (!sc) return XR_ERROR_HANDLE_INVALID;
  if (!info || info->type != XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO) return XR_ERROR_VALIDATION_FAILURE;
  if (sc->acquired.empty() || sc->waited) return XR_ERROR_CALL_ORDER_INVALID;
  sc->waited = true;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL ReleaseSwapchainImage(XrSwapchain h, const XrSwapchainImageReleaseInfo* info) {
  DRAPE_LOCK;
  Swapchain* sc = lookup<Swapchain>(h);
  if (!sc) return XR_ERROR_HANDLE_INVALID;
  if (info && info->type != XR_TYPE_SWAPCHAIN_IMAGE_RELEASE_INFO)
    return XR_ERROR_VALIDATION_FAILURE;
  if (sc->acquired.empty() || !sc->waited) return XR_ERROR_CALL_ORDER_INVALID;
  sc->last_released = sc->acquired.front();
  sc->acquired.pop_front();
  sc->waited = false;
  return XR_SUCCESS;
}

}  // namespace

bool init_session_vulkan(Session* s) {
  VkCommandPoolCreateInfo ci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  ci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  ci.queueFamilyIndex = s->queue_family;
  return vkCreateCommandPool(s->vk_device, &ci, nullptr, &s->cmd_pool) == VK_SUCCESS;
}

Session::~Session() {
  if (cmd_pool != VK_NULL_HANDLE) vkDestroyCommandPool(vk_device, cmd_pool, nullptr);
}

Swapchain::~Swapchain() {
  if (device == VK_NULL_HANDLE) return;
  if (!images.empty()) vkDeviceWaitIdle(device);
  for (auto& im : images) {
    if (im.image != VK_NULL_HANDLE) vkDestroyImage(device, im.image, nullptr);
    if (im.memory != VK_NULL_HANDLE) vkFreeMemory(device, im.memory, nullptr);
  }
}

namespace {
// Copies a region (texel bytes per texel) of one array layer of a swapchain's last released
// image to host memory. Between frames the image is in its attachment layout (as
// XR_KHR_vulkan_enable has it) and it is returned to that layout.
bool read_region(Session* s, const XrSwapchainSubImage& sub, int x, int y, uint32_t w, uint32_t h,
                 size_t texel, std::vector<unsigned char>* out) {
  Swapchain* sc = lookup<Swapchain>(sub.swapchain);
  if (!sc || sc->last_released < 0) return false;
  const VkImage img = sc->images[static_cast<size_t>(sc->last_released)].image;
  const VkImageAspectFlags aspect =
      sc->depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
  const VkImageLayout layout = sc->depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL
                                         : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  const VkAccessFlags written = sc->depth ? VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT
                                          : VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  const VkAccessFlags used =
      sc->depth ? VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                      VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT
                : VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT;
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = static_cast<VkDeviceSize>(w) * h * texel;
  bi.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VkBuffer buf = VK_NULL_HANDLE;
  VkDeviceMemory mem = VK_NULL_HANDLE;
  if (vkCreateBuffer(s->vk_device, &bi, nullptr, &buf) != VK_SUCCESS) return false;
  VkMemoryRequirements mr;
  vkGetBufferMemoryRequirements(s->vk_device, buf, &mr);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = mr.size;
  mai.memoryTypeIndex =
      memory_type(s, mr.memoryTypeBits,
                  VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  if (vkAllocateMemory(s->vk_device, &mai, nullptr, &mem) != VK_SUCCESS ||
      vkBindBufferMemory(s->vk_device, buf, mem, 0) != VK_SUCCESS) {
    vkDestroyBuffer(s->vk_device, buf, nullptr);
    if (mem) vkFreeMemory(s->vk_device, mem, nullptr);
    return false;
  }
  bool ok = false;
  VkCommandBuffer cb = begin_commands(s);
  if (cb != VK_NULL_HANDLE) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = written;
    b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    b.oldLayout = layout;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = img;
    b.subresourceRange = {aspect, 0, 1, sub.imageArrayIndex, 1};
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         0, nullptr, 0, nullptr, 1, &b);
    VkBufferImageCopy region{};
    region.imageSubresource = {aspect, 0, sub.imageArrayIndex, 1};
    region.imageOffset = {x, y, 0};
    region.imageExtent = {w, h, 1};
    vkCmdCopyImageToBuffer(cb, img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buf, 1, &region);
    b.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    b.dstAccessMask = used;
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    b.newLayout = layout;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0,
                         0, nullptr, 0, nullptr, 1, &b);
    if (submit_and_wait(s, cb)) {
      void* p = nullptr;
      if (vkMapMemory(s->vk_device, mem, 0, bi.size, 0, &p) == VK_SUCCESS) {
        out->resize(static_cast<size_t>(bi.size));
        std::memcpy(out->data(), p, out->size());
        vkUnmapMemory(s->vk_device, mem);
        ok = true;
      }
    }
  }
  vkDestroyBuffer(s->vk_device, buf, nullptr);
  vkFreeMemory(s->vk_device, mem, nullptr);
  return ok;
}
}  // namespace

bool read_color(Session* s, const XrSwapchainSubImage& sub, std::vector<unsigned char>* rgba) {
  Swapchain* sc = lookup<Swapchain>(sub.swapchain);
  if (!sc || sc->depth) return false;
  const uint32_t w = static_cast<uint32_t>(sub.imageRect.extent.width);
  const uint32_t h = static_cast<uint32_t>(sub.imageRect.extent.height);
  if (!read_region(s, sub, sub.imageRect.offset.x, sub.imageRect.offset.y, w, h, 4, rgba))
    return false;
  bool bgra =
      sc->info.format == VK_FORMAT_B8G8R8A8_SRGB || sc->info.format == VK_FORMAT_B8G8R8A8_UNORM;
  for (size_t i = 0; i < rgba->size(); i += 4) {
    if (bgra) std::swap((*rgba)[i], (*rgba)[i + 2]);
    (*rgba)[i + 3] = 255;
  }
  return true;
}

bool read_depth_texel(Session* s, const XrSwapchainSubImage& sub, int x, int y, float* depth) {
  Swapchain* sc = lookup<Swapchain>(sub.swapchain);
  if (!sc || !sc->depth) return false;
  if (x < 0 || y < 0 || x >= sub.imageRect.extent.width || y >= sub.imageRect.extent.height)
    return false;
  const bool d16 = sc->info.format == VK_FORMAT_D16_UNORM;
  std::vector<unsigned char> texel;
  if (!read_region(s, sub, sub.imageRect.offset.x + x, sub.imageRect.offset.y + y, 1, 1,
                   d16 ? 2 : 4, &texel))
    return false;
  if (d16) {
    uint16_t v;
    std::memcpy(&v, texel.data(), 2);
    *depth = static_cast<float>(v) / 65535.f;
  } else {
    std::memcpy(depth, texel.data(), 4);
  }
  return true;
}

void write_layer_png(Session* s, const XrCompositionLayerProjection* layer,
                     const std::string& path) {
  const XrSwapchainSubImage& sub = layer->views[0].subImage;
  std::vector<unsigned char> rgba;
  if (!read_color(s, sub, &rgba)) return;
  if (!write_png_rgba(path, sub.imageRect.extent.width, sub.imageRect.extent.height, rgba.data()))
    log("cannot write %s", path.c_str());
}

#define DRAPE_ENTRY(fn) \
  if (name == "xr" #fn) return reinterpret_cast<void*>(&fn)
void* vulkan_proc(const std::string& name) {
  DRAPE_ENTRY(GetVulkanGraphicsRequirementsKHR);
  DRAPE_ENTRY(GetVulkanGraphicsRequirements2KHR);
  DRAPE_ENTRY(GetVulkanInstanceExtensionsKHR);
  DRAPE_ENTRY(GetVulkanDeviceExtensionsKHR);
  DRAPE_ENTRY(GetVulkanGraphicsDeviceKHR);
  DRAPE_ENTRY(GetVulkanGraphicsDevice2KHR);
  DRAPE_ENTRY(CreateVulkanInstanceKHR);
  DRAPE_ENTRY(CreateVulkanDeviceKHR);
  DRAPE_ENTRY(EnumerateSwapchainFormats);
  DRAPE_ENTRY(CreateSwapchain);
  DRAPE_ENTRY(DestroySwapchain);
  DRAPE_ENTRY(EnumerateSwapchainImages);
  DRAPE_ENTRY(AcquireSwapchainImage);
  DRAPE_ENTRY(WaitSwapchainImage);
  DRAPE_ENTRY(ReleaseSwapchainImage);
  return nullptr;
}
#undef DRAPE_ENTRY

}  // namespace drape::mock
