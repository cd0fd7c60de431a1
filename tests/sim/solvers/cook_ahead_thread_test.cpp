// CookAheadSolver: a cut's topology cooked on a worker while the cloth steps on uncut, adopted at
// a fixed step. The swap must land at the same step and give the same cloth bit for bit however
// slow the worker is, the cut's sides must stay together until then and part after it, a
// checkpoint taken in the window must resume bit for bit, and malformed saved state must be
// refused with a reason. (In the TSan build: "thread" in the name.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "sim/ops/cut.hpp"
#include "sim/solvers/cook_ahead.hpp"
#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

namespace {

constexpr int kRes = 24;
constexpr int kTicks = 4;

XpbdOptions options(const Testbed& sc) {
  XpbdOptions o;
  o.air_drag = sc.air_drag;
  o.threads = 2;
  o.min_parallel_triangles = 0;
  o.freeze = true;
  o.finish_thread = false;  // the finish one cycle per step: the same frames on every run
  return o;
}

// The form drape cut across at `at` of its height (material space, between two grid rows).
bool cut_across(Cloth& cloth, double at = 0.5) {
  return cut_across_material(cloth, at + 0.25 / (kRes - 1)).ok;
}

// The largest distance between a vertex the cut made and the vertex it was duplicated from.
double largest_gap(const Cloth& cloth, int before) {
  double g = 0;
  for (int j = before; j < cloth.num_vertices(); ++j)
    g = std::max(g, (cloth.state.x[j] - cloth.state.x[cloth.topo.vertex_origin[j]]).norm());
  return g;
}

struct CutRun {
  uint64_t hash = 0;
  int waits = 0, edits_ahead = 0, edits_in_step = 0;
  int adopted_at = -1;  // steps after the cut's until the solver stepped the cut topology
  double gap_at_swap = -1, gap_after = -1;
  long anchor_renewals = -1;  // by the solver adopted at the swap, in its first step
  int region_builds = -1;     // the self-collision splits the solver at the end has made
  bool same_pool = false;     // the adopted solver steps on the threads that stepped the base
};

// The form drape cut across at half its height after 30 steps and stepped 40 more; with
// second_cut, cut again at a quarter of its height after the first cut's step (inside its
// window). The gaps are those of the last cut. self_collision: the scene's.
CutRun run(int worker_delay_ms, bool second_cut = false, CookAheadOptions o = {},
           int frames_before = 30, bool self_collision = false) {
  Testbed sc = make_scene("form", kRes);
  sc.objects.self_collision = self_collision;
  o.ticks = kTicks;
  o.worker_delay_ms = worker_delay_ms;
  CookAheadSolver s(options(sc), o);
  for (int f = 0; f < frames_before; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
  const ThreadPool* base_pool = s.pool();
  int before = sc.cloth.num_vertices();
  EXPECT_TRUE(cut_across(sc.cloth));
  // The second cut's window opens when the first cut's topology is adopted.
  const int swap = second_cut ? 2 * kTicks : kTicks;
  CutRun r;
  for (int f = 0; f < 40; ++f) {
    if (second_cut && f == 1) {
      before = sc.cloth.num_vertices();
      EXPECT_TRUE(cut_across(sc.cloth, 0.25));
    }
    s.step(sc.cloth, sc.objects, 1.0 / 90);
    if (r.adopted_at < 0 && !s.pending()) {
      r.adopted_at = f;
      r.same_pool = s.pool() == base_pool;
      r.anchor_renewals = s.xpbd().anchor_renewals();
    }
    if (f == swap - 1) r.gap_at_swap = largest_gap(sc.cloth, before);  // the window's last
  }
  r.gap_after = largest_gap(sc.cloth, before);
  r.hash = state_hash(sc.cloth);
  r.region_builds = s.xpbd().self_collision().region_builds();
  r.waits = s.waits();
  r.edits_ahead = s.edits_ahead();
  r.edits_in_step = s.edits_in_step();
  return r;
}

}  // namespace

TEST(CookAhead, TheCutLandsAtTheSameStepWhateverTheWorker) {
  const CutRun fast = run(0);
  const CutRun slow = run(300);  // the worker starts 0.3 s late: the due step waits for it
  EXPECT_EQ(fast.edits_ahead, 1);
  EXPECT_EQ(fast.edits_in_step, 0);
  EXPECT_GE(slow.waits, 1);
  // The cut's step and the next kTicks - 1 step the base; the kTicks-th steps the cut cloth.
  EXPECT_EQ(fast.adopted_at, kTicks);
  EXPECT_EQ(slow.adopted_at, kTicks);
  EXPECT_EQ(fast.hash, slow.hash);
  EXPECT_TRUE(fast.same_pool) << "the adopted solver steps on the base's awake threads";
}

// What the worker does beyond the cook changes when things run, not what they give: its warm-up
// of the first step (XpbdSolver::warm; the swap's step takes over the base's anchors either way)
// and its waits while the steps run (TickGate).
TEST(CookAhead, TheWarmUpAndTheGateChangeNoResult) {
  using K = CookAheadOptions::KeepOff;
  // Cut while falling (the swap's step renews the anchors) and after the drape has come to rest
  // on the form (the swap's step keeps the base's anchors).
  for (const int frames : {30, 300}) {
    SCOPED_TRACE(frames);
    const CutRun plain = run(0, false, {.warm = false, .keep_off_steps = K::kNever}, frames);
    const CutRun warm = run(0, false, {.warm = true, .keep_off_steps = K::kNever}, frames);
    const CutRun gated = run(0, false, {.warm = true, .keep_off_steps = K::kAlways}, frames);
    const CutRun slow = run(50, false, {.warm = true, .keep_off_steps = K::kAlways}, frames);
    EXPECT_EQ(plain.adopted_at, kTicks);
    EXPECT_EQ(gated.adopted_at, kTicks);
    EXPECT_EQ(warm.hash, plain.hash);
    EXPECT_EQ(gated.hash, plain.hash);
    EXPECT_EQ(slow.hash, plain.hash);
    EXPECT_GE(slow.waits, 1);
    std::printf("cut after %d frames: the swap's step renewed the anchors: %s\n", frames,
                warm.anchor_renewals ? "yes" : "no");
    if (frames == 300) {
      EXPECT_EQ(warm.anchor_renewals, 0) << "the base's anchors were not kept";
    }
  }
}

// With self-collision on, the worker's warm-up also splits the cut cloth into self-collision
// regions (the swap's first detection otherwise does): the same cloth, bit for bit.
TEST(CookAhead, SelfCollisionRegionsMadeAheadChangeNoResult) {
  using K = CookAheadOptions::KeepOff;
  const CutRun plain = run(0, false, {.warm = false, .keep_off_steps = K::kNever}, 30, true);
  const CutRun warm = run(0, false, {.warm = true, .keep_off_steps = K::kNever}, 30, true);
  const CutRun slow = run(50, false, {.warm = true, .keep_off_steps = K::kAlways}, 30, true);
  // (self-collision's costlier steps: half as many ticks again for the worker)
  EXPECT_EQ(warm.adopted_at, kTicks * CookAheadOptions{}.self_collision_percent / 100);
  EXPECT_EQ(warm.hash, plain.hash);
  EXPECT_EQ(slow.hash, plain.hash);
  EXPECT_EQ(warm.region_builds, 1) << "the adopted solver split the cut cloth once";
}

TEST(CookAhead, TheSidesStayTogetherUntilTheSwapAndPartAfter) {
  const CutRun r = run(0);
  std::printf("largest gap of the cut: %.3g mm at the window's last step, %.1f mm 35 steps later\n",
              1e3 * r.gap_at_swap, 1e3 * r.gap_after);
  EXPECT_EQ(r.gap_at_swap, 0.0) << "the new vertices follow their sources in the window";
  EXPECT_GT(r.gap_after, 0.005) << "the cut's sides part once the cut topology steps";
}

TEST(CookAhead, TicksGrowWithTheCloth) {
  CookAheadSolver s(XpbdOptions{}, CookAheadOptions{8});
  Testbed small = make_scene("form", 128), large = make_scene("form", 256);
  EXPECT_EQ(s.ticks_for(small.cloth), 8);   // 32 258 triangles
  EXPECT_EQ(s.ticks_for(large.cloth), 32);  // 130 050 triangles
  // With self-collision its steps cost more: the worker gets more of them.
  EXPECT_EQ(s.ticks_for(small.cloth, true), 12);
  EXPECT_EQ(s.ticks_for(large.cloth, true), 48);
}

// A checkpoint in the window (the base stepping, the worker cooking) resumes bit for bit.
TEST(CookAhead, AStateSavedInTheWindowResumesBitForBit) {
  Testbed sc = make_scene("form", kRes);
  CookAheadSolver s(options(sc), CookAheadOptions{kTicks});
  for (int f = 0; f < 30; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
  ASSERT_TRUE(cut_across(sc.cloth));
  for (int f = 0; f < 2; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
  ASSERT_TRUE(s.pending());
  const std::vector<unsigned char> bytes = s.save_state(sc.cloth);
  Cloth saved = sc.cloth;
  for (int f = 0; f < 20; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);

  CookAheadSolver r(options(sc), CookAheadOptions{kTicks});
  ASSERT_EQ(r.restore_state(bytes, saved), "");
  EXPECT_TRUE(r.pending());
  EXPECT_EQ(r.steps_left(), kTicks - 2);
  for (int f = 0; f < 20; ++f) r.step(saved, sc.objects, 1.0 / 90);
  EXPECT_FALSE(r.pending());
  EXPECT_EQ(state_hash(saved), state_hash(sc.cloth));
}

TEST(CookAhead, MalformedStateIsRefusedWithAReason) {
  Testbed sc = make_scene("form", kRes);
  CookAheadSolver s(options(sc), CookAheadOptions{kTicks});
  for (int f = 0; f < 5; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
  ASSERT_TRUE(cut_across(sc.cloth));
  s.step(sc.cloth, sc.objects, 1.0 / 90);
  ASSERT_TRUE(s.pending());
  const std::vector<unsigned char> bytes = s.save_state(sc.cloth);
  CookAheadSolver r(options(sc), CookAheadOptions{kTicks});
  // Cut short, a wrong version, a base that does not fit a cloth without the cut, and steps left
  // out of range.
  std::vector<unsigned char> shortened(bytes.begin(), bytes.begin() + bytes.size() / 2);
  EXPECT_NE(r.restore_state(shortened, sc.cloth).find("cook-ahead state: its bytes are malformed"),
            std::string::npos);
  std::vector<unsigned char> version = bytes;
  version[4] = 9;
  EXPECT_NE(r.restore_state(version, sc.cloth).find("version 9"), std::string::npos);
  Testbed uncut = make_scene("form", kRes);
  EXPECT_NE(r.restore_state(bytes, uncut.cloth).find("does not fit"), std::string::npos);
  // Steps left below zero or beyond the longer window (self-collision's); after the magic and
  // the version, as a little-endian int32.
  for (const int32_t steps : {-1, 1000}) {
    std::vector<unsigned char> far = bytes;
    for (int k = 0; k < 4; ++k) far[8 + k] = static_cast<unsigned char>(uint32_t(steps) >> (8 * k));
    EXPECT_NE(r.restore_state(far, sc.cloth).find("steps left out of range"), std::string::npos)
        << steps;
  }
  // The refused solver steps on as a fresh one.
  EXPECT_FALSE(r.pending());
  r.step(sc.cloth, sc.objects, 1.0 / 90);
  EXPECT_TRUE(sc.cloth.validate().empty());
}

// An edit that removes vertices (an undo of the cut) cannot step on the base: cooked in the step.
TEST(CookAhead, AnUndoOfTheCutIsCookedInTheStep) {
  Testbed sc = make_scene("form", kRes);
  CookAheadSolver s(options(sc), CookAheadOptions{kTicks});
  for (int f = 0; f < 10; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
  const Cloth uncut = sc.cloth;
  ASSERT_TRUE(cut_across(sc.cloth));
  for (int f = 0; f < kTicks + 2; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
  EXPECT_EQ(s.edits_ahead(), 1);
  sc.cloth = uncut;
  s.step(sc.cloth, sc.objects, 1.0 / 90);
  EXPECT_FALSE(s.pending());
  EXPECT_EQ(s.edits_in_step(), 1);
  EXPECT_TRUE(s.xpbd().cooked_for(sc.cloth));
}

// A second cut inside the window maps onto the same base: the base steps on until the first
// cut's topology is adopted, whose window then opens again for the second. Both land ahead (no
// cook in a step), the second's sides stay together until its own swap, and the result does not
// depend on the worker's speed, nor on whether the second cook starts from the spare energy the
// first one copied beside the steps (ClothEnergy::spare_copy) or builds its energy whole.
TEST(CookAhead, ASecondCutInTheWindowLandsAheadToo) {
  const CutRun fast = run(0, true), slow = run(200, true);
  const CutRun whole = run(0, true, {.spare_energy = false});
  EXPECT_EQ(whole.hash, fast.hash);
  std::printf("second cut: gap %.3g mm at its window's last step, %.1f mm after; adopted at %d\n",
              1e3 * fast.gap_at_swap, 1e3 * fast.gap_after, fast.adopted_at);
  EXPECT_EQ(fast.edits_ahead, 2);
  EXPECT_EQ(fast.edits_in_step, 0);
  EXPECT_EQ(slow.edits_ahead, 2);
  EXPECT_EQ(slow.edits_in_step, 0);
  EXPECT_GE(slow.waits, 1);
  EXPECT_EQ(fast.adopted_at, 2 * kTicks);
  EXPECT_EQ(slow.adopted_at, 2 * kTicks);
  EXPECT_EQ(fast.gap_at_swap, 0.0);
  EXPECT_GT(fast.gap_after, 0.005);
  EXPECT_EQ(fast.hash, slow.hash);
}
