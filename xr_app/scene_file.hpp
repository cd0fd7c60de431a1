// Scene files for `drape render --scene FILE` (JSON, documented in docs/rendering.md) and the
// default scene (muslin draped on the 9AR form): a SceneSnapshot, a camera and draw options.
#pragma once

#include <optional>
#include <string>

#include "render/camera.hpp"
#include "render/geometry.hpp"
#include "sim/core/snapshot.hpp"

namespace drape::app {

struct CameraSpec {
  // Look-at camera (default: in front of the form, a little to its left, at eye height).
  Eigen::Vector3f eye{0.55f, 1.50f, 1.90f};
  Eigen::Vector3f target{0.0f, 1.02f, 0.0f};
  float fov_y_deg = 38.0f;
  // Or an XR eye: field of view (radians, XrFovf) and pose (XrPosef) — used when set.
  std::optional<render::Fov> xr_fov;
  render::Pose xr_pose;
  render::View view(int width, int height) const;
};

struct SceneDescription {
  sim::SceneSnapshot snapshot;
  CameraSpec camera;
  render::DrawOptions options;
  int samples = 4;      // MSAA for screenshots
  std::string summary;  // what was built (printed by the command)
};

// Reads a scene file; errors name the file and the field ("scene.json: cloth.indices[5]: ...").
sim::Result<SceneDescription> load_scene(const std::string& path);
// The same from JSON text; relative paths inside are resolved against `base_dir`.
sim::Result<SceneDescription> parse_scene(const std::string& json_text, const std::string& source,
                                          const std::string& base_dir = ".");
// The default scene: a 1 m square of muslin dropped over the 9AR form and simulated until it
// hangs (`sim_seconds` of simulated time, solver `solver`), with grain lines.
sim::Result<SceneDescription> default_scene(double sim_seconds = 2.5,
                                            const std::string& solver = "xpbd", int grid = 81);

}  // namespace drape::app
