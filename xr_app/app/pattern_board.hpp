// The live pattern board and the mid-session pattern: the cloth of a published snapshot (never
// the sim's own) extracted into pattern pieces (sim/draping/session_pattern.hpp) on a worker
// thread of its own, so the sim's ticks never wait for it. The worker keeps the board of the
// newest snapshot (at most `period_ms` old when the cloth changes) for the renderer, and writes
// <out_dir>/pattern/session-<n>/ for each export asked for, from the newest snapshot then.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "render/geometry.hpp"
#include "sim/draping/pattern_extract.hpp"
#include "sim/runtime/sim_thread.hpp"
#include "xr_app/app/session_pattern_export.hpp"

namespace drape::app {

// The cloth of a snapshot (positions, material coordinates, triangles, flags) as a sim::Cloth
// whose grid spacing is the median material edge length. Errors name what is inconsistent.
sim::Result<sim::Cloth> cloth_of_snapshot(const sim::SceneSnapshot& snap);
// The pattern pieces of a snapshot's cloth: its finished cuts' strokes as cut edges, notches at
// the form's waist and hip lines (when it has a form).
sim::Result<std::vector<sim::PatternPiece>> snapshot_pieces(const sim::SceneSnapshot& snap);
// What the board draws of the pieces: outlines, grain lines, notch points.
render::PatternBoard board_of(const std::vector<sim::PatternPiece>& pieces);

// One board as built: the tick and fill time of the snapshot it came from.
struct BoardBuild {
  std::shared_ptr<const render::PatternBoard> board;
  uint64_t tick = 0;
  std::chrono::steady_clock::time_point snapshot_at{};
  double build_ms = 0;  // extraction and board (worker thread)
  uint64_t serial = 0;  // 1, 2, ... per build
};

struct PatternWorkerOptions {
  bool board = true;    // keep the live board
  int period_ms = 250;  // the board is rebuilt at most this long after the cloth changed
  std::string out_dir;  // exports go to <out_dir>/pattern/session-<n>/
};

class PatternWorker {
 public:
  PatternWorker(sim::SnapshotReader reader, PatternWorkerOptions opt);
  ~PatternWorker();
  PatternWorker(const PatternWorker&) = delete;
  PatternWorker& operator=(const PatternWorker&) = delete;

  // Asks for an export of the newest snapshot; returns its number n (1, 2, ...).
  int request_export();
  // The newest board (null before the first).
  BoardBuild latest_board() const;
  // The exports finished since the last call (in order).
  std::vector<SessionPatternExport> take_exports();
  // Finishes the exports asked for, then stops the thread. Safe to call twice.
  void stop();
  // The next export's number (the session's end export takes it).
  int next_number() const;

 private:
  void loop();
  void build_board(const sim::SceneSnapshot& snap);
  void run_export(const sim::SceneSnapshot& snap, int n);

  sim::SnapshotReader reader_;
  const PatternWorkerOptions opt_;
  mutable std::mutex m_;
  std::condition_variable cv_;
  std::vector<int> pending_;  // export numbers asked for, under m_
  std::vector<SessionPatternExport> done_;
  BoardBuild board_;
  int next_n_ = 1;
  bool stop_ = false;
  uint64_t built_tick_ = 0;
  uint64_t serial_ = 0;
  std::thread thread_;
};

}  // namespace drape::app
