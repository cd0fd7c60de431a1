// Projection maths: XR field-of-view edges land on the image edges, look-at centres its target.
#include "render/camera.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace drape::render {
namespace {

TEST(Camera, FovEdgesMapToImageEdges) {
  const Fov fov{-0.9f, 0.4f, 0.7f, -0.3f};
  Pose pose;  // at the origin looking down -z
  const View v = make_view(pose, fov, 0.1f, 10.0f);
  const int w = 200, h = 100;
  const float d = 2.0f;  // a point at 2 m on each edge ray
  auto left = project_to_pixel(v, {d * std::tan(fov.angle_left), 0, -d}, w, h);
  auto right = project_to_pixel(v, {d * std::tan(fov.angle_right), 0, -d}, w, h);
  auto up = project_to_pixel(v, {0, d * std::tan(fov.angle_up), -d}, w, h);
  auto down = project_to_pixel(v, {0, d * std::tan(fov.angle_down), -d}, w, h);
  ASSERT_TRUE(left && right && up && down);
  std::printf("left x %.5f right x %.5f up y %.5f down y %.5f\n", left->x(), right->x(), up->y(),
              down->y());
  EXPECT_NEAR(left->x(), 0.0f, 1e-3f);
  EXPECT_NEAR(right->x(), float(w), 1e-3f);
  EXPECT_NEAR(up->y(), 0.0f, 1e-3f);  // image rows go down: up is row 0
  EXPECT_NEAR(down->y(), float(h), 1e-3f);
  EXPECT_FALSE(project_to_pixel(v, {0, 0, 1}, w, h));  // behind the eye
}

TEST(Camera, DepthRangeIsZeroToOne) {
  const Mat4f p = projection_from_fov(Fov{}, 0.1f, 10.0f);
  for (float z : {0.1f, 10.0f}) {
    const Eigen::Vector4f c = p * Eigen::Vector4f(0, 0, -z, 1);
    std::printf("z %.1f -> depth %.6f\n", z, c.z() / c.w());
    EXPECT_NEAR(c.z() / c.w(), z == 0.1f ? 0.0f : 1.0f, 1e-5f);
  }
}

TEST(Camera, LookAtCentresTargetAndPoseRotates) {
  const View v = look_at({1, 2, 3}, {0, 1, 0}, 0.8f, 1.5f);
  auto c = project_to_pixel(v, {0, 1, 0}, 300, 200);
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->x(), 150.0f, 1e-3f);
  EXPECT_NEAR(c->y(), 100.0f, 1e-3f);
  // A point above the target is higher in the image (smaller row).
  auto above = project_to_pixel(v, {0, 1.1f, 0}, 300, 200);
  ASSERT_TRUE(above);
  EXPECT_LT(above->y(), c->y());
  // An eye turned 90 degrees left (about +y) sees -x straight ahead.
  Pose p;
  p.orientation = Eigen::AngleAxisf(1.5707963f, Eigen::Vector3f::UnitY());
  const View t = make_view(p, symmetric_fov(1.0f, 1.0f));
  auto ahead = project_to_pixel(t, {-3, 0, 0}, 100, 100);
  ASSERT_TRUE(ahead);
  EXPECT_NEAR(ahead->x(), 50.0f, 1e-3f);
  EXPECT_NEAR(ahead->y(), 50.0f, 1e-3f);
}

}  // namespace
}  // namespace drape::render
