// Checkpoints with the solver's state (sim/ops/checkpoint.cpp, Solver::save_state): a World
// stepped, checkpointed and stepped N ticks more reaches the same state hash as a fresh World
// restored from the checkpoint's file and stepped the same N ticks, bit for bit, with the
// session's solver (XPBD, pieces at rest sleep, the static finish one cycle per tick) on one and
// on two threads, from checkpoints taken while the drape falls, settles, sleeps and finishes, is
// lifted by a hand and settles again.
// Restored with a fresh solver instead, the same checkpoints end elsewhere: the solver's state
// is what makes the difference.
#include <gtest/gtest.h>

#include <cstdio>

#include "sim/ops/checkpoint.hpp"
#include "sim/solvers/solver_factory.hpp"
#include "sim/solvers/watchdog.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"
#include "sim/testbeds/testbed.hpp"

namespace drape::sim {
namespace {

constexpr double kDt = 1.0 / 90;  // the session's tick
constexpr int kRes = 16;
constexpr int kTicks = 1400;
// Falling, settling, asleep (finishing), lifted by a hand, settling again.
const int kCheckpointTicks[] = {30, 450, 650, 920, 1000, 1250};
constexpr int kLift = 900, kLiftEnd = 960;  // a hand lifts a corner 1 mm per tick, then lets go

std::unique_ptr<Solver> session_solver(int threads) {
  SolverConfig cfg;
  cfg.freeze = true;          // as the session's solver (app::make_session_solver)
  cfg.finish_thread = false;  // the finish one cycle per tick: lock step
  cfg.threads = threads;
  auto s = make_solver("xpbd", cfg);
  EXPECT_TRUE(s) << s.error();
  return std::move(s.value());
}

// The cloth falling onto the dress form, with the operations installed (as a session's World).
struct Session {
  World w;
  OperationController ops;
  explicit Session(int threads)
      : w(testbed_world(make_form_drape(kRes, {}, true), session_solver(threads))) {
    ops.install(w);
  }
  void step_to(uint64_t tick) {
    for (; w.tick < tick; ++w.tick) {
      auto& S = w.cloth.state;
      if (w.tick >= kLift && w.tick < kLiftEnd) {
        S.flags[0] |= kFlagPinched;
        S.x[0].y() += 1e-3;
      }
      if (w.tick == kLiftEnd) S.flags[0] &= static_cast<uint8_t>(~kFlagPinched);
      if (w.before_step) w.before_step(w, kDt);
      w.last_step = w.solver->step(w.cloth, w.scene, kDt);
      if (w.after_step) w.after_step(w, kDt);
    }
  }
  const XpbdSolver& xpbd() {
    return dynamic_cast<const XpbdSolver&>(dynamic_cast<WatchdogSolver&>(*w.solver).inner());
  }
};

void same_end_from_every_checkpoint(int threads) {
  Session live(threads);
  std::vector<std::vector<unsigned char>> files;
  CheckpointTaker taker;
  int asleep = 0, finished = 0;
  for (int at : kCheckpointTicks) {
    live.step_to(at);
    files.push_back(encode_checkpoint(*taker.take(live.w, live.ops, {{"start", "form"}})));
    asleep = std::max(asleep, live.xpbd().frozen_count());
    std::printf("tick %d: %d asleep, %d finished\n", at, live.xpbd().frozen_count(),
                live.xpbd().finish_count());
    finished = std::max(finished, live.xpbd().finish_count());
  }
  live.step_to(kTicks);
  const uint64_t want = state_hash(live.w.cloth);
  // The checkpoints saw the drape asleep, and a finish ran (their state is in the files).
  EXPECT_GT(asleep, 0);
  EXPECT_GT(finished + live.xpbd().finish_count(), 0);
  int differ_fresh = 0;
  for (size_t k = 0; k < files.size(); ++k) {
    WorldCheckpoint c;
    ASSERT_EQ(decode_checkpoint(files[k].data(), files[k].size(), "mem", c), "");
    EXPECT_FALSE(c.solver_state.empty());
    for (bool with_state : {true, false}) {
      if (!with_state && k % 2 == 1) continue;
      if (!with_state) c.solver_state.clear();
      Session back(threads);
      ASSERT_EQ(restore_checkpoint(c, back.w, back.ops), "");
      ASSERT_EQ(back.w.tick, static_cast<uint64_t>(kCheckpointTicks[k]));
      back.step_to(kTicks);
      const uint64_t got = state_hash(back.w.cloth);
      if (with_state)
        EXPECT_EQ(got, want) << "from the checkpoint at tick " << kCheckpointTicks[k];
      else
        differ_fresh += got != want;
    }
  }
  EXPECT_GT(differ_fresh, 0) << "a fresh solver ends as the restored one: the test sees nothing";
}

TEST(CheckpointSolver, RestoredWorldEndsBitForBitAsTheLiveOneOneThread) {
  same_end_from_every_checkpoint(1);
}

TEST(CheckpointSolver, RestoredWorldEndsBitForBitAsTheLiveOneTwoThreads) {
  same_end_from_every_checkpoint(2);
}

TEST(CheckpointSolver, StateOfAnotherClothOrSolverIsAnErrorAndLeavesAFreshSolver) {
  Session live(1);
  live.step_to(40);
  CheckpointTaker taker;
  WorldCheckpoint c = *taker.take(live.w, live.ops, {});
  // Another solver.
  c.solver = "vbd";
  Session a(1);
  EXPECT_NE(restore_checkpoint(c, a.w, a.ops).find("the state of the vbd solver"),
            std::string::npos);
  // Bytes that are not a state, and a state cut short.
  c.solver = "xpbd";
  auto state = c.solver_state;
  c.solver_state = {1, 2, 3, 4, 5, 6, 7, 8};
  Session b(1);
  EXPECT_NE(restore_checkpoint(c, b.w, b.ops).find("not an XPBD solver's state"),
            std::string::npos);
  c.solver_state.assign(state.begin(), state.begin() + static_cast<long>(state.size() / 2));
  Session d(1);
  EXPECT_NE(restore_checkpoint(c, d.w, d.ops).find("XPBD state: "), std::string::npos);
  // The solver is then as a fresh one: it steps on as a fresh solver does.
  c.solver_state.clear();
  Session fresh(1);
  ASSERT_EQ(restore_checkpoint(c, fresh.w, fresh.ops), "");
  d.step_to(80);
  fresh.step_to(80);
  EXPECT_EQ(state_hash(d.w.cloth), state_hash(fresh.w.cloth));
}

TEST(CheckpointSolver, FormatOneFilesStillLoadWithAFreshSolver) {
  Session live(1);
  live.step_to(20);
  CheckpointTaker taker;
  WorldCheckpoint c = *taker.take(live.w, live.ops, {});
  // Format 1: the same records without the solver's.
  c.solver_state.clear();
  auto bytes = encode_checkpoint(c);
  WorldCheckpoint two;
  ASSERT_EQ(decode_checkpoint(bytes.data(), bytes.size(), "f.bin", two), "");
  const size_t solver_record = bytes.size();  // found below: the record of kind 6
  size_t pos = 12, at = solver_record;
  while (pos + 8 < bytes.size()) {
    const uint32_t len = bytes[pos] | bytes[pos + 1] << 8 | bytes[pos + 2] << 16 |
                         static_cast<uint32_t>(bytes[pos + 3]) << 24;
    if (bytes[pos + 8] == 6) at = pos;
    if (at == pos) {
      bytes.erase(bytes.begin() + static_cast<long>(pos),
                  bytes.begin() + static_cast<long>(pos + 8 + len));
      break;
    }
    pos += 8 + len;
  }
  ASSERT_LT(at, solver_record);
  WorldCheckpoint one;
  // Without the solver's record the file is cut short for format 2...
  EXPECT_NE(decode_checkpoint(bytes.data(), bytes.size(), "f.bin", one)
                .find("field 'end': the end record comes before the solver"),
            std::string::npos);
  // ... and whole for format 1.
  bytes[8] = 1;
  ASSERT_EQ(decode_checkpoint(bytes.data(), bytes.size(), "f.bin", one), "");
  EXPECT_TRUE(one.solver_state.empty());
  EXPECT_EQ(state_hash(one.cloth), state_hash(live.w.cloth));
  bytes[8] = 3;
  EXPECT_NE(decode_checkpoint(bytes.data(), bytes.size(), "f.bin", one)
                .find("f.bin: byte 8: field 'format': version 3 (this program reads 1 and 2)"),
            std::string::npos);
}

}  // namespace
}  // namespace drape::sim
