// End-to-end runs of the drape OpenXR app on the mock runtime: the lifecycle to EXITING, the
// core validation layer with zero messages, hand tracking and controller input from a
// scenario, a scripted session loss (the session is re-created), and a missing runtime.
#include "xr_app/app/xr_app.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
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
