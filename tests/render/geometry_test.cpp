// CPU geometry: form normals point outward, cloth normals and strain from material coordinates,
// distance to the form, malformed snapshots.
#include "render/geometry.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/form/dress_form.hpp"
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

// Live hands (DrawOptions::hands): the 26-joint skeleton around its joints, the pointer marker
// at the pointer, a line to the hand's candidate particle; the snapshot's proxy of the same hand
// is not drawn twice; a non-finite pose is skipped.
// DrawOptions::markers (the app's calibration points): a sphere of the marker's colour, 1.5 cm in
// radius, around each finite marker; a non-finite one is skipped.
TEST(Geometry, MarkersAreSpheresOfTheirColour) {
  sim::SceneSnapshot s;
  DrawOptions opt;
  const Eigen::Vector3f at(0.3f, 0.0f, 0.4f);
  opt.markers = {{at, {0.2f, 0.9f, 0.3f}}, {Eigen::Vector3f(NAN, 0.0f, 0.0f), {1.0f, 1.0f, 1.0f}}};
  Mesh m;
  append_hand_overlays(s, opt, m);
  ASSERT_GT(m.vertices.size(), 0u);
  for (const Vertex& v : m.vertices) {
    const Eigen::Vector3f p(v.pos[0], v.pos[1], v.pos[2]);
    EXPECT_NEAR((p - at).norm(), 0.015f, 1e-4f);
    EXPECT_FLOAT_EQ(v.color[1], 0.9f);
  }
}

TEST(Geometry, HandOverlaysDrawSkeletonPointerAndCandidateLine) {
  sim::SceneSnapshot s;
  s.positions = {{0.0f, 1.0f, 0.2f}, {0.1f, 1.0f, 0.2f}, {0.0f, 1.1f, 0.2f}};
  s.candidate_vertex = {-1, 2};
  sim::HandProxy proxy;
  proxy.id = 1;
  proxy.tracked = true;
  proxy.position = sim::Vec3(0.3, 1.0, 0.4);
  s.hands.push_back(proxy);
  DrawOptions opt;
  Mesh none, with;
  append_decorations(s, opt, none);
  append_hand_overlays(s, opt, none);
  const size_t proxy_only = none.indices.size();
  EXPECT_GT(proxy_only, 0u);  // the snapshot's hand sphere
  HandOverlay h;
  h.id = 1;
  h.has_joints = true;
  for (int j = 0; j < 26; ++j) h.joints[j] = Eigen::Vector3f(0.2f + 0.004f * j, 1.0f, 0.5f);
  h.pointer = Eigen::Vector3f(0.25f, 1.0f, 0.45f);
  opt.hands = {h};
  append_decorations(s, opt, with);
  // The proxy sphere of hand 1 is replaced by the overlay (the candidate highlight stays).
  EXPECT_LT(with.indices.size(), proxy_only);
  EXPECT_GT(with.indices.size(), 0u);
  append_hand_overlays(s, opt, with);
  EXPECT_GT(with.indices.size(), 26u * 3u * 10u);  // 26 joint spheres + bones + pointer + line
  for (uint32_t i : with.indices) ASSERT_LT(i, with.vertices.size());
  // Vertices of the overlay alone: at the pointer (its marker) and at the candidate particle
  // (the end of the line from the pointer).
  Mesh only;
  append_hand_overlays(s, opt, only);
  float near_pointer = 1e9f, near_candidate = 1e9f;
  for (const Vertex& v : only.vertices) {
    const Eigen::Vector3f p(v.pos[0], v.pos[1], v.pos[2]);
    near_pointer = std::min(near_pointer, (p - h.pointer).norm());
    near_candidate = std::min(near_candidate, (p - s.positions[2]).norm());
  }
  std::printf("nearest overlay vertex to the pointer %.4f m, to the candidate %.4f m\n",
              near_pointer, near_candidate);
  EXPECT_LT(near_pointer, 0.0085f);
  EXPECT_LT(near_candidate, 0.002f);
  // A non-finite pose draws nothing.
  opt.hands[0].joints[3].x() = std::numeric_limits<float>::quiet_NaN();
  Mesh bad;
  append_hand_overlays(s, opt, bad);
  EXPECT_EQ(bad.indices.size(), 0u);
}

