// Optional desktop mirror: a GLFW window showing one eye, presented through a Vulkan swapchain on
// the renderer's own device. Optional at run time: without a display (or GLFW) prepare() fails
// with a clear message and the caller simply carries on without a mirror.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "render/renderer.hpp"

namespace drape::render {

class MirrorWindow {
 public:
  // Initialises GLFW and returns the instance extensions a window surface needs: pass them in
  // RendererOptions::context.instance_extensions (and set context.swapchain) before creating the
  // renderer. Fails without a display or when built without GLFW.
  static sim::Result<std::vector<std::string>> prepare();
  static sim::Result<std::unique_ptr<MirrorWindow>> open(Renderer& renderer, int width, int height,
                                                         const std::string& title);
  ~MirrorWindow();
  MirrorWindow(const MirrorWindow&) = delete;
  MirrorWindow& operator=(const MirrorWindow&) = delete;

  // Draws one frame of `snap` as seen from `view` and presents it; handles resizes.
  Status show(const sim::SceneSnapshot& snap, const View& view, const DrawOptions& opt = {});
  bool should_close() const;
  int width() const;
  int height() const;
  int frames_presented() const;

 private:
  MirrorWindow();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drape::render
