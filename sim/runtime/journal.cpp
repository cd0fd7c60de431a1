// The session journal's file format: writer and reader (see journal.hpp).
#include "sim/runtime/journal.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "sim/core/byte_io.hpp"

namespace drape::sim {

namespace {

constexpr char kMagic[8] = {'D', 'R', 'A', 'P', 'E', 'J', 'N', 'L'};
constexpr size_t kPreamble = 12;            // magic + format
constexpr uint32_t kMaxRecord = 16u << 20;  // a larger length is a corrupt record
enum Kind : uint8_t { kHeader = 1, kTick = 2, kEnd = 3, kCheckpoint = 4 };
constexpr auto kFlushEvery = std::chrono::milliseconds(100);

using Out = ByteWriter;
using In = ByteReader;

std::vector<unsigned char> encode_header(const JournalHeader& h) {
  Out o;
  o.u8(kHeader);
  o.fields(h.fields);
  return o.b;
}

std::string at_byte(const std::string& path, uint64_t off) {
  return path + ": byte " + std::to_string(off) + ": ";
}

}  // namespace

uint32_t crc32(const unsigned char* data, size_t n) {
  static const auto table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < n; ++i) c = table[(c ^ data[i]) & 0xFF] ^ (c >> 8);
  return ~c;
}

std::string load_journal(const std::string& path, JournalContents& out) {
  out = JournalContents{};
  std::ifstream f(path, std::ios::binary);
  if (!f) return path + ": cannot open the journal";
  const std::vector<unsigned char> d((std::istreambuf_iterator<char>(f)),
                                     std::istreambuf_iterator<char>());
  out.file_bytes = d.size();
  if (d.size() < kPreamble || std::memcmp(d.data(), kMagic, 8) != 0)
    return path + ": header field 'magic': not a drape journal (no \"DRAPEJNL\" at its start)";
  In pre{d.data() + 8, 4};
  if (const uint32_t fmt = pre.u32(); fmt < 1 || fmt > kJournalFormat)
    return path + ": header field 'format': version " + std::to_string(fmt) +
           " (this program reads 1 to " + std::to_string(kJournalFormat) + ")";
  size_t pos = kPreamble;
  size_t records = 0;
  while (pos < d.size()) {
    const uint64_t start = pos;
    auto cut = [&](const std::string& why) {
      out.cut_message = at_byte(path, start) + why + ": the journal is cut off there; loaded " +
                        std::to_string(records) + " whole records (" + std::to_string(start) +
                        " of " + std::to_string(d.size()) + " bytes)";
    };
    if (d.size() - pos < 8) {
      cut("a record's length and CRC are incomplete");
      break;
    }
    In lh{d.data() + pos, 8};
    const uint32_t len = lh.u32(), crc = lh.u32();
    if (len == 0 || len > kMaxRecord) {
      cut("a record's length " + std::to_string(len) + " is out of range");
      break;
    }
    if (d.size() - pos - 8 < len) {
      cut("a record of " + std::to_string(len) + " bytes is incomplete");
      break;
    }
    const unsigned char* p = d.data() + pos + 8;
    if (crc32(p, len) != crc) {
      cut("a record's CRC does not match");
      break;
    }
    In in{p, len};
    const uint8_t kind = in.u8();
    if (records == 0 && kind != kHeader)
      return at_byte(path, start) + "header field 'kind': the first record is not the header";
    if (kind == kHeader) {
      if (records != 0) {
        cut("a second header record");
        break;
      }
      const uint32_t n = in.u32();
      for (uint32_t i = 0; i < n && in.ok; ++i) {
        std::string k = in.str();
        std::string v = in.str();
        if (in.ok) out.header.fields[k] = v;
      }
      if (!in.ok || in.i != in.n)
        return at_byte(path, start) + "header field 'fields': the header record is malformed";
    } else if (kind == kTick) {
      JournalTick t;
      t.tick = in.u64();
      for (auto& h : t.hands) h = in.hand();
      const uint32_t nops = in.u32();
      for (uint32_t i = 0; i < nops && in.ok; ++i) {
        JournalOp op;
        op.name = in.str();
        op.phase = in.u8();
        op.hand = static_cast<int8_t>(in.u8());
        t.ops.push_back(std::move(op));
      }
      const uint32_t nph = in.u32();
      for (uint32_t i = 0; i < nph && in.ok; ++i) t.phrases.push_back(in.str());
      if (!in.ok || in.i != in.n) {
        cut("a tick record is malformed");
        break;
      }
      out.ticks.push_back(std::move(t));
    } else if (kind == kEnd) {
      JournalEnd e;
      e.ticks = in.u64();
      e.state_hash = in.u64();
      if (!in.ok || in.i != in.n) {
        cut("the end record is malformed");
        break;
      }
      out.end = e;
      out.inputs_end = start;
    } else if (kind == kCheckpoint) {
      JournalCheckpoint c;
      c.tick = in.u64();
      c.file = in.str();
      if (!in.ok || in.i != in.n) {
        cut("a checkpoint record is malformed");
        break;
      }
      out.checkpoints.push_back(std::move(c));
    } else {
      cut("a record of unknown kind " + std::to_string(kind));
      break;
    }
    pos += 8 + len;
    ++records;
    out.whole_bytes = pos;
    if (!out.end) out.inputs_end = pos;
  }
  if (records == 0) {
    out.cut_message.clear();
    return path + ": header field 'header': the journal has no whole header record";
  }
  return "";
}

