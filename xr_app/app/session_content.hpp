// The seam between the OpenXR program (xr_program.cpp) and what its sessions show and drive:
// the draping session (draping_session.hpp: the simulation, the interaction, the renderer) in
// builds with the renderer and the simulation; none otherwise (no_draping_session.cpp), and then
// the frame loop submits its swapchain images undrawn.
#pragma once

#include <cstdint>
#include <memory>

#include "xr_app/app/profiling.hpp"
#include "xr_app/app/xr_graphics.hpp"
#include "xr_app/app/xr_input.hpp"

namespace drape::app {

// The eyes' clip planes (m): what the depth images hold, 0 at kNearZ to 1 at kFarZ
// (XrCompositionLayerDepthInfoKHR).
constexpr float kNearZ = 0.05f, kFarZ = 50.0f;

// One eye of a frame: its located view, the swapchain image to draw into and, where the
// runtime takes depth (XR_KHR_composition_layer_depth), the depth swapchain image to store the
// depth into (else null).
struct EyeTarget {
  XrView view{XR_TYPE_VIEW};
  VkImage image = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  uint32_t width = 0, height = 0;
  VkImage depth_image = VK_NULL_HANDLE;
  VkFormat depth_format = VK_FORMAT_UNDEFINED;
};

class SessionContent {
 public:
  virtual ~SessionContent() = default;
  // Each frame, in this order; `frame` is the session's frame index (the scenario's).
  virtual void frame_started() = 0;  // after xrWaitFrame
  virtual void interact(int64_t frame, const HandInput& in) = 0;
  // The views are located: waits (bounded) for the snapshot holding this frame's hand pose.
  virtual void wait_for_pose(int64_t frame) = 0;
  // Pose-to-photon probes of the snapshot about to be drawn.
  virtual void record_probes(int64_t frame) = 0;
  // Draws both eyes (their images acquired); the renderer's stage times go into laps.
  virtual void draw(int64_t frame, const EyeTarget (&eyes)[2], FrameLaps& laps) = 0;
  virtual void frame_ended(Clock::time_point end) = 0;  // xrEndFrame returned
  // Before the swapchains are destroyed (the session ends).
  virtual void forget_targets() = 0;
  // The runtime lost the session (LOSS_PENDING); a new one follows, with the hands elsewhere.
  virtual void session_lost() {}
  // The run ends: outcomes into the result, files into out_dir.
  virtual void finish() = 0;
};

// The draping session on the runtime's device; nullptr where the build has none or when
// opt.render is false, and on failure (rep.r.error says why).
std::unique_ptr<SessionContent> make_draping_session(const VulkanDevice& device,
                                                     const XrAppOptions& opt, Report& rep);

}  // namespace drape::app
