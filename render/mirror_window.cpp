// GLFW mirror window (render/mirror_window.hpp).
#include "render/mirror_window.hpp"

#ifdef DRAPE_HAVE_GLFW
#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#endif

#include <algorithm>

namespace drape::render {

#ifdef DRAPE_HAVE_GLFW

struct MirrorWindow::Impl {
  Renderer* renderer = nullptr;
  GLFWwindow* window = nullptr;
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{};
  std::vector<VkImage> images;
  VkFence acquire_fence = VK_NULL_HANDLE;
  int presented = 0;

  VulkanContext& ctx() { return renderer->context(); }

  Status create_swapchain() {
    VkSurfaceCapabilitiesKHR caps;
    if (VkResult r = vkGetPhysicalDeviceSurfaceCapabilitiesKHR(ctx().physical, surface, &caps);
        r != VK_SUCCESS)
      return Status{std::string("mirror: surface capabilities: ") + vk_result_name(r)};
    uint32_t n = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(ctx().physical, surface, &n, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(n);
    vkGetPhysicalDeviceSurfaceFormatsKHR(ctx().physical, surface, &n, formats.data());
    if (formats.empty()) return Status{"mirror: the surface offers no formats"};
    VkSurfaceFormatKHR chosen = formats[0];
    for (const auto& f : formats)
      if (f.format == VK_FORMAT_B8G8R8A8_SRGB || f.format == VK_FORMAT_R8G8B8A8_SRGB) chosen = f;
    format = chosen.format;
    if (caps.currentExtent.width != 0xFFFFFFFFu) {
      extent = caps.currentExtent;
    } else {
      int w = 0, h = 0;
      glfwGetFramebufferSize(window, &w, &h);
      extent = {std::clamp<uint32_t>(w, caps.minImageExtent.width, caps.maxImageExtent.width),
                std::clamp<uint32_t>(h, caps.minImageExtent.height, caps.maxImageExtent.height)};
    }
    if (extent.width == 0 || extent.height == 0) return {};  // minimised: nothing to draw
    VkSwapchainCreateInfoKHR si{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    si.surface = surface;
    si.minImageCount = std::max(caps.minImageCount, 2u);
    if (caps.maxImageCount) si.minImageCount = std::min(si.minImageCount, caps.maxImageCount);
    si.imageFormat = chosen.format;
    si.imageColorSpace = chosen.colorSpace;
    si.imageExtent = extent;
    si.imageArrayLayers = 1;
    si.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    si.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    si.preTransform = caps.currentTransform;
    si.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    if (!(caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR))
      si.compositeAlpha = VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR;
    si.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // always supported
    si.clipped = VK_TRUE;
    si.oldSwapchain = swapchain;
    VkSwapchainKHR created = VK_NULL_HANDLE;
    VkResult r = vkCreateSwapchainKHR(ctx().device, &si, nullptr, &created);
    if (swapchain) {
      renderer->forget_targets();
      vkDestroySwapchainKHR(ctx().device, swapchain, nullptr);
    }
    swapchain = created;
    if (r != VK_SUCCESS)
      return Status{std::string("mirror: vkCreateSwapchainKHR: ") + vk_result_name(r)};
    vkGetSwapchainImagesKHR(ctx().device, swapchain, &n, nullptr);
    images.resize(n);
    vkGetSwapchainImagesKHR(ctx().device, swapchain, &n, images.data());
    return {};
  }

  ~Impl() {
    if (renderer) {
      vkDeviceWaitIdle(ctx().device);
      renderer->forget_targets();
      if (swapchain) vkDestroySwapchainKHR(ctx().device, swapchain, nullptr);
      if (acquire_fence) vkDestroyFence(ctx().device, acquire_fence, nullptr);
      if (surface) vkDestroySurfaceKHR(ctx().instance, surface, nullptr);
    }
    if (window) glfwDestroyWindow(window);
  }
};

sim::Result<std::vector<std::string>> MirrorWindow::prepare() {
  static bool initialised = false;
  if (!initialised) {
    if (!glfwInit())
      return sim::Error{
          "mirror: cannot initialise GLFW (no display? set DISPLAY or run under "
          "xvfb-run); continuing without a mirror window is fine"};
    initialised = true;
  }
  if (!glfwVulkanSupported()) return sim::Error{"mirror: GLFW finds no Vulkan loader"};
  uint32_t n = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&n);
  if (!names) return sim::Error{"mirror: no Vulkan surface extension for this display"};
  return std::vector<std::string>(names, names + n);
}

MirrorWindow::MirrorWindow() : impl_(std::make_unique<Impl>()) {}
MirrorWindow::~MirrorWindow() = default;

sim::Result<std::unique_ptr<MirrorWindow>> MirrorWindow::open(Renderer& renderer, int width,
                                                              int height,
                                                              const std::string& title) {
  if (auto p = prepare(); !p) return sim::Error{p.error()};
  std::unique_ptr<MirrorWindow> w(new MirrorWindow());
  Impl& m = *w->impl_;
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  m.window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!m.window) return sim::Error{"mirror: cannot create a window"};
  m.renderer = &renderer;
  if (VkResult r = glfwCreateWindowSurface(m.ctx().instance, m.window, nullptr, &m.surface);
      r != VK_SUCCESS)
    return sim::Error{std::string("mirror: cannot create a surface (was the renderer created with "
                                  "MirrorWindow::prepare()'s extensions?): ") +
                      vk_result_name(r)};
  VkBool32 supported = VK_FALSE;
  vkGetPhysicalDeviceSurfaceSupportKHR(m.ctx().physical, m.ctx().queue_family, m.surface,
                                       &supported);
  if (!supported) return sim::Error{"mirror: the renderer's queue cannot present to the window"};
  VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  vkCreateFence(m.ctx().device, &fi, nullptr, &m.acquire_fence);
  if (Status s = m.create_swapchain(); !s) return sim::Error{s.error};
  return w;
}

Status MirrorWindow::show(const sim::SceneSnapshot& snap, const View& view,
                          const DrawOptions& opt) {
  Impl& m = *impl_;
  glfwPollEvents();
  if (m.extent.width == 0 || m.extent.height == 0 || !m.swapchain) {
    if (Status s = m.create_swapchain(); !s) return s;
    if (m.extent.width == 0 || !m.swapchain) return {};
  }
  uint32_t index = 0;
  VkResult r = vkAcquireNextImageKHR(m.ctx().device, m.swapchain, UINT64_MAX, VK_NULL_HANDLE,
                                     m.acquire_fence, &index);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) return m.create_swapchain();
  if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR)
    return Status{std::string("mirror: vkAcquireNextImageKHR: ") + vk_result_name(r)};
  vkWaitForFences(m.ctx().device, 1, &m.acquire_fence, VK_TRUE, UINT64_MAX);
  vkResetFences(m.ctx().device, 1, &m.acquire_fence);
  ColorTarget t{m.images[index], m.format, m.extent.width,
                m.extent.height, 0,        VK_IMAGE_LAYOUT_PRESENT_SRC_KHR};
  if (Status s = m.renderer->render(snap, view, t, opt); !s) return s;
  VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  pi.swapchainCount = 1;
  pi.pSwapchains = &m.swapchain;
  pi.pImageIndices = &index;
  r = vkQueuePresentKHR(m.ctx().queue, &pi);
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) return m.create_swapchain();
  if (r != VK_SUCCESS)
    return Status{std::string("mirror: vkQueuePresentKHR: ") + vk_result_name(r)};
  ++m.presented;
  return {};
}

