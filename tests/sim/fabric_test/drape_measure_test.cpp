// The drape-test measurement on analytic outlines: a circle's DC is known exactly, a
// cosine-modulated outline with k lobes has k nodes, and R(theta) follows the outline.
#include "sim/fabric_test/drape_measure.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace drape::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Outline r(theta) = r0 + a cos(k theta + phase), sampled at 0.1 degree.
std::vector<Vec2> lobed(double r0, double a, int k, double phase = 0) {
  std::vector<Vec2> p;
  for (int q = 0; q < 3600; ++q) {
    const double t = 2 * kPi * q / 3600;
    const double r = r0 + a * std::cos(k * t + phase);
    p.emplace_back(r * std::cos(t), r * std::sin(t));
  }
  return p;
}

DrapeMeasures measure(const std::vector<Vec2>& outline) {
  ShadowRaster r;
  r.reset(0.16, 0.0005);
  rasterize_polygon(outline, r);
  fill_holes(r);
  return measure_shadow(r, DrapeMeasureOptions{});
}

TEST(DrapeMeasure, CircleHasTheDcOfItsArea) {
  // DC of a circle of radius rc: (rc^2 - 0.09^2) / (0.15^2 - 0.09^2).
  for (double rc : {0.09, 0.12, 0.15}) {
    const DrapeMeasures m = measure(lobed(rc, 0, 1));
    const double exact = (rc * rc - 0.09 * 0.09) / (0.15 * 0.15 - 0.09 * 0.09);
    EXPECT_NEAR(m.dc, exact, 2e-3) << rc;
    EXPECT_EQ(m.nodes, 0) << rc;
    EXPECT_NEAR(m.r_min, rc, 0.001);
    EXPECT_NEAR(m.r_max, rc, 0.001);
  }
}

TEST(DrapeMeasure, CosineOutlineWithKLobesHasKNodes) {
  for (int k : {5, 6, 8, 9, 12}) {
    const DrapeMeasures m = measure(lobed(0.125, 0.015, k, 0.3));
    EXPECT_EQ(m.nodes, k) << k;
    EXPECT_NEAR(m.r_min, 0.110, 0.001) << k;
    EXPECT_NEAR(m.r_max, 0.140, 0.001) << k;
  }
}

TEST(DrapeMeasure, LobesBelowTheProminenceAreNotNodes) {
  // 1 mm ripples on a 3-lobe outline: the ripples (prominence < 3 mm) are not counted.
  std::vector<Vec2> p;
  for (int q = 0; q < 3600; ++q) {
    const double t = 2 * kPi * q / 3600;
    const double r = 0.12 + 0.01 * std::cos(3 * t) + 0.001 * std::cos(40 * t);
    p.emplace_back(r * std::cos(t), r * std::sin(t));
  }
  EXPECT_EQ(measure(p).nodes, 3);
}

TEST(DrapeMeasure, HolesInTheShadowAreFilled) {
  ShadowRaster r;
  r.reset(0.16, 0.0005);
  rasterize_polygon(lobed(0.14, 0, 1), r);
  const double full = r.area();
  // Clear a square hole in the middle: the shadow's area is the same once holes are filled.
  for (int j = r.size / 2 - 20; j < r.size / 2 + 20; ++j)
    for (int i = r.size / 2 - 20; i < r.size / 2 + 20; ++i) r.cells[j * r.size + i] = 0;
  EXPECT_LT(r.area(), full);
  fill_holes(r);
  EXPECT_DOUBLE_EQ(r.area(), full);
}

TEST(DrapeMeasure, ProfileFollowsTheOutlineAngle) {
  // One lobe at 90 degrees (+w, the warp): the node is there, R(90) = 0.13 and R(270) = 0.11.
  const DrapeMeasures m = measure(lobed(0.12, 0.01, 1, -kPi / 2));
  ASSERT_EQ(m.nodes, 1);
  EXPECT_NEAR(m.node_bins[0], 90, 2);
  EXPECT_NEAR(m.profile[90], 0.13, 0.001);
  EXPECT_NEAR(m.profile[270], 0.11, 0.001);
}

TEST(DrapeMeasure, MeshShadowMatchesThePolygonShadow) {
  // A flat disc of triangles (a fan) casts the same shadow as its polygon.
  TriMesh fan;
  fan.vertices.emplace_back(0, 0, 0);
  const auto ring = lobed(0.13, 0, 1);
  for (size_t q = 0; q < ring.size(); q += 10)
    fan.vertices.emplace_back(ring[q].x(), 0, -ring[q].y());
  const int n = static_cast<int>(fan.vertices.size()) - 1;
  for (int q = 0; q < n; ++q) fan.triangles.push_back({0, 1 + q, 1 + (q + 1) % n});
  ShadowRaster a;
  a.reset(0.16, 0.0005);
  rasterize_mesh(fan, a);
  fill_holes(a);
  EXPECT_NEAR(a.area(), kPi * 0.13 * 0.13, 2e-5);
}

}  // namespace
}  // namespace drape::sim
