// The in-view feedback: Feedback's lines and versions (refusals expiring, the first seconds'
// help, the help built from the command map), and the app end to end on the simulated runtime
// in lock step: a pinch with nothing within reach puts its refusal into the feedback and into
// the drawn frame (the panel's part of the screenshot differs from the same frame without it).
#include "xr_app/app/feedback.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "render/image_io.hpp"
#include "render/text.hpp"
#include "xr_app/app/xr_app.hpp"

namespace fs = std::filesystem;
using drape::app::Feedback;

namespace {

bool contains(const std::vector<std::string>& lines, const std::string& s) {
  for (const auto& l : lines)
    if (l.find(s) != std::string::npos) return true;
  return false;
}

TEST(Feedback, RefusalsShowForAFewSecondsAndTheVersionFollows) {
  Feedback f;
  const uint64_t v0 = f.shown_version(0);
  f.refused(10, "pinch: nothing within 3 cm of the right hand to pinch");
  EXPECT_NE(f.shown_version(10), v0);
  EXPECT_TRUE(contains(f.lines(10), "nothing within 3 cm"));
  const uint64_t shown = f.shown_version(10 + Feedback::kRefusalFrames - 1);
  EXPECT_EQ(shown, f.shown_version(10));  // nothing changed while it shows
  const int64_t gone = 10 + Feedback::kRefusalFrames;
  EXPECT_FALSE(contains(f.lines(gone), "nothing within 3 cm"));
  EXPECT_NE(f.shown_version(gone), shown);  // ... and its expiry is a change
  f.set_operation(1, "pinching particle 7");
  EXPECT_TRUE(contains(f.lines(gone), "right hand: pinching particle 7"));
}

TEST(Feedback, HelpFromTheCommandMapAndForTheFirstSeconds) {
  Feedback f;
  const auto help = drape::app::help_lines(drape::tracking::CommandMap::defaults());
  ASSERT_GT(help.size(), 5u);
  EXPECT_TRUE(contains(help, "gesture pinch begin: pinch begin")) << help[1];
  f.set_help(help);
  EXPECT_FALSE(contains(f.lines(0), "gesture pinch begin"));
  f.show_help_until(720);
  EXPECT_TRUE(contains(f.lines(719), "gesture pinch begin"));
  EXPECT_FALSE(contains(f.lines(720), "gesture pinch begin"));
  EXPECT_NE(f.shown_version(719), f.shown_version(720));
  f.show_help(true);  // held: shown whatever the frame
  EXPECT_TRUE(contains(f.lines(5000), "gesture pinch begin"));
}

#ifdef DRAPE_XR_TEST_WITH_RENDER
const std::string kManifest = std::string(DRAPE_BINARY_DIR) + "/bin/drape_mock_runtime.json";

// Runs a lock-step session of the scenario (the right hand away from the cloth, pinching or
// not), writing the left eye's frames to dir/frames.
drape::app::XrAppResult run(const fs::path& dir, bool pinch) {
  for (const char* v : {"DRAPE_MOCK_END_AFTER_FRAMES", "DRAPE_MOCK_LOSE_SESSION_AT_FRAME",
                        "XR_ENABLE_API_LAYERS", "DRAPE_MOCK_WRITE_EVERY"})
    unsetenv(v);
  fs::remove_all(dir);
  fs::create_directories(dir / "frames");
  const std::string sc = (dir / "scenario.json").string();
  const char* p = pinch ? "1.0" : "0.0";
  std::ofstream(sc) << R"({"name": "refusal", "end_after_frames": 40, "fast": true,
    "head": [{"frame": 0, "position": [0.0, 1.3, 1.2]}],
    "hands": {"right": [
      {"frame": 0, "palm": {"position": [0.35, 1.55, 0.9]}, "pinch": 0.0},
      {"frame": 10, "palm": {"position": [0.35, 1.55, 0.9]}, "pinch": 0.0},
      {"frame": 14, "palm": {"position": [0.35, 1.55, 0.9]}, "pinch": )"
                    << p << R"(}]}})";
  setenv("XR_RUNTIME_JSON", kManifest.c_str(), 1);
  setenv("DRAPE_MOCK_FAST", "1", 1);
  setenv("DRAPE_MOCK_SCENARIO", sc.c_str(), 1);
  setenv("DRAPE_MOCK_WRITE_FRAMES", (dir / "frames").c_str(), 1);
  drape::app::XrAppOptions o;
  o.eye_size = 512;
  o.cloth_res = 12;
  o.commands_path = std::string(DRAPE_SOURCE_DIR) + "/assets/commands.json";
  o.scenario_path = sc;
  o.voice = false;
  auto r = drape::app::run_xr_app(o);
  unsetenv("DRAPE_MOCK_WRITE_FRAMES");
  unsetenv("DRAPE_MOCK_SCENARIO");
  if (!r.error.empty()) std::printf("error: %s\n", r.error.c_str());
  return r;
}

TEST(FeedbackPanel, PinchWithNothingWithinReachIsRefusedInView) {
  const fs::path base = fs::path(DRAPE_BINARY_DIR) / "xr_test_out";
  const auto with = run(base / "feedback_refusal", true);
  const auto without = run(base / "feedback_no_refusal", false);
  ASSERT_EQ(with.exit_code, 0);
  ASSERT_EQ(without.exit_code, 0);
  for (const auto& l : with.refusals) std::printf("refusal %s\n", l.c_str());
  ASSERT_FALSE(with.refusals.empty());
  EXPECT_NE(with.refusals[0].find("pinch: nothing within"), std::string::npos) << with.refusals[0];
  EXPECT_NE(with.refusals[0].find("of the right hand to pinch"), std::string::npos);
  EXPECT_TRUE(without.refusals.empty());
  // Frame 30: the refusal (taken at ~frame 15) shows. The panel's part of the image (its
  // rectangle projected from the head; the eyes sit a few millimetres beside it, hence the
  // margin) differs; the rest of the frame is the same scene.
  const std::string f30 = "frame_000030.png";
  auto a = drape::render::read_png((base / "feedback_refusal" / "frames" / f30).string());
  auto b = drape::render::read_png((base / "feedback_no_refusal" / "frames" / f30).string());
  ASSERT_TRUE(a.ok()) << a.error();
  ASSERT_TRUE(b.ok()) << b.error();
  ASSERT_EQ(a->width, b->width);
  const int w = a->width, h = a->height;
  // The panel hangs below the line of sight: the lower part of the view, the middle of it.
  int differ_low = 0, differ_high = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint8_t *pa = a->px(x, y), *pb = b->px(x, y);
      const int d = std::abs(pa[0] - pb[0]) + std::abs(pa[1] - pb[1]) + std::abs(pa[2] - pb[2]);
      if (d <= 60) continue;
      (y > h / 2 ? differ_low : differ_high) += 1;
    }
  std::printf("pixels that differ: %d below the middle, %d above\n", differ_low, differ_high);
  EXPECT_GT(differ_low, 100);  // the refusal's text
  // Above the line of sight the hand (pinched or open) alone may differ: far less.
  EXPECT_LT(differ_high, differ_low);
}
#endif

}  // namespace
