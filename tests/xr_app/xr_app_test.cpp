// End-to-end runs of the drape OpenXR app on the mock runtime: the lifecycle to EXITING, the
// core validation layer with zero messages, hand tracking and controller input from a
// scenario, a scripted session loss (the session is re-created), and a missing runtime.
#include "xr_app/app/xr_app.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace {

const std::string kManifest = std::string(DRAPE_BINARY_DIR) + "/bin/drape_mock_runtime.json";

void base_env() {
  for (const char* v :
       {"DRAPE_MOCK_SCENARIO", "DRAPE_MOCK_END_AFTER_FRAMES", "DRAPE_MOCK_WRITE_FRAMES",
        "DRAPE_MOCK_LOSE_SESSION_AT_FRAME", "XR_ENABLE_API_LAYERS"})
    unsetenv(v);
  setenv("XR_RUNTIME_JSON", kManifest.c_str(), 1);
  setenv("DRAPE_MOCK_FAST", "1", 1);
}

drape::app::XrAppOptions small() {
  drape::app::XrAppOptions o;
  o.eye_size = 128;
  o.cloth_res = 12;
  return o;
}

void print(const drape::app::XrAppResult& r) {
  std::printf("state %s, frames %lld (rendered %lld), sessions %d, lost %d, validation %u\n",
              drape::app::to_string(r.final_state), static_cast<long long>(r.frames),
              static_cast<long long>(r.frames_rendered), r.sessions, r.sessions_lost,
              r.validation_messages);
  if (!r.error.empty()) std::printf("error: %s\n", r.error.c_str());
}

TEST(XrApp, RunsToExitingWhenTheRuntimeEndsTheSession) {
  base_env();
  setenv("DRAPE_MOCK_END_AFTER_FRAMES", "12", 1);
  auto r = drape::app::run_xr_app(small());
  print(r);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.final_state, drape::app::XrAppState::kExiting);
  EXPECT_EQ(r.frames, 12);
  EXPECT_EQ(r.frames_rendered, 12);
  EXPECT_EQ(r.runtime_name, "drape mock runtime");
  EXPECT_EQ(r.sessions, 1);
}

TEST(XrApp, FrameBudgetRequestsExitUnderCoreValidation) {
  base_env();
  setenv("XR_ENABLE_API_LAYERS", "XR_APILAYER_LUNARG_core_validation", 1);
  auto o = small();
  o.max_frames = 10;
  auto r = drape::app::run_xr_app(o);
  print(r);
  for (const auto& l : r.log)
    if (l.rfind("validation", 0) == 0) std::printf("%s\n", l.c_str());
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.final_state, drape::app::XrAppState::kExiting);
  EXPECT_GE(r.frames, 10);
  EXPECT_EQ(r.validation_messages, 0u);
  unsetenv("XR_ENABLE_API_LAYERS");
}

TEST(XrApp, HandsAndControllersFromTheScenario) {
  base_env();
  setenv("DRAPE_MOCK_SCENARIO",
         (std::string(DRAPE_SOURCE_DIR) + "/assets/scenarios/mock_basic.json").c_str(), 1);
  setenv("DRAPE_MOCK_END_AFTER_FRAMES", "100", 1);
  auto o = small();
  o.render = false;
  auto r = drape::app::run_xr_app(o);
  print(r);
  std::printf("right hand tracked in %lld frames, min pinch gap %.4f m, max trigger %.3f\n",
              static_cast<long long>(r.hand_frames_tracked), r.min_pinch_gap_m, r.max_trigger);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(r.hand_tracking);
  EXPECT_EQ(r.hand_frames_tracked, 100);
  EXPECT_NEAR(r.min_pinch_gap_m, 0.005f, 1e-4);  // pinch = 1 in frames 45..60
  EXPECT_GT(r.max_trigger, 0.99f);               // the left trigger ramps to 1 at frame 90
}

