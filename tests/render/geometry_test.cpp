// CPU geometry: form normals point outward, cloth normals and strain from material coordinates,
// distance to the form, malformed snapshots.
#include "render/geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "sim/dress_form.hpp"
#include "test_scenes.hpp"

namespace drape::render {
namespace {

TEST(Geometry, FormGridNormalsPointOutward) {
  auto form = test::analytic_form();
  Mesh m;
  DrawOptions opt;
  append_form(*form, 0.01f, opt, m);
  ASSERT_GT(m.vertices.size(), 1000u);
  int checked = 0, outward = 0;
  for (const Vertex& v : m.vertices) {
    if (v.aux[0] != float(ShadeMode::kForm)) continue;
    const Eigen::Vector3f radial(v.pos[0] - v.aux[1], 0, v.pos[2] - v.aux[2]);
    const Eigen::Vector3f n(v.normal[0], v.normal[1], v.normal[2]);
    EXPECT_NEAR(n.norm(), 1.0f, 1e-4f);
    ++checked;
    outward += n.dot(radial) > 0;
  }
  std::printf("%d of %d form normals point outward\n", outward, checked);
  EXPECT_EQ(outward, checked);
  for (uint32_t i : m.indices) ASSERT_LT(i, m.vertices.size());
}

TEST(Geometry, FormDistanceMatchesSectionRadius) {
  auto form = test::analytic_form();
  // On the section at index 40, angle index 32 (theta = pi/4): radius r.
  const int j = 40, n = 32;
  const double r = form->radius(j, n), th = sim::DressForm::theta(n);
  const Eigen::Vector3f p(float((r + 0.03) * std::sin(th)), float(form->section_y(j)),
                          float((r + 0.03) * std::cos(th)));
  const float d = form_distance(*form, p);
  std::printf("distance %.6f (expected 0.03)\n", d);
  EXPECT_NEAR(d, 0.03f, 1e-5f);
  EXPECT_TRUE(std::isinf(form_distance(*form, {0, 2.0f, 0})));
}

TEST(Geometry, StretchedPanelStrainAndNormals) {
  sim::SceneSnapshot s;
  test::add_panel(s, 5, 4, 0.4f, 0.3f, 0, 0, 0, 0);
  // Stretch 10 % along u (x): strain +0.10 everywhere.
  for (auto& p : s.positions) p.x() *= 1.1f;
  std::vector<float> strain;
  material_strain(s.positions, s.material, s.indices, strain);
  for (float e : strain) EXPECT_NEAR(e, 0.10f, 1e-5f);
  // Compress 20 % along v: the furthest stretch from 1 wins -> -0.2.
  for (auto& p : s.positions) p.y() *= 0.8f;
  material_strain(s.positions, s.material, s.indices, strain);
  for (float e : strain) EXPECT_NEAR(e, -0.20f, 1e-5f);
  std::vector<sim::Vec3f> normals;
  vertex_normals(s.positions, s.indices, normals);
  for (const auto& n : normals) EXPECT_NEAR(std::abs(n.z()), 1.0f, 1e-5f);
}

TEST(Geometry, ClothSkipsBadTrianglesAndMapsEase) {
  sim::SceneSnapshot s;
  s.form = test::analytic_form();
  s.positions = {{0, 1.0f, 0.5f}, {0.1f, 1.0f, 0.5f}, {0, 1.1f, 0.5f}};
  s.material = {{0, 0}, {0.1f, 0}, {0, 0.1f}};
  s.indices = {0, 1, 2, 0, 1, 99};
  DrawOptions opt;
  opt.colour_map = ColourMap::kEase;
  opt.ease_range = 1.0f;
  Mesh m;
  append_cloth(s, opt, m);
  EXPECT_EQ(m.indices.size(), 3u);
  const float ease = form_distance(*s.form, s.positions[0]);
  EXPECT_NEAR(m.vertices[0].aux[3], ease, 1e-6f);
  EXPECT_GT(ease, 0.3f);
}

TEST(Geometry, DecorationsForEveryElement) {
  sim::SceneSnapshot s = test::decorated_scene();
  DrawOptions opt;
  Mesh all, none;
  append_decorations(s, opt, all);
  opt.pattern_panel = false;
  s.hands.clear();
  s.pins.clear();
  append_decorations(s, opt, none);
  EXPECT_GT(all.indices.size(), none.indices.size());
  for (uint32_t i : all.indices) ASSERT_LT(i, all.vertices.size());
}

}  // namespace
}  // namespace drape::render
