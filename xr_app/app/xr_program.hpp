// The OpenXR program (hello_xr's "program"): the instance and system, the session lifecycle as
// a state machine (a missing runtime and a lost session are ordinary states), the event queue
// and the frame loop. Graphics, input and the session's content are its parts.
#pragma once

#include <memory>

#include "xr_app/app/session_content.hpp"
#include "xr_app/app/xr_graphics.hpp"
#include "xr_app/app/xr_input.hpp"

namespace drape::app {

class XrProgram {
 public:
  XrProgram(const XrAppOptions& opt, XrAppResult* res);
  ~XrProgram();
  XrProgram(const XrProgram&) = delete;
  XrProgram& operator=(const XrProgram&) = delete;

  // Runs to EXITING, a failure, or a missing runtime.
  void run();
  XrAppState state() const { return state_; }

 private:
  void set_state(XrAppState s);
  bool create_instance();
  bool offers_debug_utils_through_layers();
  void create_debug_messenger();
  bool get_system();
  bool create_device_and_content();
  bool create_session();
  void destroy_session();
  void teardown();
  bool handle_events();  // false: leave the loop
  bool on_session_state(XrSessionState s);
  bool frame();
  // Locates the views and renders both eyes; layer_count 1 when a projection layer is ready.
  bool render_layer(const XrFrameState& fs, int64_t frame, FrameLaps& laps, uint32_t& layer_count);

  XrAppOptions opt_;
  Report rep_;
  XrAppState state_ = XrAppState::kNoRuntime;
  XrInstance instance_ = XR_NULL_HANDLE;
  XrSystemId system_ = XR_NULL_SYSTEM_ID;
  XrDebugUtilsMessengerEXT messenger_ = XR_NULL_HANDLE;
  bool has_hands_ext_ = false, has_debug_ext_ = false;
  bool has_depth_ext_ = false;  // XR_KHR_composition_layer_depth: the eyes' depth is submitted
  XrGraphics graphics_;
  XrInput input_;
  std::unique_ptr<SessionContent> content_;
  XrSession session_ = XR_NULL_HANDLE;
  bool running_ = false;
  bool exit_requested_ = false;
  XrSpace space_ = XR_NULL_HANDLE;
  int64_t session_frame_ = 0;  // xrWaitFrame calls in this session (the scenario's frame index)
  XrCompositionLayerProjectionView views_[2] = {{XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW},
                                                {XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW}};
  XrCompositionLayerDepthInfoKHR depth_[2] = {{XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR},
                                              {XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR}};
  XrCompositionLayerProjection layer_{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
};

}  // namespace drape::app