bool MirrorWindow::should_close() const {
  return glfwWindowShouldClose(impl_->window);
}
int MirrorWindow::width() const {
  return static_cast<int>(impl_->extent.width);
}
int MirrorWindow::height() const {
  return static_cast<int>(impl_->extent.height);
}
int MirrorWindow::frames_presented() const {
  return impl_->presented;
}

#else  // built without GLFW

struct MirrorWindow::Impl {};
MirrorWindow::MirrorWindow() = default;
MirrorWindow::~MirrorWindow() = default;
sim::Result<std::vector<std::string>> MirrorWindow::prepare() {
  return sim::Error{"mirror: built without GLFW (install libglfw3-dev)"};
}
sim::Result<std::unique_ptr<MirrorWindow>> MirrorWindow::open(Renderer&, int, int,
                                                              const std::string&) {
  return sim::Error{"mirror: built without GLFW (install libglfw3-dev)"};
}
Status MirrorWindow::show(const sim::SceneSnapshot&, const View&, const DrawOptions&) {
  return Status{"mirror: built without GLFW"};
}
bool MirrorWindow::should_close() const {
  return true;
}
int MirrorWindow::width() const {
  return 0;
}
int MirrorWindow::height() const {
  return 0;
}
int MirrorWindow::frames_presented() const {
  return 0;
}

#endif

}  // namespace drape::render
