// Builds without the renderer and the simulation have no draping session: the frame loop
// submits its swapchain images undrawn.
#include "xr_app/app/session_content.hpp"

namespace drape::app {

std::unique_ptr<SessionContent> make_draping_session(const VulkanDevice&, const XrAppOptions&,
                                                     Report&) {
  return nullptr;
}

}  // namespace drape::app
