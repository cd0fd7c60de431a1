// The mock runtime's Vulkan side through the loader: XR_KHR_vulkan_enable2 creates real Vulkan
// objects (lavapipe), swapchain images are real VkImages, the acquire/wait/release order is
// enforced, and the composed left eye is read back to a PNG whose pixels we check.
#define XR_USE_GRAPHICS_API_VULKAN
#include <gtest/gtest.h>
#include <vulkan/vulkan.h>
// (Vulkan first: openxr_platform.h uses its types)
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "xr_vulkan_handover.hpp"

namespace {

const std::string kManifest = std::string(DRAPE_BINARY_DIR) + "/bin/drape_mock_runtime.json";

template <class F>
F proc(XrInstance inst, const char* name) {
  PFN_xrVoidFunction fn = nullptr;
  EXPECT_EQ(xrGetInstanceProcAddr(inst, name, &fn), XR_SUCCESS) << name;
  return reinterpret_cast<F>(fn);
}

uint32_t be32(const unsigned char* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | p[3];
}

// Decodes the runtime's PNGs (zlib "stored" blocks only) into RGBA rows.
bool read_stored_png(const std::string& path, int* w, int* h, std::vector<unsigned char>* rgba) {
  std::ifstream in(path, std::ios::binary);
  std::vector<unsigned char> d((std::istreambuf_iterator<char>(in)), {});
  if (d.size() < 33 || std::memcmp(d.data(), "\x89PNG\r\n\x1a\n", 8) != 0) return false;
  std::vector<unsigned char> z;
  size_t pos = 8;
  while (pos + 12 <= d.size()) {
    uint32_t n = be32(&d[pos]);
    std::string type(reinterpret_cast<char*>(&d[pos + 4]), 4);
    if (type == "IHDR") {
      *w = static_cast<int>(be32(&d[pos + 8]));
      *h = static_cast<int>(be32(&d[pos + 12]));
    } else if (type == "IDAT") {
      z.insert(z.end(), d.begin() + pos + 8, d.begin() + pos + 8 + n);
    }
    pos += 12 + n;
  }
  std::vector<unsigned char> raw;
  size_t p = 2;
  for (;;) {
    if (p + 5 > z.size()) return false;
    bool last = z[p] & 1;
    size_t len = z[p + 1] | (z[p + 2] << 8);
    raw.insert(raw.end(), z.begin() + p + 5, z.begin() + p + 5 + len);
    p += 5 + len;
    if (last) break;
  }
  rgba->clear();
  for (int y = 0; y < *h; ++y) {
    size_t row = static_cast<size_t>(y) * (*w * 4 + 1);
    if (raw[row] != 0) return false;
    rgba->insert(rgba->end(), raw.begin() + row + 1, raw.begin() + row + 1 + *w * 4);
  }
  return true;
}

TEST(MockVulkan, SwapchainFramesAreReadBackToPng) {
  const std::string out =
      (std::filesystem::temp_directory_path() / ("drape_xr_vk_" + std::to_string(::getpid())))
          .string();
  std::filesystem::remove_all(out);
  setenv("XR_RUNTIME_JSON", kManifest.c_str(), 1);
  setenv("DRAPE_MOCK_FAST", "1", 1);
  setenv("DRAPE_MOCK_WRITE_FRAMES", out.c_str(), 1);
  setenv("DRAPE_MOCK_WRITE_EVERY", "2", 1);
  unsetenv("DRAPE_MOCK_SCENARIO");
  unsetenv("DRAPE_MOCK_END_AFTER_FRAMES");
  unsetenv("DRAPE_MOCK_LOSE_SESSION_AT_FRAME");

  const char* exts[] = {XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME};
  XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
  std::strcpy(ci.applicationInfo.applicationName, "drape_vk_test");
  ci.applicationInfo.apiVersion = XR_CURRENT_API_VERSION;
  ci.enabledExtensionCount = 1;
  ci.enabledExtensionNames = exts;
  XrInstance inst;
  ASSERT_EQ(xrCreateInstance(&ci, &inst), XR_SUCCESS);
  XrSystemGetInfo gi{XR_TYPE_SYSTEM_GET_INFO};
  gi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  XrSystemId sys;
  ASSERT_EQ(xrGetSystem(inst, &gi, &sys), XR_SUCCESS);

  XrVulkanHandover h;
  ASSERT_EQ(create_vulkan_through_xr(inst, sys, h), "");
  EXPECT_LE(h.requirements.minApiVersionSupported, XR_MAKE_VERSION(1, 1, 0));
  VkInstance vk = h.instance;
  VkPhysicalDevice phys = h.phys;
  VkDevice dev = h.device;
  const uint32_t family = h.family;
  VkPhysicalDeviceProperties pp;
  vkGetPhysicalDeviceProperties(phys, &pp);
  std::printf("runtime chose Vulkan device: %s\n", pp.deviceName);

  XrGraphicsBindingVulkan2KHR bind{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
  bind.instance = vk;
  bind.physicalDevice = phys;
  bind.device = dev;
  bind.queueFamilyIndex = family;
  XrSessionCreateInfo sci{XR_TYPE_SESSION_CREATE_INFO, &bind};
  sci.systemId = sys;
  XrSession session;
  ASSERT_EQ(xrCreateSession(inst, &sci, &session), XR_SUCCESS);

  uint32_t nf = 0;
  ASSERT_EQ(xrEnumerateSwapchainFormats(session, 0, &nf, nullptr), XR_SUCCESS);
  std::vector<int64_t> formats(nf);
  ASSERT_EQ(xrEnumerateSwapchainFormats(session, nf, &nf, formats.data()), XR_SUCCESS);
  ASSERT_NE(std::find(formats.begin(), formats.end(), VK_FORMAT_R8G8B8A8_UNORM), formats.end());

  const int W = 64, H = 48;
  XrSwapchainCreateInfo sw{XR_TYPE_SWAPCHAIN_CREATE_INFO};
  sw.usageFlags = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT;
  sw.format = VK_FORMAT_R8G8B8A8_UNORM;
  sw.sampleCount = 1;
  sw.width = W;
  sw.height = H;
  sw.faceCount = 1;
  sw.arraySize = 1;
  sw.mipCount = 1;
  XrSwapchain chain;
  sw.format = 12345;
  EXPECT_EQ(xrCreateSwapchain(session, &sw, &chain), XR_ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED);
  sw.format = VK_FORMAT_R8G8B8A8_UNORM;
  ASSERT_EQ(xrCreateSwapchain(session, &sw, &chain), XR_SUCCESS);
  uint32_t ni = 0;
  ASSERT_EQ(xrEnumerateSwapchainImages(chain, 0, &ni, nullptr), XR_SUCCESS);
  ASSERT_EQ(ni, 3u);
  std::vector<XrSwapchainImageVulkan2KHR> imgs(ni, {XR_TYPE_SWAPCHAIN_IMAGE_VULKAN2_KHR});
  imgs[1].type = XR_TYPE_SWAPCHAIN_IMAGE_OPENGL_KHR;
  EXPECT_EQ(xrEnumerateSwapchainImages(chain, ni, &ni,
                                       reinterpret_cast<XrSwapchainImageBaseHeader*>(imgs.data())),
            XR_ERROR_VALIDATION_FAILURE);
  imgs[1].type = XR_TYPE_SWAPCHAIN_IMAGE_VULKAN2_KHR;
  ASSERT_EQ(xrEnumerateSwapchainImages(chain, ni, &ni,
                                       reinterpret_cast<XrSwapchainImageBaseHeader*>(imgs.data())),
            XR_SUCCESS);
  for (auto& im : imgs) EXPECT_NE(im.image, VK_NULL_HANDLE);

  XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  rs.poseInReferenceSpace.orientation.w = 1;
  XrSpace local;
  ASSERT_EQ(xrCreateReferenceSpace(session, &rs, &local), XR_SUCCESS);

  XrEventDataBuffer ev{XR_TYPE_EVENT_DATA_BUFFER};
  while (xrPollEvent(inst, &ev) == XR_SUCCESS) ev = {XR_TYPE_EVENT_DATA_BUFFER};
  XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
  bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  ASSERT_EQ(xrBeginSession(session, &bi), XR_SUCCESS);

  VkQueue queue;
  vkGetDeviceQueue(dev, family, 0, &queue);
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.queueFamilyIndex = family;
  VkCommandPool pool;
  ASSERT_EQ(vkCreateCommandPool(dev, &pci, nullptr, &pool), VK_SUCCESS);

  auto clear = [&](VkImage img, VkClearColorValue color) {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkCommandBuffer cb;
    vkAllocateCommandBuffers(dev, &ai, &cb);
    VkCommandBufferBeginInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    vkBeginCommandBuffer(cb, &cbi);
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = img;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    b.oldLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         0, nullptr, 0, nullptr, 1, &b);
    VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(cb, img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &color, 1, &range);
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0,
                         0, nullptr, 0, nullptr, 1, &b);
    vkEndCommandBuffer(cb);
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE);
    vkQueueWaitIdle(queue);
    vkFreeCommandBuffers(dev, pool, 1, &cb);
  };

  XrCompositionLayerProjectionView views[2] = {{XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW},
                                               {XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW}};
  for (auto& v : views) {
    v.pose.orientation.w = 1;
    v.subImage.swapchain = chain;
    v.subImage.imageRect = {{0, 0}, {W, H}};
  }
  XrCompositionLayerProjection layer{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
  layer.space = local;
  layer.viewCount = 2;
  layer.views = views;
  const XrCompositionLayerBaseHeader* layers[] = {
      reinterpret_cast<XrCompositionLayerBaseHeader*>(&layer)};

  for (int f = 0; f < 4; ++f) {
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    ASSERT_EQ(xrWaitFrame(session, nullptr, &fs), XR_SUCCESS);
    ASSERT_EQ(xrBeginFrame(session, nullptr), XR_SUCCESS);
    XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
    ei.displayTime = fs.predictedDisplayTime;
    ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    ei.layerCount = 1;
    ei.layers = layers;
    if (f == 0) {  // nothing released yet: the layer is invalid
      EXPECT_EQ(xrEndFrame(session, &ei), XR_ERROR_LAYER_INVALID);
    }
    uint32_t idx;
    ASSERT_EQ(xrAcquireSwapchainImage(chain, nullptr, &idx), XR_SUCCESS);
    EXPECT_EQ(idx, static_cast<uint32_t>(f % 3));
    EXPECT_EQ(xrReleaseSwapchainImage(chain, nullptr), XR_ERROR_CALL_ORDER_INVALID);
    XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
    wi.timeout = XR_INFINITE_DURATION;
    ASSERT_EQ(xrWaitSwapchainImage(chain, &wi), XR_SUCCESS);
    EXPECT_EQ(xrWaitSwapchainImage(chain, &wi), XR_ERROR_CALL_ORDER_INVALID);
    // Frame f: red = 40 * f, green 100, blue 200.
    clear(imgs[idx].image, VkClearColorValue{{f * 40 / 255.f, 100 / 255.f, 200 / 255.f, 1.f}});
    ASSERT_EQ(xrReleaseSwapchainImage(chain, nullptr), XR_SUCCESS);
    views[0].subImage.imageRect = {{0, 0}, {W + 1, H}};
    EXPECT_EQ(xrEndFrame(session, &ei), XR_ERROR_SWAPCHAIN_RECT_INVALID);
    views[0].subImage.imageRect = {{0, 0}, {W, H}};
    ASSERT_EQ(xrEndFrame(session, &ei), XR_SUCCESS);
  }
  // All three images acquired: a fourth acquire is a call-order error.
  uint32_t idx;
  for (int i = 0; i < 3; ++i) ASSERT_EQ(xrAcquireSwapchainImage(chain, nullptr, &idx), XR_SUCCESS);
  EXPECT_EQ(xrAcquireSwapchainImage(chain, nullptr, &idx), XR_ERROR_CALL_ORDER_INVALID);

  ASSERT_EQ(xrDestroySwapchain(chain), XR_SUCCESS);
  ASSERT_EQ(xrDestroySession(session), XR_SUCCESS);
  ASSERT_EQ(xrDestroyInstance(inst), XR_SUCCESS);
  vkDestroyCommandPool(dev, pool, nullptr);
  vkDestroyDevice(dev, nullptr);
  vkDestroyInstance(vk, nullptr);

  // Every 2nd frame was written: frames 0 and 2, with the colours cleared into them.
  for (int f : {0, 2}) {
    char name[64];
    std::snprintf(name, sizeof(name), "/frame_%06d.png", f);
    int w = 0, h = 0;
    std::vector<unsigned char> px;
    ASSERT_TRUE(read_stored_png(out + name, &w, &h, &px)) << out + name;
    EXPECT_EQ(w, W);
    EXPECT_EQ(h, H);
    int max_err = 0;
    for (size_t i = 0; i < px.size(); i += 4) {
      max_err = std::max(max_err, std::abs(px[i] - f * 40));
      max_err = std::max(max_err, std::abs(px[i + 1] - 100));
      max_err = std::max(max_err, std::abs(px[i + 2] - 200));
    }
    std::printf("frame %d: %dx%d, max channel error %d\n", f, w, h, max_err);
    EXPECT_LE(max_err, 1);
  }
  EXPECT_FALSE(std::filesystem::exists(out + "/frame_000001.png"));
  std::filesystem::remove_all(out);
}

}  // namespace
