// The session journal: the sim's inputs as the sim thread received them, so that a session can be
// replayed bit for bit or resumed after a crash (docs/sessions.md).
//
// File layout: the 8-byte magic "DRAPEJNL", a u32 format version, then records. Each record is
// a u32 payload length, a u32 CRC32 of the payload and the payload; the payload's first byte is
// its kind: the header (once, first: key = value fields naming everything needed to rebuild the
// starting World), a tick's input (the tick index, both hands' proxies, the operations applied,
// the voice phrases heard), a checkpoint's tick and file, or the end (the ticks run and the final
// state hash). Integers are little-endian, doubles their IEEE-754 bits, strings a u32 length and
// the bytes.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "sim/core/scene_objects.hpp"

namespace drape::sim {

// 2 adds the checkpoint record; journals of format 1 (without it) are read as well.
inline constexpr uint32_t kJournalFormat = 2;

struct JournalOp {
  std::string name;   // the operation ("pinch", "cut", "undo", ...)
  uint8_t phase = 0;  // sim::TriggerPhase's value (begin, end, toggle)
  int8_t hand = 0;    // 0 left, 1 right
  bool operator==(const JournalOp&) const = default;
};

// The input one command brought to the sim at the start of tick `tick` (ticks completed before
// it). Several records may share a tick (a free-running sim takes every command posted since its
// last tick); they are applied in file order.
struct JournalTick {
  uint64_t tick = 0;
  std::array<HandProxy, 2> hands{};
  std::vector<JournalOp> ops;
  std::vector<std::string> phrases;  // voice phrases heard with this input
};

struct JournalEnd {
  uint64_t ticks = 0;       // ticks the sim ran in all
  uint64_t state_hash = 0;  // sim::state_hash of the cloth after them
};

// A checkpoint of the World taken at the start of tick `tick` (before that tick's inputs), whose
// file `file` (in the journal's directory) is written on another thread after the record: the
// record says that the sim restarted its solver there (sim/ops/checkpoint.hpp), the file may be
// missing when the process ended before it was renamed into place.
struct JournalCheckpoint {
  uint64_t tick = 0;
  std::string file;
};

// The header: named fields (text values). `field` returns "" for a missing one.
struct JournalHeader {
  std::map<std::string, std::string> fields;
  std::string field(const std::string& key) const {
    auto it = fields.find(key);
    return it == fields.end() ? std::string() : it->second;
  }
};

struct JournalContents {
  JournalHeader header;
  std::vector<JournalTick> ticks;
  std::optional<JournalEnd> end;
  std::vector<JournalCheckpoint> checkpoints;  // in file order (ascending ticks)
  uint64_t whole_bytes = 0;                    // bytes up to the end of the last whole record
  // Where the input records end: the end record's offset when there is one, else whole_bytes
  // (a resumed session appends from here).
  uint64_t inputs_end = 0;
  uint64_t file_bytes = 0;
  // Non-empty when the file ends inside a record or a record's CRC fails: names the file and the
  // byte offset where the whole records stop ("... cut off at byte N: loaded K records").
  std::string cut_message;
};

// Reads a journal. A bad magic, format or header record is an error naming the file and the
// field; a journal cut off (or corrupted) after its header loads up to its last whole record and
// says so in cut_message. Returns "" on success, else the error.
std::string load_journal(const std::string& path, JournalContents& out);

// Appends records to a journal. Records are buffered and flushed to the operating system (where a
// crash of the process cannot lose them) at each record with an operation, at the end record and
// whenever 100 ms have passed since the last flush.
class JournalWriter {
 public:
  JournalWriter() = default;
  ~JournalWriter() { close(); }
  JournalWriter(const JournalWriter&) = delete;
  JournalWriter& operator=(const JournalWriter&) = delete;

  // A new journal at `path` (replacing any file there) starting with `header`.
  std::string create(const std::string& path, const JournalHeader& header);
  // Continues the journal at `path`, whose whole records end at `whole_bytes` (load_journal):
  // what follows them (a cut-off record, an end record) is cut away first.
  std::string append_to(const std::string& path, uint64_t whole_bytes);
  std::string write(const JournalTick& t);
  std::string write(const JournalEnd& e);
  std::string write(const JournalCheckpoint& c);  // flushed at once
  void close();
  bool is_open() const { return f_ != nullptr; }
  uint64_t bytes() const { return bytes_; }
  uint64_t flushes() const { return flushes_; }

 private:
  std::string put(const std::vector<unsigned char>& payload, bool flush_now);

  std::FILE* f_ = nullptr;
  std::string path_;
  uint64_t bytes_ = 0, flushes_ = 0;
  std::chrono::steady_clock::time_point last_flush_{};
};

uint32_t crc32(const unsigned char* data, size_t n);

}  // namespace drape::sim
