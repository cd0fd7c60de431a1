// Recording a draping session (--record DIR) and replaying its journal (drape replay DIR): the
// header that rebuilds the starting World, the World itself (shared with DrapingSession::create,
// so a replay starts from exactly the recorded run's state), and the lock-step replay that feeds
// each journaled input at its tick. Files and formats: docs/sessions.md.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sim/core/types.hpp"
#include "sim/ops/operation_controller.hpp"
#include "sim/runtime/journal.hpp"
#include "sim/runtime/world.hpp"
#include "xr_app/app/xr_app.hpp"

namespace drape::app {

// The journal's header for a session run with `opt`: the scene's options, the solver's and the
// sim thread's settings and the program's version.
sim::JournalHeader journal_header(const XrAppOptions& opt);
// The options of the recorded session from a journal's header; an error names the file and the
// field ("" when all are good).
std::string options_from_header(const sim::JournalHeader& h, const std::string& path,
                                XrAppOptions& opt);

// The session's starting World: the scene of `opt` with the default solver (pieces at rest
// sleep; a free-running sim lands the static finish from its own thread unless `finish_in_tick`).
sim::Result<sim::World> make_session_world(const XrAppOptions& opt, bool finish_in_tick);
// The session's solver (make_session_world's); a checkpoint restarts the sim with a fresh one.
sim::Result<std::unique_ptr<sim::Solver>> make_session_solver(bool finish_in_tick);
// Ticks between checkpoints for `seconds` of session time (0: none).
uint64_t checkpoint_ticks(double seconds);

// On the sim thread: one journaled input (hands, then the operations in order), as
// DrapingSession's posted command applies it.
void apply_input(sim::World& w, sim::OperationController& ops,
                 const std::array<sim::HandProxy, 2>& hands,
                 const std::vector<sim::JournalOp>& use);

struct ReplayResult {
  std::string error;        // "" when the journal replayed
  std::string cut_message;  // the journal's cut-off notice (load_journal), if any
  size_t records = 0;       // tick records fed
  uint64_t ticks = 0;       // ticks run
  uint64_t state_hash = 0;  // the cloth's state hash after them
  bool has_end = false;     // the journal has its end record ...
  uint64_t recorded_hash = 0, recorded_ticks = 0;  // ... with these
  double seconds = 0;                              // wall time of the replay
  uint64_t start_tick = 0;  // the checkpoint's tick it started from (0: the journal's start)
  std::string checkpoint;   // that checkpoint's file name ("" when none)
  // Newer checkpoints passed over and why (not written, cut off, corrupt, another session's).
  std::vector<std::string> notes;
};

// Replays the journal `dir`/journal.bin in lock step on the calling thread: to its end record's
// tick when it has one, else to the tick after its last whole record (or `until_tick` when > 0
// and earlier). It starts from the newest checkpoint the journal names up to there whose file is
// whole (unless `from_start`), feeding only the inputs from its tick on, and restarts the solver
// at the later checkpoints' ticks as the recorded session did. For a resume: the World and its
// operations stay in `world` / `ops`, and `inputs_end` gets where the journal's input records end
// (sim::JournalContents::inputs_end).
ReplayResult replay_journal(const std::string& dir, uint64_t until_tick,
                            std::unique_ptr<sim::World>* world = nullptr,
                            std::shared_ptr<sim::OperationController>* ops = nullptr,
                            uint64_t* inputs_end = nullptr, bool from_start = false);

// The session directory's meta.json: the options, the version and, at the end, the ticks and
// the final state hash.
std::string write_meta(const std::string& dir, const XrAppOptions& opt, const std::string& status,
                       uint64_t ticks, uint64_t state_hash);

}  // namespace drape::app
