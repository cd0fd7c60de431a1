// World checkpoints: encoding, decoding, taking, restoring and the writer thread (see header).
#include "sim/ops/checkpoint.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "sim/core/byte_io.hpp"
#include "sim/core/cloth_io.hpp"
#include "sim/runtime/journal.hpp"

namespace drape::sim {

namespace {

constexpr char kMagic[8] = {'D', 'R', 'A', 'P', 'E', 'C', 'K', 'P'};
constexpr size_t kPreamble = 12;           // magic + format
constexpr uint32_t kMaxRecord = 1u << 30;  // a larger length is a corrupt record
enum Kind : uint8_t { kHeader = 1, kWorld = 2, kOps = 3, kEntry = 4, kEnd = 5, kSolver = 6 };

// A built incidence must describe this cloth's arrays (cut.cpp indexes through it).
std::string check_incidence(const Cloth& c) {
  const ClothIncidence& ci = c.incidence;
  if (!ci.built) return "";
  const size_t n = static_cast<size_t>(c.num_vertices());
  if (ci.start.size() != n || ci.count.size() != n || ci.component.size() != n)
    return "incidence: arrays of another size than the vertices";
  for (size_t v = 0; v < n; ++v) {
    if (ci.start[v] < 0 || ci.count[v] < 0 ||
        static_cast<size_t>(ci.start[v]) + static_cast<size_t>(ci.count[v]) > ci.tris.size())
      return "incidence: vertex " + std::to_string(v) + "'s triangles out of range";
  }
  for (int32_t t : ci.tris)
    if (t < -1 || t >= c.topo.num_triangles()) return "incidence: a triangle index out of range";
  return "";
}

// ---- the scene ---------------------------------------------------------------------------

void put_scene(ByteWriter& o, const SceneObjects& s) {
  put_list(o, s.plates, [](ByteWriter& w, const Plate& p) {
    w.vec3(p.centre);
    w.f64(p.half_x);
    w.f64(p.half_z);
    w.f64(p.thickness);
  });
  put_list(o, s.boxes, [](ByteWriter& w, const Box& b) {
    w.vec3(b.centre);
    w.vec3(b.half);
  });
  put_list(o, s.spheres, [](ByteWriter& w, const Sphere& sp) {
    w.vec3(sp.centre);
    w.f64(sp.radius);
  });
  put_list(o, s.hands, [](ByteWriter& w, const HandProxy& h) { w.hand(h); });
  o.u8(static_cast<uint8_t>((s.floor ? 1 : 0) | (s.self_collision ? 2 : 0)));
  o.f64(s.offset);
  o.f64(s.friction);
}
void get_scene(ByteReader& in, SceneObjects& s) {
  get_list(in, s.plates, 48, [](ByteReader& r) {
    Plate p;
    p.centre = r.vec3();
    p.half_x = r.f64();
    p.half_z = r.f64();
    p.thickness = r.f64();
    return p;
  });
  get_list(in, s.boxes, 48, [](ByteReader& r) {
    Box b;
    b.centre = r.vec3();
    b.half = r.vec3();
    return b;
  });
  get_list(in, s.spheres, 32, [](ByteReader& r) {
    Sphere sp;
    sp.centre = r.vec3();
    sp.radius = r.f64();
    return sp;
  });
  get_list(in, s.hands, 93, [](ByteReader& r) { return r.hand(); });
  const uint8_t flags = in.u8();
  s.floor = flags & 1;
  s.self_collision = (flags & 2) != 0;
  s.offset = in.f64();
  s.friction = in.f64();
}

// ---- the operations ----------------------------------------------------------------------

void put_settling(ByteWriter& o, const std::vector<SettlingPin>& v) {
  put_list(o, v, [](ByteWriter& w, const SettlingPin& p) {
    w.i32(p.vertex);
    w.vec3(p.target);
    w.vec3(p.normal);
    w.i32(p.ticks_left);
  });
}
void get_settling(ByteReader& in, std::vector<SettlingPin>& v) {
  get_list(in, v, 56, [](ByteReader& r) {
    SettlingPin p;
    p.vertex = r.i32();
    p.target = r.vec3();
    p.normal = r.vec3();
    p.ticks_left = r.i32();
    return p;
  });
}

void put_strokes(ByteWriter& o, const std::vector<CutStroke>& v) {
  put_list(o, v, [](ByteWriter& w, const CutStroke& s) {
    put_vec3s(w, s.smooth);
    put_vec2s(w, s.material);
  });
}
void get_strokes(ByteReader& in, std::vector<CutStroke>& v) {
  get_list(in, v, 8, [](ByteReader& r) {
    CutStroke s;
    get_vec3s(r, s.smooth);
    get_vec2s(r, s.material);
    return s;
  });
}

void put_candidates(ByteWriter& o, const HandCandidates& c) {
  put_list(o, c.particles, [](ByteWriter& w, const Candidate& p) {
    w.i32(p.vertex);
    w.f64(p.distance);
    w.u8(p.from_ray ? 1 : 0);
    w.i32(p.layer);
  });
  o.i32(c.chosen);
  o.i32(c.release_vertex);
  o.u8(static_cast<uint8_t>((c.has_object_point ? 1 : 0) | (c.object_is_form ? 2 : 0)));
  o.vec3(c.object_point);
  o.vec3(c.object_normal);
}
void get_candidates(ByteReader& in, HandCandidates& c) {
  get_list(in, c.particles, 17, [](ByteReader& r) {
    Candidate p;
    p.vertex = r.i32();
    p.distance = r.f64();
    p.from_ray = r.u8() != 0;
    p.layer = r.i32();
    return p;
  });
  c.chosen = in.i32();
  c.release_vertex = in.i32();
  const uint8_t flags = in.u8();
  c.has_object_point = flags & 1;
  c.object_is_form = (flags & 2) != 0;
  c.object_point = in.vec3();
  c.object_normal = in.vec3();
}

// The per-hand fields of the operations' state.
void put_hands_state(ByteWriter& o, const OperationsState& s) {
  for (int h = 0; h < 2; ++h) {
    o.hand(s.hands[h]);
    o.u8(static_cast<uint8_t>((s.hand_valid[h] ? 1 : 0) | (s.cutting[h] ? 2 : 0) |
                              (s.smoothing[h] ? 4 : 0) | (s.move_grabbed[h] ? 8 : 0)));
    o.i32(s.pinched[h]);
    put_vec3s(o, s.stroke[h]);
    o.i32(s.move_vertex[h]);
    o.vec3(s.move_offset[h]);
    o.i32(s.selected[h]);
    put_candidates(o, s.candidates[h]);
    o.i32(s.lost_ticks[h]);
  }
}
void get_hands_state(ByteReader& in, OperationsState& s) {
  for (int h = 0; h < 2; ++h) {
    s.hands[h] = in.hand();
    const uint8_t flags = in.u8();
    s.hand_valid[h] = flags & 1;
    s.cutting[h] = (flags & 2) != 0;
    s.smoothing[h] = (flags & 4) != 0;
    s.move_grabbed[h] = (flags & 8) != 0;
    s.pinched[h] = in.i32();
    get_vec3s(in, s.stroke[h]);
    s.move_vertex[h] = in.i32();
    s.move_offset[h] = in.vec3();
    s.selected[h] = in.i32();
    get_candidates(in, s.candidates[h]);
    s.lost_ticks[h] = in.i32();
  }
}

void put_ops(ByteWriter& o, const OperationsState& s) {
  put_hands_state(o, s);
  o.u8(s.moving ? 1 : 0);
  put_settling(o, s.settling);
  put_strokes(o, s.cut_strokes);
  put_list(o, s.loss_reports, [](ByteWriter& w, const std::string& r) { w.str(r); });
  o.f64(s.last_pin_landing_error);
  o.f64(s.last_pin_distance);
}
void get_ops(ByteReader& in, OperationsState& s) {
  get_hands_state(in, s);
  s.moving = in.u8() != 0;
  get_settling(in, s.settling);
  get_strokes(in, s.cut_strokes);
  get_list(in, s.loss_reports, 4, [](ByteReader& r) { return r.str(); });
  s.last_pin_landing_error = in.f64();
  s.last_pin_distance = in.f64();
}

// ---- history entries ---------------------------------------------------------------------

void put_entry(ByteWriter& o, const HistoryEntry& e) {
  o.str(e.label);
  put_cloth(o, e.cloth);
  put_strokes(o, e.cut_strokes);
  o.u8(static_cast<uint8_t>((e.moving ? 1 : 0) | (e.move_grabbed[0] ? 2 : 0) |
                            (e.move_grabbed[1] ? 4 : 0)));
  for (int h = 0; h < 2; ++h) {
    o.i32(e.pinched[h]);
    o.i32(e.move_vertex[h]);
    o.vec3(e.move_offset[h]);
  }
  put_settling(o, e.settling);
}
void get_entry(ByteReader& in, HistoryEntry& e) {
  e.label = in.str();
  get_cloth(in, e.cloth);
  get_strokes(in, e.cut_strokes);
  const uint8_t flags = in.u8();
  e.moving = flags & 1;
  e.move_grabbed = {(flags & 2) != 0, (flags & 4) != 0};
  for (int h = 0; h < 2; ++h) {
    e.pinched[h] = in.i32();
    e.move_vertex[h] = in.i32();
    e.move_offset[h] = in.vec3();
  }
  get_settling(in, e.settling);
}

// ---- validation --------------------------------------------------------------------------

bool vertex_ok(int32_t v, int n) {
  return v >= -1 && v < n;
}

std::string check_cloth(const Cloth& c) {
  if (c.num_vertices() == 0) return "the cloth has no vertices";
  if (std::string e = c.validate(); !e.empty()) return e;
  return check_incidence(c);
}

// Vertex indices the operations keep must name vertices of the cloth they act on (or be -1).
std::string check_ops(const OperationsState& s, int n) {
  for (int h = 0; h < 2; ++h) {
    bool ok = vertex_ok(s.pinched[h], n) && vertex_ok(s.move_vertex[h], n) &&
              vertex_ok(s.candidates[h].release_vertex, n);
    for (const Candidate& p : s.candidates[h].particles) ok = ok && vertex_ok(p.vertex, n);
    if (!ok) return std::string("the ") + (h ? "right" : "left") + " hand's vertices";
  }
  for (const SettlingPin& p : s.settling)
    if (!vertex_ok(p.vertex, n)) return "a settling pin's vertex";
  return "";
}

std::string check_entry(const HistoryEntry& e) {
  if (std::string c = check_cloth(e.cloth); !c.empty()) return c;
  const int n = e.cloth.num_vertices();
  for (int h = 0; h < 2; ++h)
    if (!vertex_ok(e.pinched[h], n) || !vertex_ok(e.move_vertex[h], n)) return "a hand's vertex";
  for (const SettlingPin& p : e.settling)
    if (!vertex_ok(p.vertex, n)) return "a settling pin's vertex";
  return "";
}

// ---- records -----------------------------------------------------------------------------

void put_record(std::vector<unsigned char>& file, const ByteWriter& payload) {
  ByteWriter lh;
  lh.u32(static_cast<uint32_t>(payload.b.size()));
  lh.u32(crc32(payload.b.data(), payload.b.size()));
  file.insert(file.end(), lh.b.begin(), lh.b.end());
  file.insert(file.end(), payload.b.begin(), payload.b.end());
}

ByteWriter header_payload(const WorldCheckpoint& c) {
  ByteWriter o;
  o.u8(kHeader);
  o.fields(c.header);
  o.u64(c.tick);
  o.u64(c.step);
  return o;
}

// The decoder's progress through the records.
struct Decoder {
  const std::string& source;
  WorldCheckpoint& out;
  uint32_t format = kCheckpointFormat;
  bool world = false, ops = false, solver = false, end = false;
  uint32_t undo_expected = 0, redo_expected = 0;
  std::deque<HistoryEntry> undo, redo;
};

std::string at(const std::string& source, size_t off, const std::string& field) {
  return source + ": byte " + std::to_string(off) + ": field '" + field + "': ";
}

std::string decode_header(ByteReader& in, WorldCheckpoint& out) {
  const uint32_t n = in.count(8);
  for (uint32_t i = 0; i < n && in.ok; ++i) {
    std::string k = in.str();
    out.header[k] = in.str();
  }
  out.tick = in.u64();
  out.step = in.u64();
  return in.ok && in.i == in.n ? "" : "the header record is malformed";
}

std::string decode_world(ByteReader& in, Decoder& d) {
  get_cloth(in, d.out.cloth);
  get_scene(in, d.out.scene);
  d.out.paused = in.u8() != 0;
  if (!in.ok || in.i != in.n) return "the world record is malformed";
  d.world = true;
  return check_cloth(d.out.cloth);
}

std::string decode_ops(ByteReader& in, Decoder& d) {
  if (!d.world) return "the operations come before the world";
  get_ops(in, d.out.ops);
  if (!in.ok || in.i != in.n) return "the operations record is malformed";
  d.ops = true;
  return check_ops(d.out.ops, d.out.cloth.num_vertices());
}

std::string decode_solver(ByteReader& in, Decoder& d) {
  if (d.format < kCheckpointFormat) return "a solver record in a file of format 1";
  if (!d.ops || d.solver) return "the solver's state must follow the operations, once";
  d.out.solver = in.str();
  in.array<unsigned char>(d.out.solver_state);
  if (!in.ok || in.i != in.n) return "the solver record is malformed";
  d.solver = true;
  return "";
}

std::string decode_entry(ByteReader& in, Decoder& d) {
  const uint8_t stack = in.u8();
  HistoryEntry e;
  get_entry(in, e);
  if (!in.ok || in.i != in.n || stack > 1) return "a history entry is malformed";
  if (std::string c = check_entry(e); !c.empty()) return "a history entry: " + c;
  (stack == 0 ? d.undo : d.redo).push_back(std::move(e));
  return "";
}

std::string decode_end(ByteReader& in, Decoder& d) {
  d.undo_expected = in.u32();
  d.redo_expected = in.u32();
  if (!in.ok || in.i != in.n) return "the end record is malformed";
  if (!d.world || !d.ops) return "the end record comes before the world and the operations";
  if (d.format >= kCheckpointFormat && !d.solver) return "the end record comes before the solver";
  if (d.undo.size() != d.undo_expected || d.redo.size() != d.redo_expected)
    return "the end record counts other history entries than the file holds";
  d.end = true;
  return "";
}

std::string decode_record(const unsigned char* p, uint32_t len, size_t index, Decoder& d,
                          std::string& field) {
  ByteReader in{p, len};
  const uint8_t kind = in.u8();
  static const char* names[] = {"kind",    "header", "world", "operations",
                                "history", "end",    "solver"};
  field = names[kind <= kSolver ? kind : 0];
  if ((index == 0) != (kind == kHeader)) return "the header must be the first record, once";
  switch (kind) {
    case kHeader:
      return decode_header(in, d.out);
    case kWorld:
      return decode_world(in, d);
    case kOps:
      return decode_ops(in, d);
    case kEntry:
      return decode_entry(in, d);
    case kEnd:
      return decode_end(in, d);
    case kSolver:
      return decode_solver(in, d);
    default:
      return "a record of unknown kind " + std::to_string(kind);
  }
}

// Where the whole records stop in a file that ends early or whose record fails its CRC.
std::string cut_off(const std::string& source, size_t pos, size_t records, size_t n,
                    const std::string& why) {
  return source + ": byte " + std::to_string(pos) + ": " + why +
         ": the checkpoint is cut off there (" + std::to_string(records) + " whole records, " +
         std::to_string(pos) + " of " + std::to_string(n) + " bytes; no end record): not used";
}

// One record's frame at `pos`: "" and the payload's length, or why it is not whole.
std::string frame(const unsigned char* p, size_t n, size_t pos, uint32_t& len) {
  if (n - pos < 8) return "a record's length and CRC are incomplete";
  ByteReader lh{p + pos, 8};
  len = lh.u32();
  const uint32_t crc = lh.u32();
  if (len == 0 || len > kMaxRecord)
    return "a record's length " + std::to_string(len) + " is out of range";
  if (n - pos - 8 < len) return "a record of " + std::to_string(len) + " bytes is incomplete";
  if (crc32(p + pos + 8, len) != crc) return "a record's CRC does not match";
  return "";
}

}  // namespace

std::string checkpoint_file_name(uint64_t tick) {
  return "checkpoint-" + std::to_string(tick) + ".bin";
}

std::vector<unsigned char> encode_checkpoint(const WorldCheckpoint& c) {
  std::vector<unsigned char> file(kMagic, kMagic + 8);
  ByteWriter pre;
  pre.u32(kCheckpointFormat);
  file.insert(file.end(), pre.b.begin(), pre.b.end());
  put_record(file, header_payload(c));
  ByteWriter w;
  w.u8(kWorld);
  put_cloth(w, c.cloth);
  put_scene(w, c.scene);
  w.u8(c.paused ? 1 : 0);
  put_record(file, w);
  ByteWriter o;
  o.u8(kOps);
  put_ops(o, c.ops);
  put_record(file, o);
  ByteWriter sv;
  sv.u8(kSolver);
  sv.str(c.solver);
  sv.array(c.solver_state.data(), c.solver_state.size());
  put_record(file, sv);
  for (uint8_t stack = 0; stack < 2; ++stack) {
    for (const auto& e : stack == 0 ? c.undo : c.redo) {
      ByteWriter h;
      h.u8(kEntry);
      h.u8(stack);
      put_entry(h, *e);
      put_record(file, h);
    }
  }
  ByteWriter end;
  end.u8(kEnd);
  end.u32(static_cast<uint32_t>(c.undo.size()));
  end.u32(static_cast<uint32_t>(c.redo.size()));
  put_record(file, end);
  return file;
}

std::string decode_checkpoint(const unsigned char* p, size_t n, const std::string& source,
                              WorldCheckpoint& out) {
  out = WorldCheckpoint{};
  if (n < kPreamble || std::memcmp(p, kMagic, 8) != 0)
    return at(source, 0, "magic") + "not a drape checkpoint (no \"DRAPECKP\" at its start)";
  ByteReader pre{p + 8, 4};
  const uint32_t fmt = pre.u32();
  if (fmt != kCheckpointFormat && fmt != kCheckpointFormatNoSolver)
    return at(source, 8, "format") + "version " + std::to_string(fmt) + " (this program reads " +
           std::to_string(kCheckpointFormatNoSolver) + " and " + std::to_string(kCheckpointFormat) +
           ")";
  Decoder d{source, out, fmt};
  size_t pos = kPreamble, records = 0;
  while (pos < n && !d.end) {
    uint32_t len = 0;
    if (std::string why = frame(p, n, pos, len); !why.empty())
      return cut_off(source, pos, records, n, why);
    std::string field;
    if (std::string e = decode_record(p + pos + 8, len, records, d, field); !e.empty())
      return at(source, pos, field) + e;
    pos += 8 + len;
    ++records;
  }
  if (!d.end) return cut_off(source, pos, records, n, "the file ends");
  if (pos != n) return at(source, pos, "end") + "bytes after the end record";
  auto share = [](std::deque<HistoryEntry>& from, auto& to) {
    for (HistoryEntry& e : from) to.push_back(std::make_shared<const HistoryEntry>(std::move(e)));
  };
  share(d.undo, out.undo);
  share(d.redo, out.redo);
  return "";
}

std::string load_checkpoint(const std::string& path, WorldCheckpoint& out) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return path + ": cannot open the checkpoint";
  const std::vector<unsigned char> d((std::istreambuf_iterator<char>(f)),
                                     std::istreambuf_iterator<char>());
  return decode_checkpoint(d.data(), d.size(), path, out);
}

