// Scene files: every element parsed; bad input gives errors that name the file and field.
#include "xr_app/scene_file.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

namespace drape::app {
namespace {

using render::ColourMap;
using render::View;

const char* kScene = R"({
  "cloth": {"positions": [[0,1,0],[0.1,1,0],[0,1.1,0]], "indices": [0,1,2],
            "material": [[0,0],[0.1,0],[0,0.1]], "strain": [0, 0.01, -0.02]},
  "plates": [{"centre": [0, 0.8, 0], "half_x": 0.3, "half_z": 0.2}],
  "boxes": [{"centre": [0, 0.9, 0], "half": [0.1, 0.1, 0.1]}],
  "spheres": [{"centre": [0, 1, 0], "radius": 0.2}],
  "hands": [{"id": 1, "position": [0.2, 1.2, 0.3], "tip": [0.2, 1.25, 0.3], "radius": 0.03}],
  "pins": [[0, 1.1, 0]],
  "cut_strokes": [[[0, 1, 0.1], [0.1, 1, 0.1]]],
  "pattern_outlines": [[[0, 0], [0.5, 0], [0.5, 0.5]]],
  "candidates": [{"hand": 0, "vertex": 2}, {"hand": 1, "point": [0, 1, 0.1]}],
  "camera": {"eye": [0, 1.5, 2], "target": [0, 1, 0], "fov_y_deg": 45},
  "options": {"colour_map": "strain", "grain": false, "floor": false, "samples": 1}
})";

TEST(SceneFile, ParsesEveryElement) {
  auto d = parse_scene(kScene, "test.json");
  ASSERT_TRUE(d.ok()) << d.error();
  const auto& s = d->snapshot;
  EXPECT_EQ(s.positions.size(), 3u);
  EXPECT_EQ(s.indices.size(), 3u);
  EXPECT_EQ(s.material.size(), 3u);
  EXPECT_FLOAT_EQ(s.strain[2], -0.02f);
  EXPECT_EQ(s.plates.size(), 1u);
  EXPECT_DOUBLE_EQ(s.plates[0].half_z, 0.2);
  EXPECT_EQ(s.boxes.size(), 1u);
  EXPECT_EQ(s.spheres.size(), 1u);
  ASSERT_EQ(s.hands.size(), 1u);
  EXPECT_EQ(s.hands[0].id, 1);
  EXPECT_TRUE(s.hands[0].tracked);
  EXPECT_EQ(s.pins.size(), 1u);
  EXPECT_EQ(s.cut_strokes[0].size(), 2u);
  EXPECT_EQ(s.pattern_outlines[0].size(), 3u);
  EXPECT_EQ(s.candidate_vertex[0], 2);
  EXPECT_TRUE(s.candidate_is_form[1]);
  EXPECT_FLOAT_EQ(d->camera.fov_y_deg, 45.0f);
  EXPECT_EQ(d->options.colour_map, render::ColourMap::kStrain);
  EXPECT_FALSE(d->options.grain);
  EXPECT_FALSE(d->options.floor_grid);
  EXPECT_EQ(d->samples, 1);
}

TEST(SceneFile, XrCameraGivesAsymmetricProjection) {
  auto d = parse_scene(R"({"camera": {"xr": {"fov": {"angleLeft": -0.8, "angleRight": 0.6,
      "angleUp": 0.7, "angleDown": -0.75}, "position": [0, 1.6, 1], "orientation": [0, 0, 0, 1]}}})",
                       "xr.json");
  ASSERT_TRUE(d.ok()) << d.error();
  ASSERT_TRUE(d->camera.xr_fov.has_value());
  const render::View v = d->camera.view(100, 100);
  EXPECT_NEAR(v.eye.y(), 1.6f, 1e-6f);
  EXPECT_GT(v.projection(0, 2), 0.0f - 1.0f);  // asymmetric: off-centre term present
  EXPECT_NE(v.projection(0, 2), 0.0f);
}

void expect_error(const std::string& json, const std::string& needle) {
  auto d = parse_scene(json, "bad.json");
  ASSERT_FALSE(d.ok()) << json;
  std::printf("%s\n", d.error().c_str());
  EXPECT_NE(d.error().find("bad.json"), std::string::npos);
  EXPECT_NE(d.error().find(needle), std::string::npos) << d.error();
}

TEST(SceneFile, BadInputNamesTheField) {
  expect_error("{", "invalid JSON");
  expect_error("[1, 2]", "expected a JSON object");
  expect_error(R"({"cloth": {"positions": [[0,0,0]], "indices": [0, 0, 5]}})", "cloth.indices[2]");
  expect_error(R"({"cloth": {"positions": [[0,0,"x"]], "indices": []}})", "cloth.positions[0][2]");
  expect_error(R"({"cloth": {"positions": [[0,0,0]], "indices": [0, 0]}})", "multiple of 3");
  expect_error(R"({"cloth": {"indices": []}})", "missing or mistyped");
  expect_error(R"({"plates": [{"half_x": -1}]})", "plates[0].half_x");
  expect_error(R"({"spheres": [{"radius": 0}]})", "spheres[0].radius");
  expect_error(R"({"camera": {"eye": [0, 1, 0], "target": [0, 1, 0]}})", "camera");
  expect_error(R"({"camera": {"xr": {"fov": {"angleLeft": 0.5, "angleRight": -0.5,
       "angleUp": 0.5, "angleDown": -0.5}}}})",
               "camera.xr.fov");
  expect_error(R"({"options": {"colour_map": "rainbow"}})", "options.colour_map");
  expect_error(R"({"candidates": [{"hand": 0, "vertex": 3}]})", "candidates[0].vertex");
  expect_error(R"({"form": {"size": "99XX"}})", "form.size");
  expect_error(R"({"form": {"colour": 1}})", "form");
}

// The default scene of `drape render` drapes with the app's solver (XPBD) and friction on the
// form: the muslin hangs from the shoulders instead of sliding off (without friction it slid
// down the form and off its hips within 1.5 s).
TEST(SceneFile, DefaultSceneHangsOnTheForm) {
  auto d = default_scene(2.5, "xpbd", 41);
  ASSERT_TRUE(d) << d.error();
  const auto& x = d->snapshot.positions;
  ASSERT_EQ(x.size(), 41u * 41u);
  float top = -1e9f, bottom = 1e9f, r2max = 0;
  for (const auto& p : x) {
    ASSERT_TRUE(std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()));
    top = std::max(top, p.y());
    bottom = std::min(bottom, p.y());
    r2max = std::max(r2max, p.x() * p.x() + p.z() * p.z());
  }
  // The 9AR form's neck base is at 1.35 m, its shoulders ~1.3 m: the panel rests there.
  EXPECT_GT(top, 1.25f);
  // A 1 m square hanging from the shoulders reaches no lower than ~0.7 m and stays within
  // ~0.8 m of the form's axis.
  EXPECT_GT(bottom, 0.5f);
  EXPECT_LT(std::sqrt(r2max), 0.8f);
}

TEST(SceneFile, MissingFileIsAnError) {
  auto d = load_scene("/nonexistent/scene.json");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().find("/nonexistent/scene.json"), std::string::npos);
}

}  // namespace
}  // namespace drape::app