// The default draping scenario end to end: the thumb-index pinch of the right hand pinches the
// cloth, a spoken "pin here" (espeak-ng WAV, decoded by the voice recogniser) pins it, the
// left controller's trigger sweep is a cut stroke that splits it.
TEST(XrApp, DefaultScenarioPinchesPinsAndCutsTheCloth) {
  base_env();
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(DRAPE_BINARY_DIR) / "xr_test_out" / "app_default";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string raw = (dir / "pin_22k.wav").string(), wav = (dir / "pin.wav").string();
  const std::string cmd = "espeak-ng -s 140 -w '" + raw + "' 'pin here' && sox '" + raw +
                          "' -r 16000 -c 1 -b 16 '" + wav + "' pad 0.3 0.5";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  // The bundled scenario with its audio cue pointing at the generated WAV.
  std::ifstream in(std::string(DRAPE_SOURCE_DIR) + "/assets/scenarios/default.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string key = "../../out/voice/cue0.wav";
  const size_t at = text.find(key);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, key.size(), wav);
  const std::string sc = (dir / "scenario.json").string();
  std::ofstream(sc) << text;
  setenv("DRAPE_MOCK_SCENARIO", sc.c_str(), 1);
  auto o = small();
  o.eye_size = 64;
  o.cloth_res = 12;
  o.out_dir = dir.string();
  auto r = drape::app::run_xr_app(o);
  print(r);
  for (const auto& t : r.triggers) std::printf("trigger %s\n", t.c_str());
  for (const auto& l : r.log)
    if (l.rfind("voice", 0) == 0 || l.rfind("cut", 0) == 0) std::printf("%s\n", l.c_str());
  for (const auto& m : r.sim_messages) std::printf("sim: %s\n", m.c_str());
  std::printf(
      "pinched in %lld frames, pinned +%d, cuts %d (%d new particles, %d -> %d components)\n",
      static_cast<long long>(r.frames_pinched), r.pinned_added, r.cuts_ok, r.cut_new_vertices,
      r.components_before, r.components_after);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.frames, 300);
  // Pinch: closed at frame ~72 (gap < 25 mm, 80 ms debounce), held until the pin (~frame 140)
  // and the release at ~frame 160.
  EXPECT_GT(r.frames_pinched, 40);
  ASSERT_EQ(r.voice_commands.size(), 1u);
  EXPECT_EQ(r.voice_commands[0], "pin");
  EXPECT_GE(r.pinned_added, 1);
  // The stroke across the panel is applied: the mesh is cut along it (particles duplicated).
  // It does not yet separate the panel into two pieces (components stay 1, see docs/xr.md).
  EXPECT_EQ(r.cuts_ok, 1);
  EXPECT_GE(r.cut_new_vertices, 5);
  for (const char* f : {"session_log.json", "drape_cloth.gltf", "xr_session.txt"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
}

TEST(XrApp, SessionLossIsAnOrdinaryState) {
  base_env();
  setenv("DRAPE_MOCK_LOSE_SESSION_AT_FRAME", "5", 1);
  setenv("DRAPE_MOCK_END_AFTER_FRAMES", "8", 1);
  auto o = small();
  o.render = false;
  auto r = drape::app::run_xr_app(o);
  print(r);
  EXPECT_EQ(r.sessions_lost, 1);
  EXPECT_EQ(r.sessions, 2);
  EXPECT_EQ(r.final_state, drape::app::XrAppState::kExiting);
  EXPECT_EQ(r.exit_code, 0);
  // 5 frames before the loss; the new session's frames continue the instance's count to 8.
  EXPECT_EQ(r.frames, 8);
}

TEST(XrApp, MissingRuntimeIsReportedNotCrashed) {
  base_env();
  setenv("XR_RUNTIME_JSON", "/nonexistent/drape_no_runtime.json", 1);
  auto r = drape::app::run_xr_app(small());
  print(r);
  EXPECT_EQ(r.final_state, drape::app::XrAppState::kNoRuntime);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_FALSE(r.error.empty());
  EXPECT_EQ(r.frames, 0);
}

TEST(XrApp, SelectRuntimeKeepsAnExplicitChoice) {
  setenv("XR_RUNTIME_JSON", "/some/runtime.json", 1);
  EXPECT_EQ(drape::app::select_runtime(), "/some/runtime.json");
}

}  // namespace