std::string write_checkpoint_file(const std::string& path, const WorldCheckpoint& c) {
  const std::vector<unsigned char> bytes = encode_checkpoint(c);
  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) return tmp + ": cannot create: " + std::strerror(errno);
  bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  ok = std::fflush(f) == 0 && ok;
  ok = ::fsync(fileno(f)) == 0 && ok;
  const int err = errno;
  ok = std::fclose(f) == 0 && ok;
  std::error_code ec;
  if (ok) std::filesystem::rename(tmp, path, ec);
  if (!ok || ec) {
    std::filesystem::remove(tmp, ec);
    return path + ": cannot write the checkpoint: " + std::strerror(ok ? EIO : err);
  }
  return "";
}

std::shared_ptr<const HistoryEntry> CheckpointTaker::entry(
    const HistoryEntry& e, std::map<uint64_t, std::shared_ptr<const HistoryEntry>>& kept) {
  auto it = kept_.find(e.serial);
  auto copy = it != kept_.end() ? it->second : std::make_shared<const HistoryEntry>(e);
  kept[e.serial] = copy;
  return copy;
}

std::shared_ptr<WorldCheckpoint> CheckpointTaker::take(
    const World& w, const OperationController& ops,
    const std::map<std::string, std::string>& header) {
  auto c = std::make_shared<WorldCheckpoint>();
  c->header = header;
  c->tick = w.tick;
  c->step = ops.step();
  c->cloth = w.cloth;
  c->scene = w.scene;
  c->scene.form.reset();
  c->paused = w.paused;
  c->ops = ops.state();
  c->ops.last_cut = CutResult{};
  if (w.solver) {
    c->solver = w.solver->name();
    c->solver_state = w.solver->save_state(w.cloth);
  }
  std::map<uint64_t, std::shared_ptr<const HistoryEntry>> kept;
  for (const HistoryEntry& e : ops.history().undo_entries()) c->undo.push_back(entry(e, kept));
  for (const HistoryEntry& e : ops.history().redo_entries()) c->redo.push_back(entry(e, kept));
  kept_ = std::move(kept);
  return c;
}

