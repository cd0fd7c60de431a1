// Recording and replaying a draping session's journal (see session_record.hpp).
#include "xr_app/app/session_record.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "sim/ops/checkpoint.hpp"
#include "sim/runtime/sim_thread.hpp"
#include "sim/solvers/solver_factory.hpp"
#include "sim/testbeds/testbed.hpp"
#include "xr_app/app/desk_scene.hpp"
#include "xr_app/app/draping_session.hpp"
#include "xr_app/app/garment_scene.hpp"

#ifndef DRAPE_VERSION
#define DRAPE_VERSION "unknown"
#endif

namespace drape::app {

namespace {
constexpr int kTickRateHz = 90;
constexpr int kSubsteps = 1;
const char* kSolver = "default";
constexpr int kCookAheadTicks = 8;
constexpr int kSelfCollisionMinRes = 48;  // 10.6 mm edges on the 0.5 m panel
}  // namespace

sim::JournalHeader journal_header(const XrAppOptions& opt) {
  sim::JournalHeader h;
  auto& f = h.fields;
  f["version"] = DRAPE_VERSION;
  f["resolution"] = std::to_string(opt.cloth_res);
  f["start"] = opt.start;
  f["fabric"] = opt.fabric;
  f["fabrics_file"] = opt.fabrics_path;
  f["form_size"] = opt.form_size;
  f["form_measurements"] = opt.form_measurements;
  f["form_mesh"] = opt.form_mesh;
  f["forms_dir"] = opt.forms_dir;
  f["solver"] = kSolver;
  f["freeze"] = "1";
  f["tick_rate_hz"] = std::to_string(kTickRateHz);
  f["substeps"] = std::to_string(kSubsteps);
  f["lock_step"] = opt.sim_lock_step ? "1" : "0";
  f["self_collision"] = opt.self_collision ? "1" : "0";
  // Checkpoints hold the solver's state and the sim goes on with its solver through them
  // (journals without the field restarted the solver at each checkpoint).
  f["solver_state"] = "1";
  // A session opened from a saved file (drape open) has no start to replay from: its journal
  // starts from the file's copy (checkpoint record and file in the session directory).
  if (!opt.open_file.empty()) f["opened"] = opt.open_file;
  return h;
}

std::string options_from_header(const sim::JournalHeader& h, const std::string& path,
                                XrAppOptions& opt) {
  auto bad = [&](const std::string& field, const std::string& why) {
    return path + ": header field '" + field + "': " + why;
  };
  for (const char* k : {"version", "resolution", "start", "fabric", "form_size", "solver",
                        "tick_rate_hz", "substeps", "lock_step"})
    if (!h.fields.count(k)) return bad(k, "missing");
  try {
    size_t used = 0;
    const std::string res = h.field("resolution");
    opt.cloth_res = std::stoi(res, &used);
    if (used != res.size() || opt.cloth_res < 4 || opt.cloth_res > 256)
      return bad("resolution", "'" + res + "' is not a resolution of 4-256");
  } catch (const std::exception&) {
    return bad("resolution", "'" + h.field("resolution") + "' is not a number");
  }
  opt.start = h.field("start");
  if (!opt.start.empty() && !is_desk_start(opt.start))
    return bad("start", "'" + opt.start + "' is not one of " + desk_start_names());
  if (h.field("solver") != kSolver)
    return bad("solver", "'" + h.field("solver") + "' (this program records '" + kSolver + "')");
  if (h.field("tick_rate_hz") != std::to_string(kTickRateHz))
    return bad("tick_rate_hz", "'" + h.field("tick_rate_hz") + "' (this program runs " +
                                   std::to_string(kTickRateHz) + ")");
  if (h.field("substeps") != std::to_string(kSubsteps))
    return bad("substeps", "'" + h.field("substeps") + "' (this program runs " +
                               std::to_string(kSubsteps) + ")");
  const std::string ls = h.field("lock_step");
  if (ls != "0" && ls != "1") return bad("lock_step", "'" + ls + "' is not 0 or 1");
  opt.sim_lock_step = ls == "1";
  // (Optional: journals recorded before the field existed ran without self-collision.)
  const std::string sc = h.fields.count("self_collision") ? h.field("self_collision") : "0";
  if (sc != "0" && sc != "1") return bad("self_collision", "'" + sc + "' is not 0 or 1");
  opt.self_collision = sc == "1";
  opt.fabric = h.field("fabric");
  opt.fabrics_path = h.field("fabrics_file");
  opt.form_size = h.field("form_size");
  opt.form_measurements = h.field("form_measurements");
  opt.form_mesh = h.field("form_mesh");
  opt.forms_dir = h.field("forms_dir");
  return "";
}

sim::Result<std::unique_ptr<sim::Solver>> make_session_solver(bool finish_in_tick) {
  sim::SolverConfig solver_cfg;
  solver_cfg.freeze = true;  // pieces at rest sleep until a hand, pin or cut disturbs them
  // A lock-step run replays bit for bit: the static finish of a sleeping piece then runs one
  // cycle per tick instead of landing whenever its thread ends.
  solver_cfg.finish_thread = !finish_in_tick;
  // A cut's new topology is cooked on a worker while the cloth steps on uncut for 8 ticks (per
  // 32 768 triangles): no tick stalls on the cook, and a replay swaps at the same tick.
  solver_cfg.cook_ahead_ticks = kCookAheadTicks;
  return sim::make_solver(kSolver, solver_cfg);
}

uint64_t checkpoint_ticks(double seconds) {
  if (seconds <= 0) return 0;
  return std::max<uint64_t>(1, static_cast<uint64_t>(std::llround(seconds * kTickRateHz)));
}

sim::Result<sim::World> make_session_world(const XrAppOptions& opt, bool finish_in_tick) {
  if (!opt.garment.empty()) return make_garment_world(opt);  // its own solver (XPBD, ties)
  auto scene = opt.start.empty() ? sim::Result<sim::Testbed>(sim::make_form_drape(opt.cloth_res))
                                 : make_desk_scene(opt);
  if (!scene) return sim::Error{"scene: " + scene.error()};
  auto solver = make_session_solver(finish_in_tick);
  if (!solver) return sim::Error{"solver: " + solver.error()};
  sim::World w;
  w.cloth = std::move(scene->cloth);
  w.scene = std::move(scene->objects);
  // Self-collision only on cloths fine enough for its vertex-triangle pairs: on a coarse grid
  // (edges several times the 7 mm reach) layers pass between the vertices, and pairs found
  // after a crossing hold the layers on the wrong sides (a pinched 16^2 panel locks into a
  // crumpled band).
  w.scene.self_collision = opt.self_collision && opt.cloth_res >= kSelfCollisionMinRes;
  w.solver = std::move(solver.value());
  return w;
}

void apply_input(sim::World& w, sim::OperationController& ops,
                 const std::array<sim::HandProxy, 2>& hands,
                 const std::vector<sim::JournalOp>& use) {
  ops.set_hands(w, hands);
  w.scene.hands.assign(hands.begin(), hands.end());  // into the snapshot (latency probe)
  for (const auto& op : use)
    ops.trigger(w, op.name, static_cast<sim::TriggerPhase>(op.phase), op.hand);
}

namespace {

// The journal's replay ends: its end record's tick when it has one, else the tick after its last
// whole record, or `until_tick` when earlier.
uint64_t replay_end(const sim::JournalContents& j, uint64_t until_tick, ReplayResult& r) {
  uint64_t end = j.ticks.empty() ? 0 : j.ticks.back().tick + 1;
  if (j.end) {
    r.has_end = true;
    r.recorded_hash = j.end->state_hash;
    r.recorded_ticks = j.end->ticks;
    end = std::max(end, j.end->ticks);
  }
  if (until_tick > 0 && until_tick < end) end = until_tick;
  return end;
}

// The scene fields a checkpoint must share with its journal (the program's version may differ
// after a resume by a newer build; a saved session opened may run in another sim mode, and may
// have been saved before checkpoints held the solver's state).
bool same_session(std::map<std::string, std::string> a, std::map<std::string, std::string> b) {
  for (const char* k : {"version", "opened", "lock_step", "solver_state"}) {
    a.erase(k);
    b.erase(k);
  }
  return a == b;
}

bool plain_checkpoint_name(const std::string& f) {
  return f.rfind("checkpoint-", 0) == 0 && f.find('/') == std::string::npos && f.size() > 15 &&
         f.compare(f.size() - 4, 4, ".bin") == 0;
}

// The newest checkpoint the journal names at or before `end` whose file loads whole and belongs
// to the journal's session; why a newer one was passed over goes to `notes`.
std::optional<sim::WorldCheckpoint> newest_checkpoint(const std::string& dir,
                                                      const sim::JournalContents& j, uint64_t end,
                                                      std::vector<std::string>& notes) {
  bool first = true;
  for (auto it = j.checkpoints.rbegin(); it != j.checkpoints.rend(); ++it) {
    if (it->tick > end || it->tick == 0) continue;
    const std::string p = dir + "/" + it->file;
    std::error_code ec;
    if (!plain_checkpoint_name(it->file) || !std::filesystem::exists(p, ec)) {
      if (first) notes.push_back(p + ": not there (the session ended before it was written)");
      first = false;
      continue;
    }
    first = false;
    sim::WorldCheckpoint c;
    if (std::string e = sim::load_checkpoint(p, c); !e.empty()) {
      notes.push_back(e);
      continue;
    }
    if (c.tick != it->tick || !same_session(c.header, j.header.fields)) {
      notes.push_back(p + ": field 'header': another session's checkpoint: not used");
      continue;
    }
    return c;
  }
  return std::nullopt;
}

// Journals recorded before checkpoints held the solver's state (no header field
// `solver_state`): the sim restarted its solver at each checkpoint the journal records after
// `after`, and so does their replay.
void restart_solver_at_checkpoints(sim::World& w, const sim::JournalContents& j, uint64_t after) {
  std::set<uint64_t> ticks;
  for (const auto& c : j.checkpoints)
    if (c.tick > after) ticks.insert(c.tick);
  w.at_tick_start = nullptr;
  if (ticks.empty() || j.header.field("solver_state") == "1") return;
  w.at_tick_start = [ticks](sim::World& wd) {
    if (!ticks.count(wd.tick)) return;
    auto s = make_session_solver(true);
    if (s) wd.solver = std::move(s.value());
  };
}

}  // namespace

ReplayResult replay_journal(const std::string& dir, uint64_t until_tick,
                            std::unique_ptr<sim::World>* world_out,
                            std::shared_ptr<sim::OperationController>* ops_out,
                            uint64_t* inputs_end, bool from_start) {
  ReplayResult r;
  const auto t0 = std::chrono::steady_clock::now();
  const std::string path = dir + "/journal.bin";
  sim::JournalContents j;
  if (std::string e = sim::load_journal(path, j); !e.empty()) {
    r.error = e;
    return r;
  }
  r.cut_message = j.cut_message;
  if (inputs_end) *inputs_end = j.inputs_end;
  XrAppOptions opt;
  if (std::string e = options_from_header(j.header, path, opt); !e.empty()) {
    r.error = e;
    return r;
  }
  auto w = make_session_world(opt, true);
  if (!w) {
    r.error = path + ": " + w.error();
    return r;
  }
  auto ops = std::make_shared<sim::OperationController>();
  ops->install(w.value());
  const uint64_t end = replay_end(j, until_tick, r);
  if (auto c = from_start ? std::nullopt : newest_checkpoint(dir, j, end, r.notes)) {
    if (std::string e = sim::restore_checkpoint(*c, w.value(), *ops); !e.empty()) {
      r.error = dir + "/" + sim::checkpoint_file_name(c->tick) + ": field 'solver': " + e;
      return r;
    }
    r.start_tick = c->tick;
    r.checkpoint = sim::checkpoint_file_name(c->tick);
  } else if (!j.header.field("opened").empty()) {
    r.error = path + ": header field 'opened': the session was opened from " +
              j.header.field("opened") + " and has no start to replay from" +
              (from_start ? "" : ", and no whole checkpoint");
    return r;
  }
  restart_solver_at_checkpoints(w.value(), j, r.start_tick);
  sim::SimThreadOptions so;
  so.lock_step = true;
  so.tick_rate_hz = kTickRateHz;
  so.substeps = kSubsteps;
  so.first_tick = r.start_tick;
  sim::SimThread sim(std::move(w.value()), so);  // not started: advance() ticks on this thread
  for (const auto& t : j.ticks) {
    if (t.tick < r.start_tick) continue;
    if (t.tick >= end) break;
    if (t.tick > sim.ticks()) sim.advance(static_cast<int>(t.tick - sim.ticks()));
    sim.post(
        [ops, hands = t.hands, use = t.ops](sim::World& wd) { apply_input(wd, *ops, hands, use); });
    ++r.records;
  }
  if (end > sim.ticks()) sim.advance(static_cast<int>(end - sim.ticks()));
  r.ticks = sim.ticks();
  r.state_hash = sim::state_hash(sim.world().cloth);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (world_out) *world_out = std::make_unique<sim::World>(std::move(sim.world()));
  if (ops_out) *ops_out = ops;
  return r;
}

std::string write_meta(const std::string& dir, const XrAppOptions& opt, const std::string& status,
                       uint64_t ticks, uint64_t state_hash) {
  nlohmann::json j;
  j["version"] = DRAPE_VERSION;
  j["status"] = status;
  j["journal"] = "journal.bin";
  nlohmann::json header;
  for (const auto& [k, v] : journal_header(opt).fields) header[k] = v;
  j["options"] = header;
  j["scenario"] = opt.scenario_path;
  j["hands"] = opt.hands;
  j["voice"] = opt.voice_input;
  j["ticks"] = ticks;
  char hash[24];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(state_hash));
  j["final_state_hash"] = status == "ended" ? std::string(hash) : std::string();
  const std::string p = dir + "/meta.json";
  std::ofstream o(p);
  o << j.dump(2) << "\n";
  return o ? "" : p + ": cannot write";
}

}  // namespace drape::app

