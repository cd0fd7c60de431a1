// Session files (sim/ops/session_log.cpp): bit-exact round trip, replay reproduces the recorded
// final hash (single-threaded stepping), and every kind of bad file gives a clear error.
#include "sim/ops/session_log.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/sim/ops/operations_scene.hpp"

namespace drape::sim {
namespace {

using testing::hand_at;
using testing::Initial;
using testing::tick;

// Records a scripted session on `w` (a pinch carried around, a release, a cut, an undo).
SessionLog record(World& w, OperationController& c) {
  c.install(w);
  std::array<HandProxy, 2> hands{hand_at(0, w.cloth.state.x[72]), hand_at(1, w.cloth.state.x[40])};
  hands[1].orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Vec3::UnitY()));
  c.set_hands(w, hands);
  c.start_recording(w);
  auto frame = [&](int n) {
    for (int i = 0; i < n; ++i) {
      hands[1].position += Vec3(0.001, 0.002, 0.003);
      c.set_hands(w, hands);
      tick(w);
    }
  };
  c.trigger(w, "pinch", TriggerPhase::kBegin, 1);
  frame(10);
  c.trigger(w, "release", TriggerPhase::kBegin, 0);
  frame(5);
  c.select_candidate(w, 0, 1);
  c.cut_stroke(w, 0,
               {w.cloth.state.x[18] - Vec3(0.02, 0, 0), w.cloth.state.x[26] + Vec3(0.02, 0, 0)});
  frame(5);
  c.trigger(w, "undo", TriggerPhase::kBegin, 1);
  frame(3);
  c.trigger(w, "redo", TriggerPhase::kBegin, 1);
  c.trigger(w, "pinch", TriggerPhase::kEnd, 1);
  frame(10);
  return c.stop_recording(w);
}

TEST(SessionLog, RoundTripIsBitExact) {
  World w = testing::make_world(Initial::kRolled, 2);
  OperationController c;
  SessionLog log = record(w, c);
  ASSERT_GT(log.events.size(), 30u);
  const std::string text = session_to_json(log);
  auto back = parse_session(text, "mem");
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(state_hash(back->initial), state_hash(log.initial));
  EXPECT_EQ(back->initial.state.v, log.initial.state.v);
  EXPECT_EQ(back->initial.state.mass, log.initial.state.mass);
  EXPECT_EQ(back->initial.topo.material, log.initial.topo.material);
  EXPECT_EQ(back->final_hash, log.final_hash);
  EXPECT_EQ(back->final_step, log.final_step);
  ASSERT_EQ(back->events.size(), log.events.size());
  for (size_t i = 0; i < log.events.size(); ++i) {
    const auto &a = log.events[i], &b = back->events[i];
    EXPECT_EQ(a.step, b.step);
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.points, b.points);
    for (int h = 0; h < 2; ++h) {
      EXPECT_EQ(a.hands[h].position, b.hands[h].position);
      EXPECT_EQ(a.hands[h].orientation.coeffs(), b.hands[h].orientation.coeffs());
    }
  }
  EXPECT_EQ(session_to_json(*back), text);  // and back again, byte for byte
  std::printf("session: %zu events, %zu bytes of JSON\n", log.events.size(), text.size());
}

TEST(SessionLog, ReplayReproducesTheFinalHash) {
  World w = testing::make_world(Initial::kSpread, 2);
  OperationController c;
  SessionLog log = record(w, c);
  EXPECT_EQ(state_hash(w.cloth), log.final_hash);
  const std::string path = std::string(DRAPE_BINARY_DIR) + "/session_log_test.json";
  ASSERT_EQ(save_session(path, log), "");
  auto loaded = load_session(path);
  ASSERT_TRUE(loaded.ok()) << loaded.error();
  // A fresh world and solver, as after a restart.
  World w2 = testing::make_world(Initial::kSpread, 0);
  w2.cloth.state.x[0].x() += 1;  // whatever the cloth was, the session restores its own
  OperationController c2;
  c2.install(w2);
  c2.start_replay(w2, std::move(*loaded));
  for (uint64_t i = 0; i < log.final_step; ++i) {
    c2.set_hands(w2, {});  // live input during a replay is ignored
    tick(w2);
  }
  EXPECT_FALSE(c2.replaying());
  EXPECT_EQ(state_hash(w2.cloth), log.final_hash);
  EXPECT_TRUE(testing::has_message(w2, "matches the recording"));
  std::printf("replay final hash %016llx (recorded %016llx)\n",
              static_cast<unsigned long long>(state_hash(w2.cloth)),
              static_cast<unsigned long long>(log.final_hash));
  std::filesystem::remove(path);
}

