// The session journal's file format: round trip, a journal cut off mid-record, corrupt records,
// bad headers, continuing a journal.
#include "sim/runtime/journal.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace drape::sim {
namespace {

namespace fs = std::filesystem;

std::string temp_path(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "drape_journal_test";
  fs::create_directories(dir);
  return (dir / name).string();
}

JournalHeader header() {
  JournalHeader h;
  h.fields["resolution"] = "24";
  h.fields["start"] = "pinned-top";
  h.fields["version"] = "0.1";
  return h;
}

JournalTick tick(uint64_t k, bool with_op) {
  JournalTick t;
  t.tick = k;
  t.hands[0].id = 0;
  t.hands[1].id = 1;
  t.hands[1].tracked = true;
  t.hands[1].position = Vec3(0.1 * static_cast<double>(k), 1.25, 1.0 / 3.0);
  t.hands[1].orientation = Eigen::Quaterniond(0.5, 0.5, -0.5, 0.5);
  t.hands[1].tip = t.hands[1].position;
  t.hands[1].radius = 0.02;
  if (with_op) {
    t.ops.push_back({"pinch", 0, 1});
    t.ops.push_back({"cut", 2, 0});
    t.phrases.push_back("cut across");
  }
  return t;
}

std::string write_sample(const std::string& name, int n) {
  const std::string p = temp_path(name);
  JournalWriter w;
  EXPECT_EQ(w.create(p, header()), "");
  for (int k = 0; k < n; ++k) EXPECT_EQ(w.write(tick(static_cast<uint64_t>(k), k % 3 == 0)), "");
  w.close();
  return p;
}

std::vector<char> read_bytes(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& p, const std::vector<char>& b) {
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f.write(b.data(), static_cast<std::streamsize>(b.size()));
}

TEST(Journal, Crc32MatchesTheStandardCheckValue) {
  const std::string s = "123456789";
  EXPECT_EQ(crc32(reinterpret_cast<const unsigned char*>(s.data()), s.size()), 0xCBF43926u);
}

TEST(Journal, RoundTripKeepsEveryFieldBitForBit) {
  const std::string p = write_sample("round_trip.bin", 10);
  JournalContents c;
  ASSERT_EQ(load_journal(p, c), "");
  EXPECT_EQ(c.cut_message, "");
  EXPECT_EQ(c.header.fields, header().fields);
  ASSERT_EQ(c.ticks.size(), 10u);
  for (int k = 0; k < 10; ++k) {
    const JournalTick want = tick(static_cast<uint64_t>(k), k % 3 == 0);
    const JournalTick& got = c.ticks[k];
    EXPECT_EQ(got.tick, want.tick);
    for (int h = 0; h < 2; ++h) {
      EXPECT_EQ(got.hands[h].id, want.hands[h].id);
      EXPECT_EQ(got.hands[h].tracked, want.hands[h].tracked);
      EXPECT_EQ(got.hands[h].position, want.hands[h].position);
      EXPECT_EQ(got.hands[h].orientation.coeffs(), want.hands[h].orientation.coeffs());
      EXPECT_EQ(got.hands[h].tip, want.hands[h].tip);
      EXPECT_EQ(got.hands[h].radius, want.hands[h].radius);
    }
    EXPECT_EQ(got.ops, want.ops);
    EXPECT_EQ(got.phrases, want.phrases);
  }
  EXPECT_FALSE(c.end.has_value());
  EXPECT_EQ(c.whole_bytes, c.file_bytes);
  EXPECT_EQ(c.inputs_end, c.whole_bytes);
}

TEST(Journal, EndRecordLoads) {
  const std::string p = temp_path("end.bin");
  JournalWriter w;
  ASSERT_EQ(w.create(p, header()), "");
  ASSERT_EQ(w.write(tick(0, true)), "");
  ASSERT_EQ(w.write(JournalEnd{42, 0x0123456789abcdefull}), "");
  w.close();
  JournalContents c;
  ASSERT_EQ(load_journal(p, c), "");
  ASSERT_TRUE(c.end.has_value());
  EXPECT_EQ(c.end->ticks, 42u);
  EXPECT_EQ(c.end->state_hash, 0x0123456789abcdefull);
  // A resumed session appends its inputs where the end record starts (it is cut away).
  EXPECT_EQ(c.inputs_end, c.whole_bytes - 8 - 17);
  JournalWriter more;
  ASSERT_EQ(more.append_to(p, c.inputs_end), "");
  ASSERT_EQ(more.write(tick(1, false)), "");
  more.close();
  JournalContents again;
  ASSERT_EQ(load_journal(p, again), "");
  EXPECT_FALSE(again.end.has_value());
  EXPECT_EQ(again.ticks.size(), 2u);
}

TEST(Journal, CutOffMidRecordLoadsItsWholeRecordsAndSaysWhere) {
  const std::string p = write_sample("cut.bin", 6);
  JournalContents full;
  ASSERT_EQ(load_journal(p, full), "");
  std::vector<char> b = read_bytes(p);
  // Every cut inside the last record keeps the first five ticks.
  const uint64_t fifth_end = [&] {
    const std::string q = write_sample("cut_ref.bin", 5);
    return static_cast<uint64_t>(fs::file_size(q));
  }();
  for (uint64_t keep = fifth_end + 1; keep < b.size(); keep += 7) {
    write_bytes(p, std::vector<char>(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(keep)));
    JournalContents c;
    ASSERT_EQ(load_journal(p, c), "") << "cut at " << keep;
    EXPECT_EQ(c.ticks.size(), 5u);
    EXPECT_EQ(c.whole_bytes, fifth_end);
    EXPECT_NE(c.cut_message.find(p), std::string::npos) << c.cut_message;
    EXPECT_NE(c.cut_message.find("byte " + std::to_string(fifth_end)), std::string::npos)
        << c.cut_message;
    EXPECT_NE(c.cut_message.find("cut off"), std::string::npos) << c.cut_message;
  }
}

TEST(Journal, CorruptRecordStopsTheLoadAtIt) {
  const std::string p = write_sample("corrupt.bin", 6);
  const uint64_t third_end = fs::file_size(write_sample("corrupt_ref.bin", 3));
  std::vector<char> b = read_bytes(p);
  b[third_end + 20] ^= 0x40;  // inside the fourth tick record's payload
  write_bytes(p, b);
  JournalContents c;
  ASSERT_EQ(load_journal(p, c), "");
  EXPECT_EQ(c.ticks.size(), 3u);
  EXPECT_NE(c.cut_message.find("CRC"), std::string::npos) << c.cut_message;
  EXPECT_NE(c.cut_message.find("byte " + std::to_string(third_end)), std::string::npos)
      << c.cut_message;
}

TEST(Journal, BadHeadersAreErrorsNamingTheFileAndField) {
  const std::string p = write_sample("bad_header.bin", 2);
  const std::vector<char> good = read_bytes(p);
  struct Case {
    std::vector<char> bytes;
    std::string field;
  };
  std::vector<Case> cases;
  {
    auto b = good;
    b[0] = 'X';
    cases.push_back({b, "'magic'"});
  }
  {
    auto b = good;
    b[8] = 9;
    cases.push_back({b, "'format'"});
  }
  cases.push_back({std::vector<char>(good.begin(), good.begin() + 15), "'header'"});
  {
    auto b = good;
    b[12 + 8 + 3] ^= 1;  // the header record's payload: its CRC fails
    cases.push_back({b, "'header'"});
  }
  cases.push_back({{}, "'magic'"});
  for (const auto& cs : cases) {
    write_bytes(p, cs.bytes);
    JournalContents c;
    const std::string err = load_journal(p, c);
    EXPECT_NE(err.find(p), std::string::npos) << err;
    EXPECT_NE(err.find("header field " + cs.field), std::string::npos) << err;
  }
  JournalContents c;
  const std::string missing = load_journal(temp_path("no_such_journal.bin"), c);
  EXPECT_NE(missing.find("no_such_journal.bin"), std::string::npos) << missing;
}

TEST(Journal, AppendingAfterACutContinuesTheJournal) {
  const std::string p = write_sample("append.bin", 4);
  std::vector<char> b = read_bytes(p);
  b.resize(b.size() - 5);  // the last record cut off
  write_bytes(p, b);
  JournalContents c;
  ASSERT_EQ(load_journal(p, c), "");
  ASSERT_EQ(c.ticks.size(), 3u);
  ASSERT_FALSE(c.cut_message.empty());
  JournalWriter w;
  ASSERT_EQ(w.append_to(p, c.whole_bytes), "");
  ASSERT_EQ(w.write(tick(3, false)), "");
  ASSERT_EQ(w.write(tick(4, true)), "");
  w.close();
  JournalContents again;
  ASSERT_EQ(load_journal(p, again), "");
  EXPECT_EQ(again.cut_message, "");
  ASSERT_EQ(again.ticks.size(), 5u);
  EXPECT_EQ(again.ticks[3].tick, 3u);
  EXPECT_EQ(again.ticks[4].ops, tick(4, true).ops);
}

TEST(Journal, RecordsWithAnOperationReachTheFileAtOnce) {
  const std::string p = temp_path("flush.bin");
  JournalWriter w;
  ASSERT_EQ(w.create(p, header()), "");
  ASSERT_EQ(w.write(tick(0, true)), "");
  // Read while the writer is still open: the record with an operation is already in the file.
  JournalContents c;
  ASSERT_EQ(load_journal(p, c), "");
  EXPECT_EQ(c.ticks.size(), 1u);
  EXPECT_EQ(w.bytes(), c.whole_bytes);
}

}  // namespace
}  // namespace drape::sim
