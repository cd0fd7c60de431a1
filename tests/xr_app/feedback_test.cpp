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
  EXPECT_TRUE(contains(help,
                       "pin: right: thumb-middle pinch, palms together for 0.3 s (palm-only "
                       "trackers) | thumbstick up | \"pin here\""))
      << help[3];
  EXPECT_TRUE(contains(help,
                       "help: left: palm up (held) | left: controller rolled palm up (held) | "
                       "\"show help\""))
      << help.back();
  f.set_help(help);
  EXPECT_FALSE(contains(f.lines(0), "pinch: thumb-index pinch (held)"));
  f.show_help_until(720);
  EXPECT_TRUE(contains(f.lines(719), "pinch: thumb-index pinch (held)"));
  EXPECT_FALSE(contains(f.lines(720), "pinch: thumb-index pinch (held)"));
  EXPECT_NE(f.shown_version(719), f.shown_version(720));
  const uint64_t hidden = f.version();
  f.show_help(true);  // held: shown whatever the frame
  EXPECT_TRUE(contains(f.lines(5000), "pinch: thumb-index pinch (held)"));
  EXPECT_NE(f.version(), hidden);  // showing it is a change the panel redraws
  f.toggle_help();                 // the spoken "show help" again: hidden
  EXPECT_FALSE(contains(f.lines(5000), "pinch: thumb-index pinch (held)"));
}

#ifdef DRAPE_XR_TEST_WITH_RENDER
const std::string kManifest = std::string(DRAPE_BINARY_DIR) + "/bin/drape_mock_runtime.json";

// Runs a lock-step session of the scenario (the right hand away from the cloth, pinching or
// not), writing the left eye's frames to dir/frames.
drape::app::XrAppResult run(const fs::path& dir, bool pinch, bool live = false) {
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
  // Live: the app is not told of the scenario the runtime plays (as at the desk window).
  o.scenario_path = live ? "" : sc;
  o.voice = false;
  auto r = drape::app::run_xr_app(o);
  unsetenv("DRAPE_MOCK_WRITE_FRAMES");
  unsetenv("DRAPE_MOCK_SCENARIO");
  if (!r.error.empty()) std::printf("error: %s\n", r.error.c_str());
  return r;
}

// The pixels of two screenshots that differ (summed channel difference over 60), in the lower
// and the upper half.
std::pair<int, int> differing(const fs::path& a_png, const fs::path& b_png) {
  auto a = drape::render::read_png(a_png.string());
  auto b = drape::render::read_png(b_png.string());
  EXPECT_TRUE(a.ok() && b.ok());
  if (!a.ok() || !b.ok() || a->width != b->width || a->height != b->height) return {-1, -1};
  int low = 0, high = 0;
  for (int y = 0; y < a->height; ++y)
    for (int x = 0; x < a->width; ++x) {
      const uint8_t *pa = a->px(x, y), *pb = b->px(x, y);
      const int d = std::abs(pa[0] - pb[0]) + std::abs(pa[1] - pb[1]) + std::abs(pa[2] - pb[2]);
      if (d > 60) (y > a->height / 2 ? low : high) += 1;
    }
  return {low, high};
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
  // Frame 30: the refusal (made when the pinch closed, ~frame 22) shows in the panel, which
  // hangs below the line of sight: the lower half of the frame differs from the frame without
  // it.
  const std::string f30 = "frame_000030.png";
  const auto [differ_low, differ_high] = differing(base / "feedback_refusal" / "frames" / f30,
                                                   base / "feedback_no_refusal" / "frames" / f30);
  std::printf("pixels that differ: %d below the middle, %d above\n", differ_low, differ_high);
  EXPECT_GT(differ_low, 500);  // the refusal's text (two lines)
  // Above the line of sight the hand (pinched or open) alone may differ: far less.
  EXPECT_LT(differ_high, differ_low);
}

// A live session (no scenario known to the app) shows the help, every binding of the command
// map, for its first seconds: the panel is far larger than a scripted session's.
TEST(FeedbackPanel, LiveSessionShowsTheHelpFirst) {
  const fs::path base = fs::path(DRAPE_BINARY_DIR) / "xr_test_out";
  const auto live = run(base / "feedback_live", false, true);
  const auto scripted = run(base / "feedback_scripted", false);
  ASSERT_EQ(live.exit_code, 0);
  ASSERT_EQ(scripted.exit_code, 0);
  const std::string f5 = "frame_000005.png";
  const auto [low, high] =
      differing(base / "feedback_live" / "frames" / f5, base / "feedback_scripted" / "frames" / f5);
  std::printf("help vs no help, pixels that differ: %d below the middle, %d above\n", low, high);
  EXPECT_GT(low, 20000);  // ~22 lines of help at 512 px over 90 degrees
}
#endif

}  // namespace
