// Every row of the operations table (docs/operations.md, "Tests") on both initial states,
// asserting the resulting cloth state, plus candidates, both hands, and bad input.
#include "sim/ops/operations.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "sim/draping/mapping.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/ops/cut.hpp"
#include "sim/testbeds/testbed.hpp"
#include "tests/sim/ops/operations_scene.hpp"

namespace drape::sim {
namespace {

using testing::hand_at;
using testing::has_message;
using testing::Initial;
using testing::stable;
using testing::tick;

struct Ops : ::testing::TestWithParam<Initial> {
  World w;
  std::shared_ptr<OperationController> c = std::make_shared<OperationController>();
  std::array<HandProxy, 2> hands{};
  void SetUpWorld(int fixed) {
    c = std::make_shared<OperationController>();
    w = testing::make_world(GetParam(), fixed);
    c->install(w);
    hands[0] = hand_at(0, Vec3(-1, 2, 1));
    hands[1] = hand_at(1, Vec3(1, 2, 1));
    hands[0].tracked = hands[1].tracked = false;
    c->set_hands(w, hands);
  }
  void set(int h, const Vec3& p) {
    hands[h].position = hands[h].tip = p;
    hands[h].tracked = true;
    c->set_hands(w, hands);
  }
  void trig(const char* name, TriggerPhase ph, int hand = 1) { c->trigger(w, name, ph, hand); }
  // The parametric 9AR dress form in the scene (what map and smooth act on).
  void add_form_9ar() {
    auto m = measurements_for_size("9AR");
    ASSERT_TRUE(m.ok()) << m.error();
    auto form = DressForm::from_measurements(*m);
    ASSERT_TRUE(form.ok()) << form.error();
    w.scene.form = std::make_shared<const DressForm>(std::move(*form));
  }
  void run(int ticks) {
    for (int i = 0; i < ticks; ++i) {
      c->set_hands(w, hands);
      tick(w);
      ASSERT_TRUE(stable(w.cloth)) << "unstable at tick " << i;
    }
  }
  const Vec3& X(int v) const { return w.cloth.state.x[v]; }
  int top(int i) const { return testing::top_vertex(w, i); }
  // A free particle in the middle of the outermost visible part.
  int middle() const { return 4 * 9 + 4; }
  // Undo must give back exactly the state before the last operation.
  void expect_undo_exact(uint64_t before_hash) {
    const uint64_t after = state_hash(w.cloth);
    trig("undo", TriggerPhase::kBegin);
    EXPECT_EQ(state_hash(w.cloth), before_hash);
    trig("redo", TriggerPhase::kBegin);
    EXPECT_EQ(state_hash(w.cloth), after);
  }
};

// --- move ---------------------------------------------------------------------------------
TEST_P(Ops, MoveWithoutObstacle) {
  SetUpWorld(2);
  run(10);
  set(0, X(top(0)) + Vec3(0, 0.001, 0));
  set(1, X(top(8)) + Vec3(0, 0.001, 0));
  const uint64_t h0 = state_hash(w.cloth);
  trig("move", TriggerPhase::kBegin);
  ASSERT_TRUE(c->state().moving);
  expect_undo_exact(h0);
  for (int i = 0; i < 30; ++i) {  // carry the cloth 15 cm toward +z and up
    set(0, hands[0].position + Vec3(0, 0.002, 0.005));
    set(1, hands[1].position + Vec3(0, 0.002, 0.005));
    run(1);
  }
  // The corners follow the hands, keeping the grab offset (here 1 mm below the hand).
  const Vec3 off(0, -0.001, 0);
  EXPECT_LT((X(top(0)) - (hands[0].position + off)).norm(), 1e-9);
  EXPECT_LT((X(top(8)) - (hands[1].position + off)).norm(), 1e-9);
  const Vec3 end0 = X(top(0));
  trig("move", TriggerPhase::kEnd);
  set(0, Vec3(-1, 1, 1));
  set(1, Vec3(1, 1, 1));
  run(30);
  // Kept fixed where they were at the end.
  EXPECT_TRUE(w.cloth.state.flags[top(0)] & kFlagPinned);
  EXPECT_LT((X(top(0)) - end0).norm(), 1e-12);
}

TEST_P(Ops, MoveKeepsTheGrabOffset) {
  SetUpWorld(2);
  run(5);
  // Hands 8 cm in front of and 3 cm beside the corners: grabbing must not make them jump.
  const Vec3 off0(-0.03, 0.0, 0.08), off1(0.03, 0.01, 0.08);
  set(0, X(top(0)) + off0);
  set(1, X(top(8)) + off1);
  const Vec3 c0 = X(top(0)), c1 = X(top(8));
  trig("move", TriggerPhase::kBegin);
  ASSERT_TRUE(c->state().moving);
  run(1);
  const double jump = std::max((X(top(0)) - c0).norm(), (X(top(8)) - c1).norm());
  std::printf("%s: corner displacement at grab %.3g mm\n", initial_name(GetParam()), jump * 1e3);
  EXPECT_LT(jump, 1e-9);
  // Hands move by d: corners move by d (offset kept), each hand independently.
  const Vec3 d0(0.05, 0.10, -0.02), d1(-0.04, 0.06, 0.03);
  for (int i = 1; i <= 20; ++i) {
    set(0, c0 + off0 + d0 * (i / 20.0));
    set(1, c1 + off1 + d1 * (i / 20.0));
    run(1);
  }
  EXPECT_LT((X(top(0)) - (c0 + d0)).norm(), 1e-9);
  EXPECT_LT((X(top(8)) - (c1 + d1)).norm(), 1e-9);
  // End: the corners stay fixed where the hands left them (offset included).
  trig("move", TriggerPhase::kEnd);
  EXPECT_TRUE(w.cloth.state.flags[top(8)] & kFlagPinned);
  EXPECT_LT((X(top(8)) - (c1 + d1)).norm(), 1e-9);
}

TEST_P(Ops, MoveWithObstacle) {
  SetUpWorld(2);
  Plate plate;
  plate.centre = Vec3(0, 0.95, 0.1);
  plate.half_x = plate.half_z = 0.3;
  w.scene.plates.push_back(plate);
  set(0, X(top(0)));
  set(1, X(top(8)));
  trig("move", TriggerPhase::kBegin);
  // Lay the cloth over the plate: hands go forward and down to 6 cm above it.
  const double goal_y = plate.centre.y() + 0.06, goal_z = 0.25;
  const Vec3 step0 = (Vec3(hands[0].position.x(), goal_y, goal_z) - hands[0].position) / 60;
  const Vec3 step1 = (Vec3(hands[1].position.x(), goal_y, goal_z) - hands[1].position) / 60;
  for (int i = 0; i < 60; ++i) {
    set(0, hands[0].position + step0);
    set(1, hands[1].position + step1);
    run(1);
  }
  run(60);
  double worst = 0;
  for (int v = 0; v < w.cloth.num_vertices(); ++v) {
    const Vec3& p = X(v);
    if (std::abs(p.x() - plate.centre.x()) < plate.half_x - 0.01 &&
        std::abs(p.z() - plate.centre.z()) < plate.half_z - 0.01 && p.y() < plate.centre.y() &&
        p.y() > plate.centre.y() - plate.thickness)
      worst = std::max(worst, plate.centre.y() - p.y());
  }
  std::printf("%s: deepest particle inside the plate %.2f mm\n", initial_name(GetParam()),
              worst * 1e3);
  EXPECT_LT(worst, 0.003);
}

// --- pinch -------------------------------------------------------------------------------
void pinch_and_carry(Ops& t) {
  const int v = t.middle();
  t.set(1, t.X(v) + Vec3(0.005, 0.005, 0.005));
  const uint64_t h0 = state_hash(t.w.cloth);
  t.trig("pinch", TriggerPhase::kBegin);
  ASSERT_EQ(t.c->state().pinched[1], v);
  t.expect_undo_exact(h0);
  for (int i = 0; i < 20; ++i) {
    t.set(1, t.hands[1].position + Vec3(0.002, 0.003, 0.004));
    t.run(1);
    ASSERT_LT((t.X(v) - t.hands[1].position).norm(), 1e-3);
  }
  std::printf("pinched particle %.3g mm from the hand\n",
              (t.X(v) - t.hands[1].position).norm() * 1e3);
  t.trig("pinch", TriggerPhase::kEnd);
  EXPECT_FALSE(t.w.cloth.state.flags[v] & (kFlagPinched | kFlagPinned));
  EXPECT_GT(t.w.cloth.state.inv_mass[v], 0);
  const double y0 = t.X(v).y();
  t.run(20);
  EXPECT_LT(t.X(v).y(), y0);  // freed: falls back under gravity
}

TEST_P(Ops, PinchWithOneFixed) {
  SetUpWorld(1);
  run(5);
  pinch_and_carry(*this);
}

TEST_P(Ops, PinchWithTwoFixed) {
  SetUpWorld(2);
  run(5);
  pinch_and_carry(*this);
}

// --- tracking loss -----------------------------------------------------------------------
int count_fixed(const Cloth& c) {
  int n = 0;
  for (uint8_t f : c.state.flags) n += (f & (kFlagPinned | kFlagKinematic)) ? 1 : 0;
  return n;
}

// Lost mid-pinch and back within the grace: the particle waits where the hand was last seen
// (fixed, not falling), then follows the hand again.
TEST_P(Ops, PinchHeldWhileTheHandIsLostWithinTheGrace) {
  SetUpWorld(2);
  run(5);
  const int v = middle();
  set(1, X(v) + Vec3(0.005, 0.005, 0.005));
  trig("pinch", TriggerPhase::kBegin);
  ASSERT_EQ(c->state().pinched[1], v);
  run(3);
  const int g = grace_ticks(c->params(), testing::kDt);
  EXPECT_EQ(g, 27);  // 0.3 s at 90 Hz
  const Vec3 last = hands[1].position;
  hands[1].tracked = false;
  run(g - 1);
  EXPECT_EQ(c->state().pinched[1], v);
  EXPECT_EQ(c->state().lost_ticks[1], g - 1);
  EXPECT_LT((X(v) - last).norm(), 1e-12);  // held, not falling
  EXPECT_FALSE(has_message(w, "lost for"));
  set(1, last + Vec3(0.02, 0.01, 0));
  run(5);
  EXPECT_EQ(c->state().pinched[1], v);
  EXPECT_EQ(c->state().lost_ticks[1], 0);
  EXPECT_LT((X(v) - hands[1].position).norm(), 1e-9);
  EXPECT_FALSE(has_message(w, "lost for"));
}

// Lost for longer: the pinch ends at the grace tick (not before) as a pinch end would, with a
// report; nothing else changes (no pin, no particle added, the undo history as it was).
TEST_P(Ops, PinchLetGoAfterTheGrace) {
  SetUpWorld(2);
  run(5);
  const int v = middle();
  set(1, X(v) + Vec3(0.005, 0.005, 0.005));
  const uint64_t h0 = state_hash(w.cloth);
  trig("pinch", TriggerPhase::kBegin);
  ASSERT_EQ(c->state().pinched[1], v);
  const size_t undo = c->history().undo_size();
  const int fixed = count_fixed(w.cloth), nv = w.cloth.num_vertices();
  const int g = grace_ticks(c->params(), testing::kDt);
  const Vec3 last = X(v);
  hands[1].tracked = false;
  run(g - 1);
  ASSERT_EQ(c->state().pinched[1], v);
  EXPECT_FALSE(has_message(w, "lost for"));
  run(1);
  EXPECT_EQ(c->state().pinched[1], -1);
  EXPECT_EQ(c->state().lost_ticks[1], 0);
  EXPECT_TRUE(
      has_message(w, "pinch: right hand lost for 0.3 s: let go of particle " + std::to_string(v)));
  EXPECT_FALSE(w.cloth.state.flags[v] & (kFlagPinched | kFlagPinned));
  EXPECT_GT(w.cloth.state.inv_mass[v], 0);
  EXPECT_EQ(count_fixed(w.cloth), fixed);
  EXPECT_EQ(w.cloth.num_vertices(), nv);
  EXPECT_EQ(c->history().undo_size(), undo);
  run(20);
  EXPECT_LT(X(v).y(), last.y());  // freed: falls under gravity
  // The hand back later takes nothing by itself; undo still returns to before the pinch.
  set(1, last);
  run(2);
  EXPECT_EQ(c->state().pinched[1], -1);
  trig("undo", TriggerPhase::kBegin);
  EXPECT_EQ(state_hash(w.cloth), h0);
}

// Lost mid-cut: the stroke pauses, then is cancelled after the grace; nothing is cut.
TEST_P(Ops, CutStrokeCancelledWhenTheHandIsLost) {
  SetUpWorld(2);
  run(30);
  const int row = 6;
  const int nv = w.cloth.num_vertices();
  set(1, X(row * 9) + (X(row * 9) - X(row * 9 + 8)) * 0.05);
  trig("cut", TriggerPhase::kBegin);
  for (int i = 0; i <= 10; ++i) {
    set(1, X(row * 9) + (X(row * 9 + 8) - X(row * 9)) * (-0.05 + 1.1 * i / 20.0));
    run(1);
  }
  const size_t samples = c->state().stroke[1].size();
  hands[1].tracked = false;
  const int g = grace_ticks(c->params(), testing::kDt);
  run(g - 1);
  EXPECT_TRUE(c->state().cutting[1]);
  EXPECT_EQ(c->state().stroke[1].size(), samples);  // paused: no samples while lost
  run(1);
  EXPECT_FALSE(c->state().cutting[1]);
  EXPECT_TRUE(c->state().stroke[1].empty());
  EXPECT_TRUE(has_message(w, "cut: right hand lost for 0.3 s: stroke cancelled"));
  set(1, X(row * 9 + 8) + (X(row * 9 + 8) - X(row * 9)) * 0.05);
  run(1);
  trig("cut", TriggerPhase::kEnd);  // the user's end comes too late: nothing to cut
  EXPECT_TRUE(has_message(w, "cut end: the right hand is not cutting"));
  EXPECT_EQ(count_components(w.cloth), 1);
  EXPECT_EQ(w.cloth.num_vertices(), nv);
  EXPECT_TRUE(c->state().cut_strokes.empty());
  EXPECT_EQ(c->history().undo_size(), 0u);
}

// A non-finite pose is reported and the previous pose kept, as before; held that long it is a
// lost hand: the pinch ends after the grace.
TEST_P(Ops, NonFinitePoseIsALostHand) {
  SetUpWorld(2);
  run(5);
  const int v = middle();
  set(1, X(v) + Vec3(0.005, 0.005, 0.005));
  trig("pinch", TriggerPhase::kBegin);
  ASSERT_EQ(c->state().pinched[1], v);
  const Vec3 last = hands[1].position;
  hands[1].position = Vec3(std::nan(""), 0, 0);
  const int g = grace_ticks(c->params(), testing::kDt);
  run(g - 1);
  EXPECT_TRUE(has_message(w, "not finite"));
  EXPECT_TRUE((c->state().hands[1].position - last).norm() < 1e-12);  // previous pose kept
  EXPECT_EQ(c->state().pinched[1], v);
  EXPECT_LT((X(v) - last).norm(), 1e-12);
  run(1);
  EXPECT_EQ(c->state().pinched[1], -1);
  EXPECT_TRUE(has_message(w, "pinch: right hand lost for 0.3 s: let go"));
  EXPECT_EQ(w.cloth.validate(), "");
}

// A move with a hand lost past the grace ends as a move end does: the corners stay fixed.
TEST_P(Ops, MoveEndedWhenAHandIsLost) {
  SetUpWorld(2);
  run(5);
  set(0, X(top(0)) + Vec3(0, 0.001, 0));
  set(1, X(top(8)) + Vec3(0, 0.001, 0));
  trig("move", TriggerPhase::kBegin);
  ASSERT_TRUE(c->state().moving);
  run(2);
  hands[0].tracked = false;
  const int g = grace_ticks(c->params(), testing::kDt);
  run(g - 1);
  EXPECT_TRUE(c->state().moving);
  run(1);
  EXPECT_FALSE(c->state().moving);
  EXPECT_TRUE(has_message(w, "move: left hand lost for 0.3 s: move ended"));
  EXPECT_TRUE(w.cloth.state.flags[top(0)] & kFlagPinned);
  EXPECT_TRUE(w.cloth.state.flags[top(8)] & kFlagPinned);
}

// The grace counts ticks, so a recorded session with a lost hand replays to the same cloth:
// the let-go happens at the same tick.
TEST_P(Ops, TrackingLossReplaysBitExact) {
  SetUpWorld(2);  // no tick before the recording: the replay's solver starts as fresh
  const int v = middle();
  set(1, X(v) + Vec3(0.005, 0.005, 0.005));
  c->start_recording(w);
  trig("pinch", TriggerPhase::kBegin);
  run(5);
  hands[1].tracked = false;
  run(10);  // within the grace
  set(1, hands[1].position + Vec3(0.01, 0, 0));
  run(5);
  hands[1].tracked = false;
  run(40);  // past it: let go
  SessionLog log = c->stop_recording(w);
  ASSERT_TRUE(has_message(w, "let go of particle"));
  World w2 = testing::make_world(GetParam(), 2);
  OperationController c2;
  c2.install(w2);
  c2.start_replay(w2, std::move(log));
  for (int i = 0; i < 60; ++i) tick(w2);
  EXPECT_FALSE(c2.replaying());
  EXPECT_TRUE(has_message(w2, "let go of particle " + std::to_string(v)));
  EXPECT_TRUE(has_message(w2, "matches the recording"));
  EXPECT_EQ(state_hash(w2.cloth), state_hash(w.cloth));
}

// --- release -----------------------------------------------------------------------------
TEST_P(Ops, ReleaseWithOneFixedLetsTheClothFall) {
  SetUpWorld(1);
  run(5);
  set(1, X(top(0)) + Vec3(0.01, 0, 0));
  const uint64_t h0 = state_hash(w.cloth);
  double ysum0 = 0;
  for (const Vec3& p : w.cloth.state.x) ysum0 += p.y();
  trig("release", TriggerPhase::kBegin);
  EXPECT_FALSE(w.cloth.state.flags[top(0)] & kFlagPinned);
  expect_undo_exact(h0);
  const double y0 = X(top(0)).y();
  run(20);
  double ysum = 0;
  for (const Vec3& p : w.cloth.state.x) ysum += p.y();
  EXPECT_LT(X(top(0)).y(), y0 - 0.05);  // ~ g t^2 / 2 = 0.24 m in 0.22 s, minus drag
  EXPECT_LT(ysum, ysum0);
}

TEST_P(Ops, ReleaseWithTwoFixedHangsFromTheOther) {
  SetUpWorld(2);
  run(5);
  set(1, X(top(8)) + Vec3(0.01, 0, 0));
  trig("release", TriggerPhase::kBegin);
  EXPECT_FALSE(w.cloth.state.flags[top(8)] & kFlagPinned);
  EXPECT_TRUE(w.cloth.state.flags[top(0)] & kFlagPinned);
  const Vec3 keep = X(top(0));
  const double y0 = X(top(8)).y();
  run(30);
  EXPECT_LT(X(top(8)).y(), y0 - 0.02);
  EXPECT_EQ(X(top(0)), keep);
}

TEST_P(Ops, ReleaseManyFixedAtAnyPosition) {
  SetUpWorld(5);
  run(5);
  // Release them one by one in an arbitrary order; each time the nearest fixed one goes.
  const int order[] = {2, 4, 0, 3, 1};
  for (int k : order) {
    const int v = top(8 * k / 4);
    ASSERT_TRUE(w.cloth.state.flags[v] & kFlagPinned) << k;
    set(1, X(v) + Vec3(0, 0.01, 0));
    trig("release", TriggerPhase::kBegin);
    EXPECT_FALSE(w.cloth.state.flags[v] & kFlagPinned) << k;
    run(3);
  }
  for (uint8_t f : w.cloth.state.flags) EXPECT_FALSE(f & kFlagPinned);
  run(10);
  // All free: the whole cloth falls.
  trig("release", TriggerPhase::kBegin);
  EXPECT_TRUE(has_message(w, "release: no fixed particle"));
}

TEST_P(Ops, ReleaseNeverTakesThePinchedParticle) {
  SetUpWorld(2);
  run(3);
  // Pinch a fixed corner with the right hand, then release right there: the pinch/release
  // conflict.
  set(1, X(top(8)));
  trig("pinch", TriggerPhase::kBegin);
  ASSERT_EQ(c->state().pinched[1], top(8));
  trig("release", TriggerPhase::kBegin);  // nearest fixed other than the pinched: too far
  EXPECT_TRUE(w.cloth.state.flags[top(8)] & kFlagPinched);
  EXPECT_TRUE(w.cloth.state.flags[top(0)] & kFlagPinned);
  // With the release reach covering the other corner (40 cm away), that one goes instead.
  c->params().release_reach = 0.5;
  trig("release", TriggerPhase::kBegin);
  EXPECT_TRUE(w.cloth.state.flags[top(8)] & kFlagPinched);
  EXPECT_FALSE(w.cloth.state.flags[top(0)] & kFlagPinned);
}

// --- pin ---------------------------------------------------------------------------------
void pinch_then_pin(Ops& t) {
  Box box;
  box.centre = Vec3(0, 1.1, 0.25);
  box.half = Vec3(0.1, 0.1, 0.1);
  t.w.scene.boxes.push_back(box);
  int v = t.c->state().pinched[1];
  if (v < 0) {
    v = t.middle();
    t.set(1, t.X(v));
    t.trig("pinch", TriggerPhase::kBegin);
  }
  ASSERT_EQ(t.c->state().pinched[1], v);
  // Carry it to the box's front face (z = 0.15), 3 cm in front.
  const Vec3 goal(0.02, 1.12, 0.12);
  const Vec3 step = (goal - t.hands[1].position) / 30;
  for (int i = 0; i < 30; ++i) {
    t.set(1, t.hands[1].position + step);
    t.run(1);
  }
  const uint64_t h0 = state_hash(t.w.cloth);
  t.trig("pin", TriggerPhase::kBegin);
  ASSERT_TRUE(t.w.cloth.state.flags[v] & kFlagPinned);
  EXPECT_LT(t.c->state().pinched[1], 0);
  t.expect_undo_exact(h0);
  t.set(1, Vec3(0.5, 1.5, 0.5));  // the hand goes away: the pin stays
  t.run(20);
  const Vec3 want(0.02, 1.12, 0.15 - t.w.scene.offset);  // normal toward the hand: -z
  std::printf("pin: landed %.3f mm from the object point + offset; distance to the point %.3f mm\n",
              (t.X(v) - want).norm() * 1e3, t.c->state().last_pin_distance * 1e3);
  EXPECT_LT((t.X(v) - want).norm(), 1e-9);
  EXPECT_NEAR(t.c->state().last_pin_distance, t.w.scene.offset, 1e-12);
  EXPECT_LT(t.c->state().last_pin_landing_error, 1e-9);
  EXPECT_TRUE(has_message(t.w, "landing error"));
}

TEST_P(Ops, PinchThenPin) {
  SetUpWorld(2);
  run(3);
  pinch_then_pin(*this);
}

// Pin without a pinch: the cloth under the hand is pinned onto the object point nearest it (the
// tracked hand's pin gesture follows a released pinch), and undo takes it back exactly.
TEST_P(Ops, PinWithoutAPinchPinsTheClothUnderTheHand) {
  SetUpWorld(2);
  run(3);
  Box box;
  box.centre = Vec3(0, 1.1, 0.25);
  box.half = Vec3(0.1, 0.1, 0.1);
  w.scene.boxes.push_back(box);
  const int v = middle();
  set(1, X(v));
  const uint64_t h0 = state_hash(w.cloth);
  ASSERT_FALSE(w.cloth.state.flags[v] & kFlagPinned);
  trig("pin", TriggerPhase::kBegin);
  ASSERT_TRUE(w.cloth.state.flags[v] & kFlagPinned) << "the particle under the hand";
  EXPECT_LT(c->state().pinched[1], 0);
  expect_undo_exact(h0);
  set(1, Vec3(3, 3, 3));  // far from any cloth: refused, nothing changes
  const uint64_t h1 = state_hash(w.cloth);
  trig("pin", TriggerPhase::kBegin);
  EXPECT_TRUE(has_message(w, "pin: nothing pinched by the right hand and no cloth within"));
  EXPECT_EQ(state_hash(w.cloth), h1);
}

// --- cut ---------------------------------------------------------------------------------
TEST_P(Ops, CutAlongPredeterminedLines) {
  // Vertical, horizontal and diagonal half-lines, and a full horizontal line.
  struct L {
    Vec2 a, b;
    int pieces;
  } lines[] = {{{0.2, 0.4}, {0.2, 0.2}, 1},
               {{0.0, 0.2}, {0.2, 0.2}, 1},
               {{0.4, 0.4}, {0.2, 0.2}, 1},
               {{0.0, 0.15}, {0.4, 0.15}, 2}};
  for (const L& l : lines) {
    SetUpWorld(2);
    run(3);
    const uint64_t h0 = state_hash(w.cloth);
    const int n0 = w.cloth.num_vertices();
    // The stroke as hand samples: the 3D positions of the material points.
    std::vector<Vec3> stroke;
    for (int k = 0; k <= 10; ++k) {
      const Vec2 q = l.a + (l.b - l.a) * k / 10.0;
      SurfacePoint best;
      best.distance = 1e9;
      for (int32_t t = 0; t < w.cloth.topo.num_triangles(); ++t) {
        const auto& tri = w.cloth.topo.triangles[t];
        // material → 3D by barycentric interpolation on the triangle containing q
        const Vec2 a = w.cloth.topo.material[tri[0]], b = w.cloth.topo.material[tri[1]],
                   cc = w.cloth.topo.material[tri[2]];
        const double det = (b - a).x() * (cc - a).y() - (b - a).y() * (cc - a).x();
        const double s = ((q - a).x() * (cc - a).y() - (q - a).y() * (cc - a).x()) / det;
        const double r = ((b - a).x() * (q - a).y() - (b - a).y() * (q - a).x()) / det;
        if (s >= -1e-9 && r >= -1e-9 && s + r <= 1 + 1e-9) {
          best.position = (1 - s - r) * X(tri[0]) + s * X(tri[1]) + r * X(tri[2]);
          best.distance = 0;
          break;
        }
      }
      ASSERT_EQ(best.distance, 0);
      stroke.push_back(best.position);
    }
    c->cut_stroke(w, 1, stroke);
    ASSERT_TRUE(c->state().last_cut.ok) << c->state().last_cut.reason;
    EXPECT_EQ(count_components(w.cloth), l.pieces);
    EXPECT_GT(w.cloth.num_vertices(), n0);
    for (int32_t nv : c->state().last_cut.new_vertices)
      EXPECT_EQ(w.cloth.topo.material[nv], w.cloth.topo.material[w.cloth.topo.vertex_origin[nv]]);
    EXPECT_EQ(c->state().cut_strokes.size(), 1u);
    expect_undo_exact(h0);
    run(60);  // the cut cloth keeps simulating: stable, the cut-off part falls
    if (l.pieces == 2) {
      auto lab = component_labels(w.cloth);
      double ymax_loose = -1e9;
      for (int v = 0; v < w.cloth.num_vertices(); ++v)
        if (lab[v] != lab[top(0)]) ymax_loose = std::max(ymax_loose, X(v).y());
      EXPECT_LT(ymax_loose, 1.0);  // fell below where the cloth started
    }
  }
}

TEST_P(Ops, CutByHandTrajectory) {
  SetUpWorld(2);
  run(150);  // let the cloth come to rest (the rolled one unrolls and hangs)
  // A line of constant v across the whole width, drawn by the hand over the cloth as it is.
  const int row = 6;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0, 0.002);
  set(1, X(row * 9) + (X(row * 9) - X(row * 9 + 8)) * 0.05);
  const uint64_t h0 = state_hash(w.cloth);
  trig("cut", TriggerPhase::kBegin);
  for (int i = 0; i <= 20; ++i) {
    const Vec3 p0 = X(row * 9 + 0), p1 = X(row * 9 + 8);
    const Vec3 p = p0 + (p1 - p0) * (-0.05 + 1.1 * i / 20.0);
    set(1, p + Vec3(noise(rng), noise(rng), noise(rng)));
    tick(w);  // while the stroke is drawn the cloth keeps moving
  }
  // the cloth moved while drawing; stroke samples were taken each tick
  trig("cut", TriggerPhase::kEnd);
  ASSERT_TRUE(c->state().last_cut.ok) << c->state().last_cut.reason;
  EXPECT_EQ(count_components(w.cloth), 2);
  EXPECT_FALSE(c->state().cut_strokes.empty());
  EXPECT_GE(c->state().cut_strokes[0].material.size(), 2u);
  // undo restores the state before the cut (not the one before drawing started)
  trig("undo", TriggerPhase::kBegin);
  EXPECT_EQ(count_components(w.cloth), 1);
  EXPECT_NE(state_hash(w.cloth), h0);  // the cloth moved during the stroke
  run(30);
}

// --- map ---------------------------------------------------------------------------------
TEST_P(Ops, MapWithoutFormIsRefusedWithAReason) {
  SetUpWorld(2);
  const uint64_t h0 = state_hash(w.cloth);
  trig("map", TriggerPhase::kBegin);
  EXPECT_TRUE(has_message(w, "map: no dress form"));
  EXPECT_EQ(state_hash(w.cloth), h0);
}

TEST_P(Ops, MapOntoTheFormAlongCentreFront) {
  SetUpWorld(2);
  ASSERT_NO_FATAL_FAILURE(add_form_9ar());
  const DressForm& f = *w.scene.form;
  const uint64_t h0 = state_hash(w.cloth);
  trig("map", TriggerPhase::kBegin);
  ASSERT_NE(state_hash(w.cloth), h0) << w.messages.back();
  // On the surface (just outside the offset), the middle warp line on centre front (x = centre).
  double worst_gap = 0, worst_cf = 0;
  for (int v = 0; v < w.cloth.num_vertices(); ++v) {
    const double sd = f.signed_distance(X(v));
    if (std::isfinite(sd)) worst_gap = std::max(worst_gap, std::abs(sd - w.scene.offset));
    if (std::abs(w.cloth.topo.material[v].x() - 0.2) < 1e-9) {
      worst_cf = std::max(worst_cf, std::abs(X(v).x() - f.centre_at(X(v).y()).x()));
      EXPECT_GT(X(v).z(), f.centre_at(X(v).y()).y());  // on the front
      EXPECT_TRUE(w.cloth.state.flags[v] & kFlagPinned);
    }
  }
  std::printf(
      "map: worst distance to the form surface + offset %.3f mm, centre line off CF %.3f mm\n",
      worst_gap * 1e3, worst_cf * 1e3);
  EXPECT_LT(worst_gap, 1e-3);
  EXPECT_LT(worst_cf, 1e-6);
  // The top edge sits 3 cm above the waist line.
  EXPECT_NEAR(X(top(4)).y(), f.landmarks().waist_y + 0.03, 1e-9);
  expect_undo_exact(h0);
  run(40);  // then dynamics: stays on the form, stable
  double inside = 0;
  for (int v = 0; v < w.cloth.num_vertices(); ++v)
    if (std::isfinite(f.signed_distance(X(v)))) inside = std::max(inside, -f.signed_distance(X(v)));
  std::printf("map then 40 ticks of dynamics: deepest particle %.2f mm inside the form\n",
              inside * 1e3);
  EXPECT_LT(inside, 0.006);  // the solver's contact penalty, not the mapping (0 mm above)
}

// Asked for by a hand behind the form, the map puts the grain on centre back; the cloth's
// u > uc half wraps toward the right side line (the user's right, seen from behind) with each
// node at its weft distance along the section; the rows nearest the waist and the hip are fixed
// with the top edge and the centre line (the lines the design pipeline's relaxation holds).
TEST_P(Ops, MapFromBehindTheFormPutsTheGrainOnCentreBack) {
  SetUpWorld(2);
  ASSERT_NO_FATAL_FAILURE(add_form_9ar());
  const DressForm& f = *w.scene.form;
  set(1, Vec3(0.1, 1.0, -0.5));  // behind the form
  trig("map", TriggerPhase::kBegin, 1);
  ASSERT_TRUE(has_message(w, "grain on centre back")) << w.messages.back();
  const double pi = 3.14159265358979323846, waist = f.landmarks().waist_y;
  const double hip = f.landmarks().hip_y, sp = 0.05;  // the test panel: 0.4 m, 9 x 9 nodes
  const MappingSurface surf(f, 0.0, false);
  double worst_arc = 0;
  for (int v = 0; v < w.cloth.num_vertices(); ++v) {
    const Vec2 mu = w.cloth.topo.material[v];
    const Vec2 c = f.centre_at(X(v).y());
    const double theta = std::atan2(X(v).x() - c.x(), X(v).z() - c.y());
    const double l = mu.x() - 0.2;
    const ArcTable T = ArcTable::build(surf, X(v).y(), pi, l >= 0 ? +1 : -1);
    worst_arc =
        std::max(worst_arc, std::abs(T.arc_at(std::fmod(theta + 2 * pi, 2 * pi)) - std::abs(l)));
    if (std::abs(l) < 1e-9) {
      EXPECT_LT(X(v).z(), c.y());  // on the back
    }
    if (l > 0.05) {
      EXPECT_LT(X(v).x(), c.x());  // toward the right side line (-x)
    }
    const double below_top = waist + 0.03 - X(v).y();
    const bool line_row = std::abs(below_top - 0.03) < 0.5 * sp ||
                          std::abs(below_top - (waist + 0.03 - hip)) < 0.5 * sp;
    const bool fixed = below_top < 1e-9 || std::abs(l) < 1e-9 || line_row;
    EXPECT_EQ((w.cloth.state.flags[v] & kFlagPinned) != 0, fixed) << "vertex " << v;
  }
  std::printf("map from behind: worst weft distance error along the sections %.4f mm\n",
              worst_arc * 1e3);
  EXPECT_LT(worst_arc, 1e-4);
}

// --- smooth (weak pressure onto the form under the hand) ----------------------------------
TEST(OpsSmooth, PressesTheClothOntoTheFormUnderTheHand) {
  World w = testing::make_world(Initial::kSpread, 2);
  OperationController c;
  c.install(w);
  auto form = DressForm::from_measurements(*measurements_for_size("9AR"));
  ASSERT_TRUE(form.ok()) << form.error();
  w.scene.form = std::make_shared<const DressForm>(std::move(*form));
  const DressForm& f = *w.scene.form;
  double zfront = 0;
  for (double y = 1.0; y <= 1.4; y += 0.01) zfront = std::max(zfront, f.surface_at(y, 0).z());
  for (auto& p : w.cloth.state.x) p.z() = zfront + 0.03;
  w.cloth.state.x_prev = w.cloth.state.x;
  const int v = 4 * 9 + 4, far = 4 * 9 + 0;
  std::array<HandProxy, 2> hands{hand_at(0, Vec3(-1, 2, 1)), hand_at(1, w.cloth.state.x[v])};
  hands[0].tracked = false;
  c.set_hands(w, hands);
  const double d0 = f.signed_distance(w.cloth.state.x[v]);
  const double f0 = f.signed_distance(w.cloth.state.x[far]);
  c.trigger(w, "smooth", TriggerPhase::kBegin, 1);
  for (int i = 0; i < 60; ++i) {
    hands[1].position = w.cloth.state.x[v];
    c.set_hands(w, hands);
    tick(w);
  }
  c.trigger(w, "smooth", TriggerPhase::kEnd, 1);
  const double d1 = f.signed_distance(w.cloth.state.x[v]);
  const double f1 = f.signed_distance(w.cloth.state.x[far]);
  std::printf("smooth: gap under the hand %.1f -> %.1f mm; far from the hand %.1f -> %.1f mm\n",
              d0 * 1e3, d1 * 1e3, f0 * 1e3, f1 * 1e3);
  EXPECT_LT(d1, d0 - 0.01);
  EXPECT_GT(d1, -0.003);  // pressed to surface + offset; the solver's contact allows ~1 mm
  EXPECT_LT(f0 - f1, 0.5 * (d0 - d1));  // local: the far edge is pressed much less
  EXPECT_TRUE(stable(w.cloth));
  // without a form: refused with a reason
  World w2 = testing::make_world(Initial::kSpread, 2);
  OperationController c2;
  c2.install(w2);
  c2.trigger(w2, "smooth", TriggerPhase::kBegin, 1);
  EXPECT_TRUE(has_message(w2, "smooth: no dress form"));
}

// --- combinations ------------------------------------------------------------------------
TEST_P(Ops, PinchReleasePin) {
  SetUpWorld(2);
  run(3);
  // pinch the middle, release a corner with the other hand, then pin the pinched particle.
  set(0, X(top(0)));
  set(1, X(middle()));
  trig("pinch", TriggerPhase::kBegin, 1);
  trig("release", TriggerPhase::kBegin, 0);
  EXPECT_FALSE(w.cloth.state.flags[top(0)] & kFlagPinned);
  run(10);
  pinch_then_pin(*this);  // carries the particle still pinched by the right hand to the box
}

TEST_P(Ops, MovePinchReleaseInAnyOrderAndCount) {
  SetUpWorld(3);
  std::mt19937 rng(GetParam() == Initial::kSpread ? 1 : 2);
  std::uniform_int_distribution<int> op(0, 5);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  for (int k = 0; k < 40; ++k) {
    const int h = k % 2;
    // The hand goes to a random particle.
    const int v = std::uniform_int_distribution<int>(0, w.cloth.num_vertices() - 1)(rng);
    set(h, X(v) + Vec3(jitter(rng), jitter(rng), jitter(rng)) * 0.2);
    switch (op(rng)) {
      case 0:
        trig("move", TriggerPhase::kToggle, h);
        break;
      case 1:
        trig("pinch", TriggerPhase::kBegin, h);
        break;
      case 2:
        trig("pinch", TriggerPhase::kEnd, h);
        break;
      case 3:
        trig("release", TriggerPhase::kBegin, h);
        break;
      case 4:
        trig("undo", TriggerPhase::kBegin, h);
        break;
      default:
        trig("redo", TriggerPhase::kBegin, h);
        break;
    }
    for (int i = 0; i < 5; ++i) {
      set(h, hands[h].position + Vec3(jitter(rng), jitter(rng), jitter(rng)) * 0.05);
      run(1);
    }
    for (int hh = 0; hh < 2; ++hh)
      if (c->state().pinched[hh] >= 0) {
        ASSERT_LT((X(c->state().pinched[hh]) - hands[hh].position).norm(), 1e-3);
      }
    ASSERT_TRUE(w.cloth.validate().empty());
  }
  trig("stop", TriggerPhase::kBegin);
  run(30);
  EXPECT_FALSE(w.last_step.diverged);
}

TEST_P(Ops, CutThenMovePinchRelease) {
  SetUpWorld(2);
  c->cut_stroke(w, 1, {X(2 * 9 + 0) - Vec3(0.01, 0, 0), X(2 * 9 + 8) + Vec3(0.01, 0, 0)});
  ASSERT_TRUE(c->state().last_cut.ok) << c->state().last_cut.reason;
  ASSERT_EQ(count_components(w.cloth), 2);
  // move with both hands, pinch with the right hand while moving, release with the left.
  set(0, X(top(0)));
  set(1, X(top(8)));
  trig("move", TriggerPhase::kBegin);
  for (int i = 0; i < 20; ++i) {
    set(0, hands[0].position + Vec3(0, 0, 0.004));
    set(1, hands[1].position + Vec3(0, 0, 0.004));
    run(1);
  }
  // simultaneous: during the move, the left hand lets its corner go (release during move)
  trig("release", TriggerPhase::kBegin, 0);
  EXPECT_EQ(c->state().move_vertex[0], -1);
  run(10);
  // and pinches a particle of the upper piece while the right hand keeps moving
  set(0, X(5 * 9 + 3));
  trig("pinch", TriggerPhase::kBegin, 0);
  EXPECT_GE(c->state().pinched[0], 0);
  for (int i = 0; i < 20; ++i) {
    set(0, hands[0].position + Vec3(0.003, 0.002, 0));
    set(1, hands[1].position + Vec3(0, 0.002, 0.002));
    run(1);
    EXPECT_LT((X(c->state().pinched[0]) - hands[0].position).norm(), 1e-3);
    EXPECT_LT((X(top(8)) - hands[1].position).norm(), 1e-9);
  }
  trig("pinch", TriggerPhase::kEnd, 0);
  trig("move", TriggerPhase::kEnd);
  run(40);
  EXPECT_EQ(count_components(w.cloth), 2);
}

TEST_P(Ops, BothHandsPinchIndependently) {
  SetUpWorld(2);
  run(3);
  const int a = 3 * 9 + 2, b = 3 * 9 + 6;
  set(0, X(a));
  set(1, X(b));
  trig("pinch", TriggerPhase::kBegin, 0);
  trig("pinch", TriggerPhase::kBegin, 1);
  ASSERT_EQ(c->state().pinched[0], a);
  ASSERT_EQ(c->state().pinched[1], b);
  for (int i = 0; i < 20; ++i) {
    set(0, hands[0].position + Vec3(-0.003, 0.001, 0.002));
    set(1, hands[1].position + Vec3(0.003, -0.001, 0.004));
    run(1);
  }
  EXPECT_LT((X(a) - hands[0].position).norm(), 1e-3);
  EXPECT_LT((X(b) - hands[1].position).norm(), 1e-3);
  // the same particle cannot be taken by both hands
  set(0, X(b));
  trig("pinch", TriggerPhase::kEnd, 0);
  trig("pinch", TriggerPhase::kBegin, 0);
  EXPECT_NE(c->state().pinched[0], b);
}

// --- candidates --------------------------------------------------------------------------
TEST_P(Ops, CandidatesComeFromTheSurfaceUnderTheHand) {
  SetUpWorld(2);
  // Hand 10 cm in front of the cloth (+z), pointing at it (-z: identity orientation), in front
  // of the outermost layer.
  int v = middle();
  if (GetParam() == Initial::kRolled)
    for (int i = 0; i < w.cloth.num_vertices(); ++i)
      if (X(i).z() > X(v).z()) v = i;
  set(1, X(v) + Vec3(0.004, 0.004, 0.10));
  ops_update_candidates(w, c->state(), c->params());
  const auto& hc = c->state().candidates[1];
  ASSERT_FALSE(hc.particles.empty());
  EXPECT_TRUE(hc.particles[0].from_ray);
  std::printf("%s: %zu candidates under the hand; first at %.1f mm\n", initial_name(GetParam()),
              hc.particles.size(), hc.particles[0].distance * 1e3);
  if (GetParam() == Initial::kRolled) {
    // Ray through the roll: several layers, exposed as alternatives in depth order.
    int layers = 0;
    for (const auto& cd : hc.particles) layers += cd.from_ray;
    EXPECT_GE(layers, 2);
  }
  // Snapshot exposure
  SceneSnapshot snap;
  fill_snapshot(w, snap);
  EXPECT_EQ(snap.candidate_vertex[1], hc.chosen_vertex());
  EXPECT_EQ(snap.candidate_alternatives[1].size(), hc.particles.size());
  // choosing an alternative changes what pinch would take
  if (hc.particles.size() > 1) {
    c->select_candidate(w, 1, 1);
    EXPECT_EQ(c->state().candidates[1].chosen_vertex(), hc.particles[1].vertex);
  }
}

// "next" cycles the hand's candidate through select_candidate: each trigger takes the next
// particle of the list and wraps back to the best; its end does nothing.
TEST_P(Ops, NextCyclesTheHandsCandidate) {
  SetUpWorld(2);
  int v = middle();
  if (GetParam() == Initial::kRolled)
    for (int i = 0; i < w.cloth.num_vertices(); ++i)
      if (X(i).z() > X(v).z()) v = i;
  set(1, X(v) + Vec3(0.004, 0.004, 0.10));
  ops_update_candidates(w, c->state(), c->params());
  const int n = static_cast<int>(c->state().candidates[1].particles.size());
  ASSERT_GE(n, 1);
  std::vector<int32_t> seen;
  for (int k = 0; k < n + 1; ++k) {
    seen.push_back(c->state().candidates[1].chosen_vertex());
    trig("next", TriggerPhase::kBegin);
    trig("next", TriggerPhase::kEnd);
  }
  for (int k = 0; k < n; ++k) EXPECT_EQ(seen[k], c->state().candidates[1].particles[k].vertex) << k;
  EXPECT_EQ(seen[n], seen[0]);  // wrapped round
  EXPECT_EQ(c->state().selected[1], 1 % n);
  EXPECT_EQ(c->state().selected[0], 0);  // the other hand's is untouched
}

// --- bad input ---------------------------------------------------------------------------
TEST_P(Ops, BadInputIsIgnoredWithAReason) {
  SetUpWorld(2);
  run(3);
  const uint64_t h0 = state_hash(w.cloth);
  trig("undo", TriggerPhase::kBegin);
  EXPECT_TRUE(has_message(w, "undo: nothing to undo"));
  trig("redo", TriggerPhase::kBegin);
  EXPECT_TRUE(has_message(w, "redo: nothing to redo"));
  EXPECT_EQ(state_hash(w.cloth), h0);
  set(1, X(middle()) + Vec3(0, 0.5, 0));  // no cloth within reach
  trig("pin", TriggerPhase::kBegin);
  EXPECT_TRUE(has_message(w, "pin: nothing pinched"));
  set(1, X(middle()));
  c->cut_stroke(w, 1, {X(middle())});
  EXPECT_TRUE(has_message(w, "fewer than 2 samples"));
  c->cut_stroke(w, 1, {Vec3(3, 3, 3), Vec3(3.5, 3, 3)});
  EXPECT_TRUE(has_message(w, "off the cloth"));
  trig("cut", TriggerPhase::kBegin);
  trig("cut", TriggerPhase::kEnd);  // no tick in between: one sample
  EXPECT_TRUE(has_message(w, "fewer than 2 samples"));
  trig("dance", TriggerPhase::kBegin);
  EXPECT_TRUE(has_message(w, "unknown operation"));
  trig("pinch", TriggerPhase::kBegin, 7);
  EXPECT_TRUE(has_message(w, "hand must be 0 or 1"));
  const double nan = std::nan("");
  w.messages.clear();
  c->cut_stroke(w, 1, {Vec3(nan, 0, 0), Vec3(0, nan, 0), Vec3(0, 0, nan)});  // NaN samples
  EXPECT_TRUE(has_message(w, "fewer than 2 usable samples"));
  EXPECT_EQ(state_hash(w.cloth), h0);
  EXPECT_EQ(c->history().undo_size(), 0u);  // nothing recorded for ignored input
  // Nothing lost: after a real operation, bad input leaves it and its undo intact.
  set(0, X(top(0)) + Vec3(0.01, 0, 0));
  trig("release", TriggerPhase::kBegin, 0);
  ASSERT_EQ(c->history().undo_size(), 1u);
  const uint64_t h1 = state_hash(w.cloth);
  trig("pin", TriggerPhase::kBegin, 0);
  c->cut_stroke(w, 0, {Vec3(3, 3, 3), Vec3(3.5, 3, 3)});
  c->cut_stroke(w, 0, {X(middle())});
  hands[0].position = Vec3(nan, nan, nan);
  c->set_hands(w, hands);
  trig("redo", TriggerPhase::kBegin);
  EXPECT_EQ(state_hash(w.cloth), h1);
  EXPECT_EQ(c->history().undo_size(), 1u);
  trig("undo", TriggerPhase::kBegin);
  EXPECT_EQ(state_hash(w.cloth), h0);
  trig("redo", TriggerPhase::kBegin);
  EXPECT_EQ(state_hash(w.cloth), h1);
  hands[0].position = X(top(0)) + Vec3(0.01, 0, 0);
  c->set_hands(w, hands);
  // NaN pose while pinching: ignored, the particle stays where the hand last was.
  trig("pinch", TriggerPhase::kBegin);
  const int v = c->state().pinched[1];
  ASSERT_GE(v, 0);
  const Vec3 last = hands[1].position;
  hands[1].position = Vec3(std::nan(""), 0, 0);
  c->set_hands(w, hands);
  EXPECT_TRUE(has_message(w, "not finite"));
  tick(w, 5);
  EXPECT_TRUE(stable(w.cloth));
  EXPECT_LT((X(v) - last).norm(), 1e-3);
  hands[1].orientation.coeffs().setConstant(std::nan(""));
  hands[1].position = last;
  c->set_hands(w, hands);
  tick(w, 2);
  EXPECT_TRUE(stable(w.cloth));
  trig("pinch", TriggerPhase::kEnd);
  EXPECT_EQ(w.cloth.validate(), "");
}

// The app's default scenario (assets/scenarios/default.json) replayed through the controller
// with the same hand key frames (one tick per frame): the right hand pinches the draped panel,
// pulls it out, brings it back and pins it; the left controller then draws the cut from 25 cm
// beyond the panel's left edge to 25 cm beyond its right edge, 22 cm below the top edge. The
// cut must separate the panel into two pieces.
TEST(OpsScenario, DefaultScenarioCutSplitsThePanel) {
  Testbed sc = make_form_drape(12);
  ASSERT_TRUE(sc.objects.form);
  World w;
  w.cloth = std::move(sc.cloth);
  w.scene = std::move(sc.objects);
  VbdOptions o;
  o.threads = 1;
  w.solver = std::make_unique<VbdSolver>(o);
  OperationController c;
  c.install(w);
  struct Key {
    int frame;
    Vec3 p;
  };
  const std::vector<Key> right = {
      {0, {0.3, 1.0, 0.6}},      {60, {0.12, 1.02, 0.21}},  {76, {0.12, 1.02, 0.21}},
      {105, {0.14, 1.06, 0.40}}, {130, {0.12, 1.04, 0.21}}, {155, {0.12, 1.04, 0.21}},
      {165, {0.14, 1.04, 0.32}}, {190, {0.3, 1.0, 0.6}},    {300, {0.3, 1.0, 0.6}}};
  const std::vector<Key> left = {{0, {-0.45, 1.17, 0.3}},   {180, {-0.4, 1.17, 0.13}},
                                 {190, {-0.5, 1.17, 0.13}}, {193, {-0.45, 1.17, 0.13}},
                                 {250, {0.5, 1.17, 0.13}},  {253, {0.47, 1.17, 0.13}},
                                 {260, {0.4, 1.17, 0.13}},  {300, {-0.2, 1.2, 0.5}}};
  auto at = [](const std::vector<Key>& k, int f) {
    for (size_t i = 0; i + 1 < k.size(); ++i)
      if (f <= k[i + 1].frame) {
        const double a = double(f - k[i].frame) / (k[i + 1].frame - k[i].frame);
        return Vec3(k[i].p + a * (k[i + 1].p - k[i].p));
      }
    return k.back().p;
  };
  std::array<HandProxy, 2> hands{hand_at(0, at(left, 0)), hand_at(1, at(right, 0))};
  int pieces_before = -1;
  for (int f = 0; f <= 260; ++f) {
    hands[0].position = hands[0].tip = at(left, f);
    hands[1].position = hands[1].tip = at(right, f);
    c.set_hands(w, hands);
    if (f == 76) c.trigger(w, "pinch", TriggerPhase::kBegin, 1);
    if (f == 140) c.trigger(w, "pin", TriggerPhase::kBegin, 1);
    if (f == 165) c.trigger(w, "pinch", TriggerPhase::kEnd, 1);
    if (f == 190) {
      pieces_before = count_components(w.cloth);
      c.trigger(w, "cut", TriggerPhase::kToggle, 0);
    }
    if (f == 250) c.trigger(w, "cut", TriggerPhase::kToggle, 0);
    tick(w);
    ASSERT_TRUE(stable(w.cloth)) << "frame " << f;
  }
  const CutResult& r = c.state().last_cut;
  ASSERT_TRUE(r.ok) << r.reason;
  std::printf(
      "default scenario cut: %zu path vertices, %zu new, %d -> %d pieces, ends extended "
      "to the edge: %d %d\n",
      r.path.size(), r.new_vertices.size(), pieces_before, count_components(w.cloth),
      int(r.extended[0]), int(r.extended[1]));
  EXPECT_EQ(pieces_before, 1);
  EXPECT_EQ(count_components(w.cloth), 2);
  EXPECT_EQ(r.components_after, 2);
  EXPECT_TRUE(w.cloth.validate().empty()) << w.cloth.validate();
}

INSTANTIATE_TEST_SUITE_P(BothInitialStates, Ops,
                         ::testing::Values(Initial::kSpread, Initial::kRolled),
                         [](const auto& info) { return std::string(initial_name(info.param)); });

}  // namespace
}  // namespace drape::sim
