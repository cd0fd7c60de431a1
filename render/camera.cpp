// Projection maths of render/camera.hpp.
#include "render/camera.hpp"

#include <cmath>

namespace drape::render {

Mat4f projection_from_fov(const Fov& fov, float n, float f) {
  const float l = std::tan(fov.angle_left), r = std::tan(fov.angle_right);
  const float u = std::tan(fov.angle_up), d = std::tan(fov.angle_down);
  Mat4f m = Mat4f::Zero();
  // x_ndc = (2 tan_x - (r + l)) / (r - l); Vulkan y_ndc grows downward; depth 0 at n, 1 at f.
  m(0, 0) = 2.0f / (r - l);
  m(0, 2) = (r + l) / (r - l);
  m(1, 1) = -2.0f / (u - d);
  m(1, 2) = -(u + d) / (u - d);
  m(2, 2) = f / (n - f);
  m(2, 3) = n * f / (n - f);
  m(3, 2) = -1.0f;
  return m;
}

Fov symmetric_fov(float fov_y, float aspect) {
  const float ty = std::tan(0.5f * fov_y), tx = ty * aspect;
  return Fov{-std::atan(tx), std::atan(tx), std::atan(ty), -std::atan(ty)};
}

View make_view(const Pose& pose, const Fov& fov, float near_m, float far_m) {
  View v;
  const Eigen::Matrix3f rt = pose.orientation.normalized().toRotationMatrix().transpose();
  v.view.setIdentity();
  v.view.topLeftCorner<3, 3>() = rt;
  v.view.topRightCorner<3, 1>() = -rt * pose.position;
  v.projection = projection_from_fov(fov, near_m, far_m);
  v.eye = pose.position;
  return v;
}

View look_at(const Vec3f& eye, const Vec3f& target, float fov_y, float aspect, float near_m,
             float far_m) {
  const Vec3f z = (eye - target).normalized();  // camera looks down -z
  Vec3f x = Vec3f::UnitY().cross(z);
  if (x.norm() < 1e-6f) x = Vec3f::UnitX();
  x.normalize();
  const Vec3f y = z.cross(x);
  Eigen::Matrix3f r;
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = z;
  Pose p{Eigen::Quaternionf(r), eye};
  return make_view(p, symmetric_fov(fov_y, aspect), near_m, far_m);
}

std::optional<Eigen::Vector2f> project_to_pixel(const View& view, const Vec3f& p, int width,
                                                int height) {
  const Eigen::Vector4f c = view.view_proj() * p.homogeneous();
  if (c.w() <= 1e-6f) return std::nullopt;
  const float xn = c.x() / c.w(), yn = c.y() / c.w();
  return Eigen::Vector2f((xn + 1.0f) * 0.5f * width, (yn + 1.0f) * 0.5f * height);
}

}  // namespace drape::render
