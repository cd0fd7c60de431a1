// World checkpoints (sim/ops/checkpoint.cpp): the file round trip bit for bit, a world restored
// from a checkpoint that goes on to exactly the state of the world it was taken from (its
// solver's state restored: checkpoint_solver_test.cpp), history entries copied once, and files cut
// off, corrupted or naming vertices the cloth lacks: errors naming the file, the byte and the
// field.
#include "sim/ops/checkpoint.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "sim/ops/cut.hpp"
#include "tests/sim/ops/operations_scene.hpp"

namespace drape::sim {
namespace {

using testing::hand_at;
using testing::Initial;
using testing::tick;

// A stroke across the 9 x 9 panel on its surface: between grid rows j and j + 1.
std::vector<Vec3> across(const Cloth& c, int j) {
  std::vector<Vec3> s;
  for (int i = 0; i < 9; ++i)
    s.push_back(0.5 * (c.state.x[j * 9 + i] + c.state.x[(j + 1) * 9 + i]));
  return s;
}

// A session's world after two cuts and an undo of the second (so the undo and the redo stacks
// both hold entries), with the left hand drawing a cut stroke (an operation in progress).
struct Session {
  World w = testing::make_world(Initial::kSpread, 2);
  OperationController c;
  Session() {
    c.install(w);
    std::array<HandProxy, 2> hands{hand_at(0, Vec3(-0.25, 1.3, 0)),
                                   hand_at(1, w.cloth.state.x[40])};
    c.set_hands(w, hands);
    tick(w, 2);
    c.cut_stroke(w, 0, across(w.cloth, 6));
    EXPECT_TRUE(c.state().last_cut.ok) << c.state().last_cut.reason;
    tick(w, 2);
    c.cut_stroke(w, 0, across(w.cloth, 3));
    EXPECT_TRUE(c.state().last_cut.ok) << c.state().last_cut.reason;
    tick(w, 2);
    c.trigger(w, "undo", TriggerPhase::kBegin, 0);
    c.trigger(w, "cut", TriggerPhase::kBegin, 0);
    for (int i = 0; i < 4; ++i) {
      hands[0].position += Vec3(0.05, 0, 0);
      hands[0].tip = hands[0].position;
      c.set_hands(w, hands);
      tick(w);
    }
  }
  // The stroke goes on across the cloth and ends (a cut), then an undo.
  static void go_on(World& world, OperationController& ctl, int n) {
    std::array<HandProxy, 2> hands = ctl.state().hands;
    for (int i = 0; i < n; ++i) {
      hands[0].position += Vec3(0.02, 0, 0);
      hands[0].tip = hands[0].position;
      ctl.set_hands(world, hands);
      if (i == n / 2) ctl.trigger(world, "cut", TriggerPhase::kEnd, 0);
      if (i == n / 2 + 3) ctl.trigger(world, "undo", TriggerPhase::kBegin, 0);
      tick(world);
    }
  }
};

std::map<std::string, std::string> header() {
  return {{"resolution", "9"}, {"start", "test"}};
}

TEST(Checkpoint, RoundTripIsBitForBit) {
  Session s;
  ASSERT_GT(s.c.history().undo_size(), 0u);
  ASSERT_GT(s.c.history().redo_size(), 0u);
  ASSERT_TRUE(s.c.state().cutting[0]);
  ASSERT_FALSE(s.c.state().stroke[0].empty());
  CheckpointTaker taker;
  s.w.tick = 11;
  auto c = taker.take(s.w, s.c, header());
  const auto bytes = encode_checkpoint(*c);
  WorldCheckpoint back;
  ASSERT_EQ(decode_checkpoint(bytes.data(), bytes.size(), "mem", back), "");
  EXPECT_EQ(encode_checkpoint(back), bytes);
  EXPECT_EQ(back.tick, 11u);
  EXPECT_EQ(back.header, header());
  EXPECT_EQ(state_hash(back.cloth), state_hash(s.w.cloth));
  EXPECT_EQ(back.undo.size(), s.c.history().undo_size());
  EXPECT_EQ(back.redo.size(), s.c.history().redo_size());
  EXPECT_EQ(back.ops.stroke[0], s.c.state().stroke[0]);
  EXPECT_TRUE(back.ops.cutting[0]);
  EXPECT_EQ(back.ops.cut_strokes.size(), s.c.state().cut_strokes.size());
}

TEST(Checkpoint, RestoredWorldGoesOnToTheSameState) {
  Session a;
  CheckpointTaker taker;
  auto c = taker.take(a.w, a.c, header());
  const auto bytes = encode_checkpoint(*c);
  const uint64_t at_checkpoint = state_hash(a.w.cloth);
  const size_t strokes = a.c.state().cut_strokes.size();
  Session::go_on(a.w, a.c, 30);
  EXPECT_NE(state_hash(a.w.cloth), at_checkpoint);
  // The stroke drawn across the checkpoint ended, then the first cut was undone too.
  EXPECT_FALSE(a.c.state().cutting[0]);
  EXPECT_EQ(a.c.history().redo_size(), 2u);
  EXPECT_EQ(a.c.state().cut_strokes.size(), strokes - 1);

  World w = testing::make_world(Initial::kSpread, 2);
  OperationController ctl;
  ctl.install(w);
  WorldCheckpoint back;
  ASSERT_EQ(decode_checkpoint(bytes.data(), bytes.size(), "mem", back), "");
  ASSERT_EQ(restore_checkpoint(back, w, ctl), "");
  Session::go_on(w, ctl, 30);
  EXPECT_EQ(state_hash(w.cloth), state_hash(a.w.cloth));
  EXPECT_EQ(ctl.history().undo_size(), a.c.history().undo_size());
  EXPECT_EQ(ctl.history().redo_size(), a.c.history().redo_size());
  // Undo all the way back: the same states as the original's history.
  while (ctl.history().can_undo()) {
    ctl.trigger(w, "undo", TriggerPhase::kBegin, 0);
    a.c.trigger(a.w, "undo", TriggerPhase::kBegin, 0);
    EXPECT_EQ(state_hash(w.cloth), state_hash(a.w.cloth));
  }
}

TEST(Checkpoint, HistoryEntriesAreCopiedOnceAndShared) {
  Session s;
  CheckpointTaker taker;
  auto c1 = taker.take(s.w, s.c, header());
  auto c2 = taker.take(s.w, s.c, header());
  ASSERT_FALSE(c1->undo.empty());
  EXPECT_EQ(c1->undo.front().get(), c2->undo.front().get());
  s.c.trigger(s.w, "undo", TriggerPhase::kBegin, 0);  // a new redo entry
  auto c3 = taker.take(s.w, s.c, header());
  EXPECT_EQ(c3->redo.size(), c2->redo.size() + 1);
}

std::vector<unsigned char> a_checkpoint() {
  Session s;
  CheckpointTaker taker;
  return encode_checkpoint(*taker.take(s.w, s.c, header()));
}

TEST(Checkpoint, CutOffAnywhereIsNamedWithItsByteAndNotUsed) {
  const auto bytes = a_checkpoint();
  for (size_t n : {size_t{13}, size_t{40}, bytes.size() / 3, bytes.size() / 2, bytes.size() - 1}) {
    WorldCheckpoint out;
    const std::string e = decode_checkpoint(bytes.data(), n, "f.bin", out);
    EXPECT_NE(e.find("f.bin: byte "), std::string::npos) << e;
    EXPECT_NE(e.find("the checkpoint is cut off there"), std::string::npos) << e;
    EXPECT_NE(e.find("not used"), std::string::npos) << e;
  }
}

TEST(Checkpoint, CorruptOrBadFilesNameTheField) {
  auto bytes = a_checkpoint();
  WorldCheckpoint out;
  auto bad = bytes;
  bad[0] = 'X';
  EXPECT_NE(decode_checkpoint(bad.data(), bad.size(), "f.bin", out).find("field 'magic'"),
            std::string::npos);
  bad = bytes;
  bad[8] = 9;
  EXPECT_NE(decode_checkpoint(bad.data(), bad.size(), "f.bin", out).find("field 'format'"),
            std::string::npos);
  bad = bytes;
  bad[bytes.size() / 2] ^= 0x40;
  EXPECT_NE(decode_checkpoint(bad.data(), bad.size(), "f.bin", out).find("CRC does not match"),
            std::string::npos);
  bad = bytes;
  bad.push_back(0);
  EXPECT_NE(decode_checkpoint(bad.data(), bad.size(), "f.bin", out).find("after the end record"),
            std::string::npos);
}

TEST(Checkpoint, AVertexTheClothLacksIsAnError) {
  Session s;
  CheckpointTaker taker;
  auto c = taker.take(s.w, s.c, header());
  c->ops.pinched[1] = s.w.cloth.num_vertices() + 5;
  const auto bytes = encode_checkpoint(*c);
  WorldCheckpoint out;
  const std::string e = decode_checkpoint(bytes.data(), bytes.size(), "f.bin", out);
  EXPECT_NE(e.find("field 'operations'"), std::string::npos) << e;
  EXPECT_NE(e.find("right hand's vertices"), std::string::npos) << e;
}

TEST(Checkpoint, FileIsWrittenWholeOrNotAtAll) {
  Session s;
  CheckpointTaker taker;
  auto c = taker.take(s.w, s.c, header());
  const std::string dir = ::testing::TempDir() + "/checkpoint_test";
  std::filesystem::create_directories(dir);
  ASSERT_EQ(write_checkpoint_file(dir + "/a.bin", *c), "");
  WorldCheckpoint back;
  ASSERT_EQ(load_checkpoint(dir + "/a.bin", back), "");
  EXPECT_EQ(state_hash(back.cloth), state_hash(s.w.cloth));
  EXPECT_FALSE(std::filesystem::exists(dir + "/a.bin.tmp"));
  // Into a directory that does not exist: an error, nothing written.
  EXPECT_NE(write_checkpoint_file(dir + "/none/a.bin", *c), "");
  EXPECT_FALSE(std::filesystem::exists(dir + "/none"));
}

TEST(Checkpoint, WriterKeepsTheNewestFiles) {
  Session s;
  CheckpointTaker taker;
  const std::string dir = ::testing::TempDir() + "/checkpoint_writer";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  {
    CheckpointWriter writer(dir, 2);
    for (uint64_t t = 1; t <= 4; ++t) {
      s.w.tick = t;
      writer.submit(taker.take(s.w, s.c, header()), checkpoint_file_name(t));
      while (writer.written() < static_cast<int>(t)) std::this_thread::yield();
    }
    EXPECT_TRUE(writer.take_errors().empty());
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/checkpoint-2.bin"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/checkpoint-3.bin"));
  WorldCheckpoint back;
  ASSERT_EQ(load_checkpoint(dir + "/checkpoint-4.bin", back), "");
  EXPECT_EQ(back.tick, 4u);
}

}  // namespace
}  // namespace drape::sim
