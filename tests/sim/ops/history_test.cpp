// Undo/redo (sim/ops/history.cpp): exact state hashes back after every kind of operation,
// topology edits included, chains of undo and redo, bounded size.
#include "sim/ops/history.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "sim/ops/cut.hpp"
#include "tests/sim/ops/operations_scene.hpp"

namespace drape::sim {
namespace {

using testing::hand_at;
using testing::Initial;
using testing::tick;

TEST(History, UndoRedoOfACutRestoresTopologyAndHash) {
  World w = testing::make_world(Initial::kSpread, 2);
  OperationsState ops;
  History h;
  const uint64_t h0 = state_hash(w.cloth);
  const int n0 = w.cloth.num_vertices();
  h.push("cut", w.cloth, ops);
  CutResult r = cut_along_material(w.cloth, {Vec2(0, 0.2), Vec2(0.4, 0.2)});
  ASSERT_TRUE(r.ok);
  ops.cut_strokes.push_back({r.smooth_stroke, r.smooth_stroke_uv});
  const uint64_t h1 = state_hash(w.cloth);
  ASSERT_NE(h0, h1);
  const uint64_t v1 = w.cloth.topology_version;
  EXPECT_EQ(h.undo(w.cloth, ops), "cut");
  EXPECT_EQ(state_hash(w.cloth), h0);
  EXPECT_EQ(w.cloth.num_vertices(), n0);
  EXPECT_TRUE(ops.cut_strokes.empty());
  EXPECT_GT(w.cloth.topology_version, v1);  // solvers re-cook
  EXPECT_EQ(h.redo(w.cloth, ops), "cut");
  EXPECT_EQ(state_hash(w.cloth), h1);
  EXPECT_EQ(ops.cut_strokes.size(), 1u);
  EXPECT_EQ(count_components(w.cloth), 2);
}

TEST(History, EmptyUndoAndRedoChangeNothing) {
  World w = testing::make_world(Initial::kRolled, 1);
  OperationsState ops;
  History h;
  const uint64_t h0 = state_hash(w.cloth);
  EXPECT_EQ(h.undo(w.cloth, ops), "");
  EXPECT_EQ(h.redo(w.cloth, ops), "");
  EXPECT_EQ(state_hash(w.cloth), h0);
}

TEST(History, ChainOfOperationsThroughTheController) {
  for (Initial s : {Initial::kSpread, Initial::kRolled}) {
    World w = testing::make_world(s, 2);
    OperationController c;
    c.install(w);
    std::array<HandProxy, 2> hands{hand_at(0, w.cloth.state.x[72]),
                                   hand_at(1, w.cloth.state.x[40])};
    c.set_hands(w, hands);
    std::vector<uint64_t> before;
    auto op = [&](const char* name, int hand) {
      before.push_back(state_hash(w.cloth));
      c.trigger(w, name, TriggerPhase::kBegin, hand);
      tick(w, 4);
    };
    op("pinch", 1);    // 1
    op("release", 0);  // 2
    c.set_hands(w, hands);
    tick(w, 2);
    before.push_back(state_hash(w.cloth));
    c.cut_stroke(w, 1,
                 {w.cloth.state.x[18] - Vec3(0.02, 0, 0), w.cloth.state.x[26] + Vec3(0.02, 0, 0)});
    ASSERT_TRUE(c.state().last_cut.ok) << c.state().last_cut.reason;
    tick(w, 4);
    before.push_back(state_hash(w.cloth));
    c.trigger(w, "move", TriggerPhase::kBegin, 0);
    ASSERT_EQ(c.history().undo_size(), 4u);
    // Undo all four: each restores exactly the state just before its operation.
    for (int k = 3; k >= 0; --k) {
      c.trigger(w, "undo", TriggerPhase::kBegin, 1);
      EXPECT_EQ(state_hash(w.cloth), before[k]) << initial_name(s) << " undo " << k;
    }
    EXPECT_EQ(count_components(w.cloth), 1);
    c.trigger(w, "undo", TriggerPhase::kBegin, 1);
    EXPECT_TRUE(testing::has_message(w, "nothing to undo"));
    // Redo twice, then a new operation clears the redo stack.
    c.trigger(w, "redo", TriggerPhase::kBegin, 1);
    c.trigger(w, "redo", TriggerPhase::kBegin, 1);
    EXPECT_EQ(c.history().redo_size(), 2u);
    c.trigger(w, "pinch", TriggerPhase::kEnd, 1);
    EXPECT_EQ(c.history().redo_size(), 0u);
    tick(w, 10);
    EXPECT_TRUE(testing::stable(w.cloth));
  }
}

// Undo after a finished pinch or move returns to the state before it began, with nothing in
// progress (not to the held state just before its end), and redo brings back the finished one.
TEST(History, UndoAfterAFinishedPinchOrMoveRestoresTheStateBeforeItsBegin) {
  for (const char* name : {"pinch", "move"}) {
    World w = testing::make_world(Initial::kSpread, 2);
    OperationController c;
    c.install(w);
    std::array<HandProxy, 2> hands{hand_at(0, w.cloth.state.x[72]),
                                   hand_at(1, w.cloth.state.x[40])};
    c.set_hands(w, hands);
    tick(w, 2);
    const uint64_t before = state_hash(w.cloth);
    c.trigger(w, name, TriggerPhase::kBegin, 1);
    ASSERT_TRUE(c.state().pinched[1] >= 0 || c.state().moving) << name;
    for (auto& hp : hands) hp.position += Vec3(0.05, 0.03, 0);
    for (int k = 0; k < 6; ++k) {
      c.set_hands(w, hands);
      tick(w, 1);
    }
    c.trigger(w, name, TriggerPhase::kEnd, 1);
    tick(w, 2);
    const uint64_t after = state_hash(w.cloth);
    ASSERT_NE(after, before) << name;
    EXPECT_EQ(c.history().undo_size(), 1u) << name;
    c.trigger(w, "undo", TriggerPhase::kBegin, 1);
    EXPECT_EQ(state_hash(w.cloth), before) << name;
    EXPECT_EQ(c.state().pinched[0], -1) << name;
    EXPECT_EQ(c.state().pinched[1], -1) << name;
    EXPECT_FALSE(c.state().moving) << name;
    tick(w, 3);  // nothing in progress drags the cloth back toward the hands
    EXPECT_EQ(c.state().pinched[1], -1) << name;
    EXPECT_FALSE(c.state().moving) << name;
    c.trigger(w, "redo", TriggerPhase::kBegin, 1);
    EXPECT_EQ(state_hash(w.cloth), after) << name;
    EXPECT_EQ(c.state().pinched[1], -1) << name;
    EXPECT_FALSE(c.state().moving) << name;
  }
}

TEST(History, IsBounded) {
  World w = testing::make_world(Initial::kSpread, 2);
  OperationsState ops;
  History h(5);
  for (int i = 0; i < 12; ++i) {
    h.push("x", w.cloth, ops);
    w.cloth.state.x[0].x() += 0.001;
  }
  EXPECT_EQ(h.undo_size(), 5u);
}

}  // namespace
}  // namespace drape::sim