TEST(SessionLog, BadFilesGiveClearErrors) {
  World w = testing::make_world(Initial::kSpread, 2);
  OperationController c;
  const std::string good = session_to_json(record(w, c));
  auto bad = [&](const std::string& text, const std::string& expect) {
    auto r = parse_session(text, "s.json");
    ASSERT_FALSE(r.ok()) << "accepted: " << expect;
    EXPECT_NE(r.error().find(expect), std::string::npos) << r.error();
    EXPECT_EQ(r.error().rfind("s.json", 0), 0u) << r.error();
    std::printf("  %s\n", r.error().c_str());
  };
  using nlohmann::json;
  auto edit = [&](auto f) {
    json j = json::parse(good);
    f(j);
    return j.dump();
  };
  bad("", "not valid JSON");
  bad(good.substr(0, good.size() / 2), "not valid JSON");
  bad("[1,2]", "top level: is not a JSON object");
  bad(edit([](json& j) { j["format"] = "x"; }), "format");
  bad(edit([](json& j) { j["version"] = 9; }), "version");
  bad(edit([](json& j) { j.erase("cloth"); }), "cloth: missing");
  bad(edit([](json& j) { j["cloth"].erase("x"); }), "cloth.x: missing");
  bad(edit([](json& j) { j["cloth"]["x"] = "###"; }), "cloth.x: is not valid base64");
  bad(edit([](json& j) { j["cloth"]["x"] = "AAAA"; }), "cloth.x");
  bad(edit([](json& j) { j["cloth"]["vertices"] = -3; }), "cloth.vertices");
  bad(edit([](json& j) { j["cloth"]["fabric"]["shear"] = -1; }), "cloth.fabric.shear");
  bad(edit([](json& j) {
        std::vector<int32_t> t{0, 1, 99999};
        j["cloth"]["triangles_count"] = 1;
        j["cloth"]["triangles"] = base64_encode(t.data(), 12);
        j["cloth"]["triangle_zone"] = base64_encode(t.data(), 4);
      }),
      "out of range");
  bad(edit([](json& j) {
        const double nan = std::nan("");
        j["step_dt"] = base64_encode(&nan, 8);
      }),
      "step_dt");
  bad(edit([](json& j) { j["events"][0]["type"] = "jump"; }), "events[0].type");
  bad(edit([](json& j) { j["events"][1]["step"] = -1; }), "events[1].step");
  bad(edit([](json& j) { j["events"][0]["pose"] = "AAAA"; }), "events[0].pose");
  bad(edit([](json& j) {
        for (auto& e : j["events"])
          if (e["type"] == "trigger") {
            e["phase"] = "sideways";
            break;
          }
      }),
      "phase");
  bad(edit([](json& j) { j["final_hash"] = "xyz"; }), "final_hash");
  auto missing = load_session("/nonexistent/dir/s.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("cannot open"), std::string::npos);
  EXPECT_NE(save_session("/nonexistent/dir/s.json", SessionLog{}), "");
}

TEST(SessionLog, Base64) {
  const std::string s = "any carnal pleas";
  for (size_t n = 0; n <= s.size(); ++n) {
    std::vector<uint8_t> out;
    ASSERT_TRUE(base64_decode(base64_encode(s.data(), n), out));
    EXPECT_EQ(std::string(out.begin(), out.end()), s.substr(0, n));
  }
  EXPECT_EQ(base64_encode("Man", 3), "TWFu");
  EXPECT_EQ(base64_encode("Ma", 2), "TWE=");
  std::vector<uint8_t> out;
  EXPECT_FALSE(base64_decode("TWE", out));
  EXPECT_FALSE(base64_decode("T=Fu", out));
  EXPECT_FALSE(base64_decode("TW=u", out));
  EXPECT_FALSE(base64_decode("TW!u", out));
}

}  // namespace
}  // namespace drape::sim