std::string restore_checkpoint(const WorldCheckpoint& c, World& w, OperationController& ops) {
  w.cloth = c.cloth;
  auto form = w.scene.form;
  w.scene = c.scene;
  w.scene.form = form;
  w.paused = c.paused;
  w.tick = c.tick;
  ops.state() = c.ops;
  ops.set_step(c.step);
  std::deque<HistoryEntry> undo, redo;
  for (const auto& e : c.undo) undo.push_back(*e);
  for (const auto& e : c.redo) redo.push_back(*e);
  ops.history().restore_entries(std::move(undo), std::move(redo));
  if (c.solver_state.empty()) return "";
  if (!w.solver || w.solver->name() != c.solver)
    return "the checkpoint holds the state of the " + c.solver + " solver, the World runs " +
           (w.solver ? "the " + w.solver->name() + " solver" : "none");
  return w.solver->restore_state(c.solver_state, w.cloth);
}

// ---- the writer thread -------------------------------------------------------------------

CheckpointWriter::CheckpointWriter(std::string dir, int keep)
    : dir_(std::move(dir)), keep_(keep), thread_([this] { run(); }) {}

CheckpointWriter::~CheckpointWriter() {
  {
    std::lock_guard<std::mutex> lk(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void CheckpointWriter::submit(std::shared_ptr<const WorldCheckpoint> c, std::string file,
                              std::shared_ptr<void> retire) {
  {
    std::lock_guard<std::mutex> lk(mu_);
    pending_ = std::move(c);
    pending_file_ = std::move(file);
    if (retire) retired_.push_back(std::move(retire));
  }
  cv_.notify_all();
}

std::vector<std::string> CheckpointWriter::take_errors() {
  std::lock_guard<std::mutex> lk(mu_);
  return std::exchange(errors_, {});
}

int CheckpointWriter::written() const {
  std::lock_guard<std::mutex> lk(mu_);
  return written_;
}

void CheckpointWriter::run() {
  std::unique_lock<std::mutex> lk(mu_);
  for (;;) {
    cv_.wait(lk, [this] { return stop_ || pending_ || !retired_.empty(); });
    auto retired = std::exchange(retired_, {});
    auto c = std::exchange(pending_, nullptr);
    const std::string file = pending_file_;
    lk.unlock();
    retired.clear();  // old solvers end here, off the sim thread
    if (c) write_one(*c, file);
    lk.lock();
    if (stop_ && !pending_ && retired_.empty()) return;
  }
}

void CheckpointWriter::write_one(const WorldCheckpoint& c, const std::string& file) {
  const std::string path = dir_ + "/" + file;
  const std::string e = write_checkpoint_file(path, c);
  std::lock_guard<std::mutex> lk(mu_);
  if (!e.empty()) {
    errors_.push_back(e);
    return;
  }
  ++written_;
  files_.push_back(path);
  while (static_cast<int>(files_.size()) > keep_) {
    std::error_code ec;
    std::filesystem::remove(files_.front(), ec);
    files_.erase(files_.begin());
  }
}

}  // namespace drape::sim
