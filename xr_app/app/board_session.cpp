// The draping session's own operations besides the sim's: the help, the mid-session pattern and
// the cloth's colour map; and the live pattern board's exports and latency (pattern_board.hpp).
#include <chrono>

#include "xr_app/app/draping_session.hpp"

namespace drape::app {

bool DrapingSession::app_operation(const tracking::Action& act, const Op& op) {
  // The help: shown while its gesture or button is held; the spoken "show help" turns it on or
  // off.
  if (op.name == "help") {
    if (act.phase == tracking::Phase::Toggle)
      feedback_.toggle_help();
    else
      feedback_.show_help(act.phase != tracking::Phase::End);
    return true;
  }
  if (op.name == "pattern") {
    if (act.phase != tracking::Phase::End) ask_pattern();
    return true;
  }
  if (op.name == "colours") {
    if (act.phase != tracking::Phase::End) next_colour_map();
    return true;
  }
  return false;
}

// The export runs on the pattern worker from the newest snapshot; the frame loop and the sim go
// on (drain_exports reports it when written).
void DrapingSession::ask_pattern() {
  if (!patterns_ || opt_.out_dir.empty()) {
    const std::string m = "pattern: no output directory for this session: ignored";
    feedback_.refused(0, m);
    rep_.note(m);
    return;
  }
  const int n = patterns_->request_export();
  feedback_.set_status("pattern", "pattern: writing session-" + std::to_string(n) + " ...");
  rep_.note("pattern: session-" + std::to_string(n) + " asked for");
}

// none -> strain -> ease -> none.
void DrapingSession::next_colour_map() {
  using render::ColourMap;
  colour_map_ = colour_map_ == ColourMap::kNone     ? ColourMap::kStrain
                : colour_map_ == ColourMap::kStrain ? ColourMap::kEase
                                                    : ColourMap::kNone;
  const char* name = colour_map_ == ColourMap::kStrain ? "strain"
                     : colour_map_ == ColourMap::kEase ? "ease"
                                                       : "off";
  feedback_.set_status(
      "colours", colour_map_ == ColourMap::kNone
                     ? ""
                     : std::string("colour map: ") + name + " (\"strain map\" again for the next)");
  rep_.note(std::string("colour map: ") + name);
}

void DrapingSession::drain_exports() {
  if (!patterns_) return;
  for (const SessionPatternExport& e : patterns_->take_exports()) {
    rep_.note(e.summary);
    feedback_.set_status("pattern", e.summary);
    for (const auto& f : e.files) rep_.r.written.push_back(f);
    if (e.error.empty()) ++rep_.r.patterns_written;
  }
}

void DrapingSession::note_board_drawn(const BoardBuild& b) {
  if (b.serial == board_drawn_serial_) return;
  board_drawn_serial_ = b.serial;
  const auto now = std::chrono::steady_clock::now();
  const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  rep_.r.profile_ms["board.latency"].push_back(ms(now - b.snapshot_at));
  if (board_drawn_at_ != std::chrono::steady_clock::time_point{})
    rep_.r.profile_ms["board.interval"].push_back(ms(now - board_drawn_at_));
  board_drawn_at_ = now;
  rep_.r.profile_ms["board.build"].push_back(b.build_ms);
  rep_.r.board_pieces = static_cast<int>(b.board->pieces.size());
}

}  // namespace drape::app