// The draping session's side of --record.
namespace drape::app {

void DrapingSession::open_record() {
  std::error_code ec;
  std::filesystem::create_directories(opt_.record_dir, ec);
  auto journal = std::make_shared<sim::JournalWriter>();
  const std::string path = opt_.record_dir + "/journal.bin";
  const std::string e = resume_inputs_end_ > 0 ? journal->append_to(path, resume_inputs_end_)
                                               : journal->create(path, journal_header(opt_));
  if (!e.empty()) {
    rep_.note("record: " + e + " (the session goes on unrecorded)");
    return;
  }
  if (!opt_.open_file.empty() && resume_inputs_end_ == 0) {
    // The opened file's copy is the journal's start (replay_journal starts from it).
    const std::string name = sim::checkpoint_file_name(opened_tick_);
    std::error_code ec;
    std::filesystem::copy_file(opt_.open_file, opt_.record_dir + "/" + name,
                               std::filesystem::copy_options::overwrite_existing, ec);
    const std::string je = ec ? "" : journal->write(sim::JournalCheckpoint{opened_tick_, name});
    if (ec || !je.empty()) {
      rep_.note("record: " + (ec ? opt_.record_dir + "/" + name + ": " + ec.message() : je) +
                " (the session goes on unrecorded)");
      return;
    }
  }
  journal_ = journal;
  if (std::string m = write_meta(opt_.record_dir, opt_, "running", 0, 0); !m.empty())
    rep_.note("record: " + m);
  rep_.note("record: journal " + opt_.record_dir + "/journal.bin");
  if (opt_.hands != "xr") {
    // A resumed session's frames go to a file of their own: a trace starts at its own time 0.
    const std::string hp =
        opt_.record_dir + (resume_inputs_end_ > 0 ? "/hands_resumed.csv" : "/hands.csv");
    hands_csv_ = std::make_unique<tracking::TraceRecorder>(hp);
    if (!hands_csv_->ok()) {
      rep_.note("record: " + hp + ": cannot write (hands not recorded)");
      hands_csv_.reset();
    }
  }
}

void DrapingSession::record_hand_frames(const std::vector<tracking::HandFrame>& frames) {
  if (!hands_csv_) return;
  for (const auto& f : frames) hands_csv_->write(f);
}

sim::Result<sim::World> DrapingSession::resume_world(uint64_t& first_tick) {
  std::unique_ptr<sim::World> w;
  const ReplayResult r = replay_journal(opt_.resume_dir, 0, &w, &ops_, &resume_inputs_end_);
  if (!r.error.empty()) return sim::Error{"resume: " + r.error};
  if (!r.cut_message.empty()) rep_.note("resume: " + r.cut_message);
  char line[160];
  std::snprintf(line, sizeof line,
                "resume: replayed %zu input records, %llu ticks in %.2f s (state hash %016llx)",
                r.records, static_cast<unsigned long long>(r.ticks), r.seconds,
                static_cast<unsigned long long>(r.state_hash));
  rep_.note(line);
  for (const auto& n : r.notes) rep_.note("resume: " + n);
  rep_.note(r.checkpoint.empty()
                ? "resume: from the session's start"
                : "resume: from " + r.checkpoint + " (tick " + std::to_string(r.start_tick) + ")");
  first_tick = r.ticks;
  if (!opt_.sim_lock_step) {
    // The replay ran the static finish in the tick; live, it lands from its own thread again.
    auto solver = make_session_solver(false);
    if (!solver) return sim::Error{"resume: solver: " + solver.error()};
    // The replayed solver's state goes on in it (sleep, settling, anchors).
    const std::string e = solver.value()->restore_state(w->solver->save_state(w->cloth), w->cloth);
    if (!e.empty()) rep_.note("resume: " + e + " (the solver starts afresh)");
    w->solver = std::move(solver.value());
  }
  return std::move(*w);
}

namespace {

// On the sim thread at the start of a checkpoint's tick: the journal's record first, then the
// copy of the World (its solver's state included) handed to the writer.
void take_checkpoint(sim::World& w, sim::OperationController& ops, sim::JournalWriter& journal,
                     sim::CheckpointTaker& taker, sim::CheckpointWriter& writer,
                     const std::map<std::string, std::string>& header) {
  for (const std::string& e : writer.take_errors()) w.report("checkpoint: " + e);
  const std::string file = sim::checkpoint_file_name(w.tick);
  if (std::string e = journal.write(sim::JournalCheckpoint{w.tick, file}); !e.empty()) {
    w.report("checkpoint: " + e + " (recording stopped)");
    journal.close();
    return;
  }
  writer.submit(taker.take(w, ops, header), file);
}

}  // namespace

void DrapingSession::install_checkpoints(sim::World& w) {
  w.at_tick_start = nullptr;  // a resumed World keeps its replay's hook otherwise
  const uint64_t every = checkpoint_ticks(opt_.checkpoint_every_s);
  if (!journal_ || !ops_ || every == 0) return;
  checkpoints_ = std::make_unique<sim::CheckpointWriter>(opt_.record_dir);
  auto taker = std::make_shared<sim::CheckpointTaker>();
  w.at_tick_start = [every, taker, journal = journal_, ops = ops_, writer = checkpoints_.get(),
                     header = journal_header(opt_).fields,
                     cost = checkpoint_cost_](sim::World& world) {
    if (world.tick == 0 || world.tick % every != 0 || !journal->is_open()) return;
    const auto t0 = std::chrono::steady_clock::now();
    take_checkpoint(world, *ops, *journal, *taker, *writer, header);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    cost->store(std::max(cost->load(), ms));
  };
}

void DrapingSession::close_record() {
  XrAppResult& r = rep_.r;
  if (checkpoints_) {
    const int written = checkpoints_->written();
    for (const std::string& e : checkpoints_->take_errors()) rep_.note("checkpoint: " + e);
    checkpoints_.reset();  // the pending checkpoint is written first
    char line[128];
    std::snprintf(line, sizeof line,
                  "record: %d checkpoints written; taking one cost at most %.2f ms on the sim "
                  "thread",
                  written, checkpoint_cost_->load());
    rep_.note(line);
  }
  if (journal_->is_open()) {
    if (std::string e = journal_->write(sim::JournalEnd{r.final_ticks, r.final_state_hash});
        !e.empty())
      rep_.note("record: " + e);
    journal_->close();
  }
  char line[96];
  std::snprintf(line, sizeof line, "record: final state hash %016llx at tick %llu",
                static_cast<unsigned long long>(r.final_state_hash),
                static_cast<unsigned long long>(r.final_ticks));
  rep_.note(line);
  if (std::string m = write_meta(opt_.record_dir, opt_, "ended", r.final_ticks, r.final_state_hash);
      !m.empty())
    rep_.note("record: " + m);
  const std::string tp = opt_.record_dir + "/session.txt";
  r.written.push_back(opt_.record_dir + "/journal.bin");
  write_session_text(tp, !opt_.resume_dir.empty());  // a resumed session's log goes after its own
}

}  // namespace drape::app
