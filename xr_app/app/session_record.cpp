// Recording and replaying a draping session's journal (see session_record.hpp).
#include "xr_app/app/session_record.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "sim/runtime/sim_thread.hpp"
#include "sim/solvers/solver_factory.hpp"
#include "sim/testbeds/testbed.hpp"
#include "xr_app/app/desk_scene.hpp"
#include "xr_app/app/draping_session.hpp"

#ifndef DRAPE_VERSION
#define DRAPE_VERSION "unknown"
#endif

namespace drape::app {

namespace {
constexpr int kTickRateHz = 90;
constexpr int kSubsteps = 1;
const char* kSolver = "default";
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

sim::Result<sim::World> make_session_world(const XrAppOptions& opt, bool finish_in_tick) {
  auto scene = opt.start.empty() ? sim::Result<sim::Testbed>(sim::make_form_drape(opt.cloth_res))
                                 : make_desk_scene(opt);
  if (!scene) return sim::Error{"scene: " + scene.error()};
  sim::SolverConfig solver_cfg;
  solver_cfg.freeze = true;  // pieces at rest sleep until a hand, pin or cut disturbs them
  // A lock-step run replays bit for bit: the static finish of a sleeping piece then runs one
  // cycle per tick instead of landing whenever its thread ends.
  solver_cfg.finish_thread = !finish_in_tick;
  auto solver = sim::make_solver(kSolver, solver_cfg);
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

ReplayResult replay_journal(const std::string& dir, uint64_t until_tick,
                            std::unique_ptr<sim::World>* world_out,
                            std::shared_ptr<sim::OperationController>* ops_out,
                            uint64_t* inputs_end) {
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
  sim::SimThreadOptions so;
  so.lock_step = true;
  so.tick_rate_hz = kTickRateHz;
  so.substeps = kSubsteps;
  sim::SimThread sim(std::move(w.value()), so);  // not started: advance() ticks on this thread
  uint64_t end = j.ticks.empty() ? 0 : j.ticks.back().tick + 1;
  if (j.end) {
    r.has_end = true;
    r.recorded_hash = j.end->state_hash;
    r.recorded_ticks = j.end->ticks;
    end = std::max(end, j.end->ticks);
  }
  if (until_tick > 0 && until_tick < end) end = until_tick;
  for (const auto& t : j.ticks) {
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
  first_tick = r.ticks;
  if (!opt_.sim_lock_step) {
    // The replay ran the static finish in the tick; live, it lands from its own thread again.
    sim::SolverConfig cfg;
    cfg.freeze = true;
    cfg.finish_thread = true;
    auto solver = sim::make_solver(kSolver, cfg);
    if (!solver) return sim::Error{"resume: solver: " + solver.error()};
    w->solver = std::move(solver.value());
  }
  return std::move(*w);
}

void DrapingSession::close_record() {
  XrAppResult& r = rep_.r;
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