std::string JournalWriter::create(const std::string& path, const JournalHeader& header) {
  close();
  f_ = std::fopen(path.c_str(), "wb");
  if (!f_) return path + ": cannot create the journal: " + std::strerror(errno);
  path_ = path;
  Out pre;
  pre.b.assign(kMagic, kMagic + 8);
  pre.u32(kJournalFormat);
  if (std::fwrite(pre.b.data(), 1, pre.b.size(), f_) != pre.b.size())
    return path + ": cannot write the journal";
  bytes_ = pre.b.size();
  return put(encode_header(header), true);
}

std::string JournalWriter::append_to(const std::string& path, uint64_t whole_bytes) {
  close();
  std::error_code ec;
  std::filesystem::resize_file(path, whole_bytes, ec);
  if (ec) return path + ": cannot cut the journal to its whole records: " + ec.message();
  f_ = std::fopen(path.c_str(), "ab");
  if (!f_) return path + ": cannot append to the journal: " + std::strerror(errno);
  path_ = path;
  bytes_ = whole_bytes;
  last_flush_ = std::chrono::steady_clock::now();
  return "";
}

std::string JournalWriter::write(const JournalTick& t) {
  Out o;
  o.u8(kTick);
  o.u64(t.tick);
  for (const auto& h : t.hands) o.hand(h);
  o.u32(static_cast<uint32_t>(t.ops.size()));
  for (const auto& op : t.ops) {
    o.str(op.name);
    o.u8(op.phase);
    o.u8(static_cast<uint8_t>(op.hand));
  }
  o.u32(static_cast<uint32_t>(t.phrases.size()));
  for (const auto& p : t.phrases) o.str(p);
  return put(o.b, !t.ops.empty() || !t.phrases.empty());
}

std::string JournalWriter::write(const JournalEnd& e) {
  Out o;
  o.u8(kEnd);
  o.u64(e.ticks);
  o.u64(e.state_hash);
  return put(o.b, true);
}

std::string JournalWriter::write(const JournalCheckpoint& c) {
  Out o;
  o.u8(kCheckpoint);
  o.u64(c.tick);
  o.str(c.file);
  return put(o.b, true);
}

std::string JournalWriter::put(const std::vector<unsigned char>& payload, bool flush_now) {
  if (!f_) return "the journal is not open";
  Out lh;
  lh.u32(static_cast<uint32_t>(payload.size()));
  lh.u32(crc32(payload.data(), payload.size()));
  if (std::fwrite(lh.b.data(), 1, 8, f_) != 8 ||
      std::fwrite(payload.data(), 1, payload.size(), f_) != payload.size())
    return path_ + ": cannot write the journal: " + std::strerror(errno);
  bytes_ += 8 + payload.size();
  const auto now = std::chrono::steady_clock::now();
  if (flush_now || now - last_flush_ >= kFlushEvery) {
    if (std::fflush(f_) != 0) return path_ + ": cannot flush the journal: " + std::strerror(errno);
    last_flush_ = now;
    ++flushes_;
  }
  return "";
}

void JournalWriter::close() {
  if (f_) std::fclose(f_);
  f_ = nullptr;
}

}  // namespace drape::sim