// The level of detail the XR app draws the form at: fewer angles and sections, the vertices still
// on the form's surface, every triangle (grid and both caps) counter-clockwise seen from outside.
TEST(Geometry, FormLevelOfDetailKeepsTheSurfaceAndTheWinding) {
  auto form = test::analytic_form();
  DrawOptions full_opt;
  Mesh full, lod;
  append_form(*form, 0.01f, full_opt, full);
  DrawOptions lod_opt;
  lod_opt.form_angle_step = 4;
  append_form(*form, 0.025f, lod_opt, lod);
  const size_t tri_full = full.indices.size() / 3, tri_lod = lod.indices.size() / 3;
  std::printf("form triangles: full %zu, LOD (every 4th angle, 25 mm) %zu\n", tri_full, tri_lod);
  EXPECT_LT(tri_lod * 8, tri_full);
  float worst = 0;
  int grid = 0, measured = 0;
  for (const Vertex& v : lod.vertices) {
    if (v.aux[0] != float(ShadeMode::kForm)) continue;
    ++grid;
    // (+inf just above the top section: float rounding of the top row's height)
    const float d = form_distance(*form, {v.pos[0], v.pos[1], v.pos[2]});
    if (!std::isfinite(d)) continue;
    ++measured;
    worst = std::max(worst, std::abs(d));
  }
  std::printf("%d grid vertices (%d angles), %d measured: worst distance from the surface %.2e m\n",
              grid, sim::DressForm::kAngles / 4, measured, worst);
  EXPECT_EQ(grid % (sim::DressForm::kAngles / 4), 0);
  EXPECT_GE(measured, grid - sim::DressForm::kAngles / 4);
  EXPECT_LT(worst, 1e-4f);
  for (const Mesh* m : {&full, &lod}) {
    int outward = 0, total = 0;
    for (size_t t = 0; t + 2 < m->indices.size(); t += 3) {
      const Vertex &a = m->vertices[m->indices[t]], &b = m->vertices[m->indices[t + 1]],
                   &c = m->vertices[m->indices[t + 2]];
      const Eigen::Vector3f pa(a.pos), pb(b.pos), pc(c.pos);
      const Eigen::Vector3f face = (pb - pa).cross(pc - pa);
      if (face.norm() < 1e-12f) continue;
      Eigen::Vector3f out;
      if (a.aux[0] == float(ShadeMode::kForm))  // the grid: away from the section centre
        out = Eigen::Vector3f((pa + pb + pc).x() / 3 - a.aux[1], 0,
                              (pa + pb + pc).z() / 3 - a.aux[2]);
      else  // a cap: along its normal (down at the bottom, up at the top)
        out = Eigen::Vector3f(a.normal);
      ++total;
      outward += face.dot(out) > 0;
    }
    std::printf("%d of %d triangles wound counter-clockwise seen from outside\n", outward, total);
    EXPECT_EQ(outward, total);
  }
}

TEST(Geometry, FormLevelOfDetailFollowsThePixelSize) {
  const float quarter_turn = 1.5707963f;
  const FormLod xr512 = form_lod_for_pixels(quarter_turn / 512, 8);
  const FormLod xr4k = form_lod_for_pixels(quarter_turn / 4096, 8);
  const FormLod xr64 = form_lod_for_pixels(quarter_turn / 64, 8);
  std::printf("512 px: %.4f m, step %d; 4096 px: %.4f m, step %d; 64 px: %.4f m, step %d\n",
              xr512.section_spacing, xr512.angle_step, xr4k.section_spacing, xr4k.angle_step,
              xr64.section_spacing, xr64.angle_step);
  // 8 px of 90/512 degrees at 1 m = 24.5 mm; 1.3 m / 64 angles = 20 mm fits, / 32 does not.
  EXPECT_NEAR(xr512.section_spacing, 8 * quarter_turn / 512, 1e-5f);
  EXPECT_EQ(xr512.angle_step, 4);
  EXPECT_FLOAT_EQ(xr4k.section_spacing, 0.008f);  // never finer than the default
  EXPECT_EQ(xr4k.angle_step, 1);
  EXPECT_FLOAT_EQ(xr64.section_spacing, 0.03f);  // never coarser than 3 cm
  EXPECT_EQ(xr64.angle_step, 4);
  const FormLod bad = form_lod_for_pixels(-1, 8);  // nonsense in: the full-detail default
  EXPECT_FLOAT_EQ(bad.section_spacing, 0.008f);
  EXPECT_EQ(bad.angle_step, 1);
}

}  // namespace
}  // namespace drape::render
