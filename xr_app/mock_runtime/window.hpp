// Window mode of the mock runtime (DRAPE_MOCK_WINDOW=1): a desktop window (GLFW, X11) that shows
// the projection layer the app submits and turns mouse and keyboard into what a headset sends:
// the head pose, both hands as XR_EXT_hand_tracking joints and as the controllers of the
// interaction profile it publishes. It is one more input source: it writes the live state into
// the instance's Scenario as one key per track, and the runtime samples that exactly as it
// samples a scripted scenario. Keys and mouse: docs/mock-window.md.
#pragma once

#include <memory>
#include <string>

#include "xr_app/mock_runtime/runtime.hpp"

namespace drape::mock {

// DRAPE_MOCK_WINDOW is set to 1 (other values than "" and "0" are an error in the log and off).
bool window_requested();

// Opens the session's window (its own thread). Null and *why on failure (no display, ...).
std::shared_ptr<Window> open_window(Session* s, std::string* why);

// xrWaitFrame of frame `frame` (under g_lock): takes the input since the last frame, moves the
// head and the hands, switches the profile, ends the session on Escape or when the window is
// closed, and writes the log line of DRAPE_MOCK_WINDOW_LOG.
void window_wait_frame(Session* s, int64_t frame);

// xrEndFrame (under g_lock): reads back the layer for the window and, when the layer carries
// XrCompositionLayerDepthInfoKHR, the depth under the cursor.
void window_end_frame(Session* s, const XrCompositionLayerProjection* layer);

// The view-space distance (metres along -z) of a depth value d of a depth swapchain described
// by an XrCompositionLayerDepthInfoKHR: 1/z is affine in d, from 1/nearZ at minDepth to 1/farZ
// at maxDepth (nearZ > farZ for reversed depth, farZ may be +inf). Returns +inf for the far
// plane (nothing drawn).
float depth_to_distance(float d, float min_depth, float max_depth, float near_z, float far_z);

}  // namespace drape::mock
