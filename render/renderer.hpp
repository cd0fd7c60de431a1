// The Vulkan renderer of the draping scene: draws a sim::SceneSnapshot (read only; the sim thread
// is never touched) into an image handed in by the caller (XR swapchain image per eye, mirror
// window) or into its own offscreen target read back to RGBA8 for PNG. See docs/rendering.md.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "render/camera.hpp"
#include "render/geometry.hpp"
#include "render/text.hpp"
#include "render/vk_context.hpp"
#include "sim/core/snapshot.hpp"

namespace drape::render {

struct RendererOptions {
  ContextOptions context;  // validation, device choice, extra extensions (ignored on handover)
  int samples = 1;         // MSAA sample count (1, 2, 4, 8; clamped to what the device has)
  std::string font_path;   // the feedback panel's font ("" = default_font_path())
};

// The feedback panel (text.hpp): lines of text on a dark rectangle, head-locked at arm's length
// (head_locked_panel), drawn over the scene in every view and kept out of a caller's depth
// image (it never hides the surface a desk runtime places the hand on).
struct TextPanel {
  std::vector<std::string> lines;  // none: no panel
  uint64_t version = 0;            // the quads are rebuilt only when it changes
  Pose head;                       // the head it hangs in front of (stage space)
  PanelStyle style;
};

// An image the caller owns (e.g. from xrEnumerateSwapchainImages): colour-attachment usage,
// 2D or 2D-array (array_layer picks the eye). It is left in final_layout.
struct ColorTarget {
  VkImage image = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_R8G8B8A8_SRGB;
  uint32_t width = 0, height = 0;
  uint32_t array_layer = 0;
  VkImageLayout final_layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;  // what XR expects
  // Optional: the caller's depth image (an XR depth swapchain image, same size, same array layer;
  // D32_SFLOAT or D16_UNORM; depth-attachment and transfer-source usage). The scene's depth
  // (cloth, form, floor; not the hands and markers drawn over it) is stored into it (storeOp
  // STORE: 0 at the view's near plane, 1 at its far plane) and it is left in
  // DEPTH_STENCIL_ATTACHMENT_OPTIMAL. Needs samples 1. Null: the renderer's own depth buffer,
  // not stored.
  VkImage depth_image = VK_NULL_HANDLE;
  VkFormat depth_format = VK_FORMAT_D32_SFLOAT;
};

// 8-bit RGBA pixels, rows top to bottom, sRGB-encoded.
struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  const uint8_t* px(int x, int y) const { return &rgba[(static_cast<size_t>(y) * width + x) * 4]; }
};

struct FrameStats {
  double build_ms = 0;         // CPU geometry (cloth, decorations; the form is cached)
  double upload_ms = 0;        // copying the geometry into the vertex/index buffers
  double submit_ms = 0;        // upload, command recording, submission (upload_ms included)
  double wait_ms = 0;          // waiting for the device (lavapipe: the rasterisation itself)
  double thread_cpu_ms = 0;    // CPU time of the calling thread for the whole frame
  size_t triangles = 0;        // per view
  int views = 0;               // views drawn by the call
  bool cloth_rebuilt = false;  // the cloth's vertices were rebuilt and uploaded (else cached)
  bool text_rebuilt = false;   // the feedback panel's quads were rebuilt (its version changed)
};

// One view of a multi-view frame (e.g. an XR eye): where it looks from and what it draws into.
struct ViewTarget {
  View view;
  ColorTarget target;
};

class Renderer {
 public:
  // Creates its own instance and device (a GPU first, lavapipe otherwise).
  static sim::Result<std::unique_ptr<Renderer>> create(const RendererOptions& opt = {});
  // Runs on an instance/device created by someone else (XR_KHR_vulkan_enable2); never destroys
  // them. The caller must keep them alive longer than the renderer.
  static sim::Result<std::unique_ptr<Renderer>> create_on(const ExternalDevice& dev,
                                                          const RendererOptions& opt = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Draws into the caller's image and waits until it is done (the image may then be released
  // to the XR compositor or presented).
  Status render(const sim::SceneSnapshot& snap, const View& view, const ColorTarget& target,
                const DrawOptions& opt = {});
  // Draws the same snapshot into several views (both XR eyes) with one geometry build and
  // upload, one command buffer, one submission and one wait. The cloth's vertices are re-built
  // only when the snapshot's cloth (or the options that colour it) changed since the last call.
  Status render_views(const sim::SceneSnapshot& snap, const ViewTarget* views, int count,
                      const DrawOptions& opt = {});
  // Draws into the renderer's own target and reads it back.
  sim::Result<Image> render_offscreen(const sim::SceneSnapshot& snap, const View& view, int width,
                                      int height, const DrawOptions& opt = {});
  // The panel drawn by the following calls (until replaced; no lines: none). Its font is loaded
  // at the first panel with lines; when that fails the scene is drawn without the panel and
  // text_error() says why (naming the font file).
  void set_text_panel(const TextPanel& panel);
  const std::string& text_error() const;
  // Drops the cached image views/framebuffers of caller images (call before destroying them).
  void forget_targets();

  ValidationCounts validation() const;
  const std::string& device_name() const;
  bool is_cpu_device() const;
  bool device_lost() const;
  const FrameStats& last_frame() const;
  VulkanContext& context();
  // Test hook: behave as if the device had returned VK_ERROR_DEVICE_LOST.
  void simulate_device_lost();

 private:
  Renderer();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drape::render
