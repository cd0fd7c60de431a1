// Views and projections for the renderer: from an OpenXR field of view and pose (per eye) or a
// look-at camera (screenshots). Vulkan conventions: clip y points down, depth 0 (near) .. 1 (far).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

namespace drape::render {

using Vec3f = Eigen::Vector3f;
using Mat4f = Eigen::Matrix4f;

// XrFovf: angles in radians, left and down negative for a centred eye.
struct Fov {
  float angle_left = -0.7f, angle_right = 0.7f, angle_up = 0.7f, angle_down = -0.7f;
};

// XrPosef in stage space: the eye looks down its local -z, local +y is up.
struct Pose {
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
  Vec3f position = Vec3f::Zero();
};

struct View {
  Mat4f view = Mat4f::Identity();        // stage -> eye
  Mat4f projection = Mat4f::Identity();  // eye -> Vulkan clip
  Vec3f eye = Vec3f::Zero();             // eye position in stage space
  Mat4f view_proj() const { return projection * view; }
};

// Asymmetric projection from an XR field of view (as xrLocateViews returns it).
Mat4f projection_from_fov(const Fov& fov, float near_m, float far_m);
// Symmetric field of view with the given vertical angle (rad) and aspect (width / height).
Fov symmetric_fov(float fov_y, float aspect);
// The view of an eye at `pose` with `fov`.
View make_view(const Pose& pose, const Fov& fov, float near_m = 0.05f, float far_m = 50.0f);
// A camera at `eye` looking at `target` (stage up +y).
View look_at(const Vec3f& eye, const Vec3f& target, float fov_y, float aspect, float near_m = 0.05f,
             float far_m = 50.0f);
// Pixel coordinates (x right, y down, pixel centres at +0.5) of a stage-space point in an image
// of width x height; nothing when it is behind the eye.
std::optional<Eigen::Vector2f> project_to_pixel(const View& view, const Vec3f& p, int width,
                                                int height);

}  // namespace drape::render
