// Operations through the SimThread in lock-step: every operation shows in the snapshot after
// the next tick (latency 1 tick), and a recorded session replays to the same final hash.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "sim/ops/cut.hpp"
#include "sim/runtime/sim_thread.hpp"
#include "tests/sim/ops/operations_scene.hpp"

namespace drape::sim {
namespace {

using testing::hand_at;
using testing::Initial;

struct Rig {
  std::shared_ptr<OperationController> c = std::make_shared<OperationController>();
  std::unique_ptr<SimThread> sim;
  SnapshotReader reader;
  explicit Rig(Initial s, int substeps = 1) {
    World w = testing::make_world(s, 2);
    c->install(w);
    SimThreadOptions o;
    o.lock_step = true;
    o.substeps = substeps;
    sim = std::make_unique<SimThread>(std::move(w), o);
    reader = sim->make_reader();
    sim->start();
  }
  ~Rig() { sim->stop(); }
  void hands(const std::array<HandProxy, 2>& h) {
    auto c2 = c;
    sim->post([c2, h](World& w) { c2->set_hands(w, h); });
  }
  void trig(const std::string& name, TriggerPhase ph, int hand) {
    auto c2 = c;
    sim->post([c2, name, ph, hand](World& w) { c2->trigger(w, name, ph, hand); });
  }
  const SceneSnapshot& snap() { return reader.latest(); }
};

Vec3 pos(const SceneSnapshot& s, int v) {
  return s.positions[v].cast<double>();
}

TEST(OperationsThread, EveryOperationTakesEffectAtTheNextTick) {
  for (Initial s : {Initial::kSpread, Initial::kRolled}) {
    Rig r(s, 2);
    r.sim->advance(3);
    const SceneSnapshot& s0 = r.snap();
    const int v = 40, corner = 72;
    std::array<HandProxy, 2> h{hand_at(0, pos(s0, corner)), hand_at(1, pos(s0, v))};
    r.hands(h);
    r.trig("pinch", TriggerPhase::kBegin, 1);
    r.sim->advance(1);
    const SceneSnapshot& s1 = r.snap();
    EXPECT_TRUE(s1.flags[v] & kFlagPinched) << "pinch latency > 1 tick";
    // The hand moves: the particle is there one tick later (float snapshot: 1 mm is plenty).
    h[1].position += Vec3(0.02, 0.01, 0.03);
    r.hands(h);
    r.sim->advance(1);
    EXPECT_LT((pos(r.snap(), v) - h[1].position).norm(), 1e-3);
    r.trig("release", TriggerPhase::kBegin, 0);
    r.sim->advance(1);
    EXPECT_FALSE(r.snap().flags[corner] & kFlagPinned) << "release latency > 1 tick";
    const size_t nv = r.snap().positions.size();
    {
      auto c2 = r.c;
      std::vector<Vec3> stroke{pos(r.snap(), 18) - Vec3(0.02, 0, 0),
                               pos(r.snap(), 26) + Vec3(0.02, 0, 0)};
      r.sim->post([c2, stroke](World& w) { c2->cut_stroke(w, 0, stroke); });
    }
    r.sim->advance(1);
    EXPECT_GT(r.snap().positions.size(), nv) << "cut latency > 1 tick";
    EXPECT_EQ(r.snap().cut_strokes.size(), 1u);
    r.trig("undo", TriggerPhase::kBegin, 1);
    r.sim->advance(1);
    EXPECT_EQ(r.snap().positions.size(), nv) << "undo latency > 1 tick";
    r.trig("pin", TriggerPhase::kBegin, 0);  // nothing pinched by the left hand
    r.sim->advance(1);
    bool reason = false;
    for (const auto& m : r.snap().messages) reason = reason || m.find("pin: nothing") != m.npos;
    EXPECT_TRUE(reason);
    EXPECT_EQ(r.snap().candidate_vertex[1], v);  // the pinched particle stays highlighted
  }
}

TEST(OperationsThread, ReplayReproducesTheRecordedFinalHash) {
  auto log = std::make_shared<SessionLog>();
  {
    Rig r(Initial::kSpread, 2);
    auto c = r.c;
    r.sim->post([c](World& w) { c->start_recording(w); });
    r.sim->advance(1);
    std::array<HandProxy, 2> h{hand_at(0, pos(r.snap(), 72)), hand_at(1, pos(r.snap(), 40))};
    r.hands(h);
    r.trig("pinch", TriggerPhase::kBegin, 1);
    for (int i = 0; i < 30; ++i) {
      h[1].position += Vec3(0.002, 0.001, 0.003);
      r.hands(h);
      if (i == 10) r.trig("release", TriggerPhase::kBegin, 0);
      if (i == 15) r.trig("move", TriggerPhase::kBegin, 0);
      if (i == 20) r.trig("cut", TriggerPhase::kBegin, 0);
      if (i > 20) {
        h[0].position = pos(r.snap(), 27 + (i - 20)) + Vec3(0, 0.002, 0);
      }
      if (i == 29) r.trig("cut", TriggerPhase::kEnd, 0);
      r.sim->advance(1);
    }
    r.trig("stop", TriggerPhase::kBegin, 1);
    r.sim->advance(20);
    r.sim->post([c, log](World& w) { *log = c->stop_recording(w); });
    r.sim->advance(1);
  }
  ASSERT_GT(log->final_step, 100u);  // 52 ticks x 2 substeps
  auto parsed = parse_session(session_to_json(*log), "mem");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  Rig r2(Initial::kRolled, 2);  // a different cloth: the session brings its own
  auto c2 = r2.c;
  auto l2 = std::make_shared<SessionLog>(std::move(*parsed));
  r2.sim->post([c2, l2](World& w) { c2->start_replay(w, std::move(*l2)); });
  const int ticks = static_cast<int>(log->final_step / 2);
  r2.sim->advance(ticks);
  const uint64_t got = state_hash(r2.sim->world().cloth);
  std::printf("recorded %llu steps, final hash %016llx; replayed %016llx\n",
              static_cast<unsigned long long>(log->final_step),
              static_cast<unsigned long long>(log->final_hash),
              static_cast<unsigned long long>(got));
  EXPECT_EQ(got, log->final_hash);
  EXPECT_FALSE(c2->replaying());
}

}  // namespace
}  // namespace drape::sim
