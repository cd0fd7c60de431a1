// The live pattern board and the mid-session export (see pattern_board.hpp).
#include "xr_app/app/pattern_board.hpp"

#include <algorithm>

#include "sim/draping/session_pattern.hpp"
#include "sim/form/dress_form.hpp"

namespace drape::app {

namespace {
// The median material edge length of the triangles (a generated grid's spacing: two of a
// triangle's three edges are axis edges).
double median_edge(const sim::ClothTopology& topo) {
  std::vector<double> len;
  len.reserve(topo.triangles.size() * 3);
  for (const auto& t : topo.triangles)
    for (int k = 0; k < 3; ++k)
      len.push_back((topo.material[t[(k + 1) % 3]] - topo.material[t[k]]).norm());
  if (len.empty()) return 0.01;
  std::nth_element(len.begin(), len.begin() + static_cast<std::ptrdiff_t>(len.size() / 2),
                   len.end());
  return len[len.size() / 2];
}
}  // namespace

sim::Result<sim::Cloth> cloth_of_snapshot(const sim::SceneSnapshot& snap) {
  const size_t n = snap.positions.size();
  if (snap.material.size() != n)
    return sim::Error{"snapshot: " + std::to_string(snap.material.size()) +
                      " material coordinates for " + std::to_string(n) + " vertices"};
  if (snap.indices.size() % 3 != 0)
    return sim::Error{"snapshot: " + std::to_string(snap.indices.size()) +
                      " triangle indices (not a multiple of 3)"};
  sim::Cloth c;
  c.topo.material.resize(n);
  c.state.x.resize(n);
  for (size_t i = 0; i < n; ++i) {
    c.topo.material[i] = snap.material[i].cast<double>();
    c.state.x[i] = snap.positions[i].cast<double>();
  }
  c.state.flags = snap.flags.size() == n ? snap.flags : std::vector<uint8_t>(n, 0);
  c.topo.triangles.reserve(snap.indices.size() / 3);
  for (size_t t = 0; t < snap.indices.size(); t += 3) {
    const uint32_t a = snap.indices[t], b = snap.indices[t + 1], d = snap.indices[t + 2];
    if (a >= n || b >= n || d >= n)
      return sim::Error{"snapshot: triangle " + std::to_string(t / 3) + " names a vertex past " +
                        std::to_string(n)};
    c.topo.triangles.push_back(
        {static_cast<int32_t>(a), static_cast<int32_t>(b), static_cast<int32_t>(d)});
  }
  c.topo.spacing = median_edge(c.topo);
  return c;
}

sim::Result<std::vector<sim::PatternPiece>> snapshot_pieces(const sim::SceneSnapshot& snap) {
  auto cloth = cloth_of_snapshot(snap);
  if (!cloth) return sim::Error{cloth.error()};
  std::vector<std::vector<sim::Vec2>> strokes;
  for (const auto& s : snap.cut_strokes_material) {
    if (s.size() < 2) continue;
    std::vector<sim::Vec2> uv;
    for (const auto& q : s) uv.push_back(q.cast<double>());
    strokes.push_back(std::move(uv));
  }
  sim::SessionPatternOptions opt;
  if (snap.form) {
    opt.waist_y = snap.form->landmarks().waist_y;
    opt.hip_y = snap.form->landmarks().hip_y;
  }
  return sim::extract_session_pieces(*cloth, strokes, opt);
}

render::PatternBoard board_of(const std::vector<sim::PatternPiece>& pieces) {
  render::PatternBoard b;
  for (const auto& p : pieces) {
    render::BoardPiece bp;
    for (const auto& q : p.outline) bp.outline.push_back(q.cast<float>());
    bp.grain_a = p.grain_a.cast<float>();
    bp.grain_b = p.grain_b.cast<float>();
    for (int i : p.notches)
      if (i >= 0 && static_cast<size_t>(i) < p.outline.size())
        bp.notches.push_back(p.outline[i].cast<float>());
    b.pieces.push_back(std::move(bp));
  }
  return b;
}

PatternWorker::PatternWorker(sim::SnapshotReader reader, PatternWorkerOptions opt)
    : reader_(std::move(reader)), opt_(std::move(opt)) {
  thread_ = std::thread([this] { loop(); });
}

PatternWorker::~PatternWorker() {
  stop();
}

int PatternWorker::request_export() {
  int n = 0;
  {
    std::lock_guard lock(m_);
    n = next_n_++;
    pending_.push_back(n);
  }
  cv_.notify_one();
  return n;
}

BoardBuild PatternWorker::latest_board() const {
  std::lock_guard lock(m_);
  return board_;
}

std::vector<SessionPatternExport> PatternWorker::take_exports() {
  std::lock_guard lock(m_);
  std::vector<SessionPatternExport> out;
  out.swap(done_);
  return out;
}

int PatternWorker::next_number() const {
  std::lock_guard lock(m_);
  return next_n_;
}

void PatternWorker::stop() {
  {
    std::lock_guard lock(m_);
    stop_ = true;
  }
  cv_.notify_one();
  if (thread_.joinable()) thread_.join();
}

// Wakes for an export or after period_ms; exports first (all asked for, even when stopping),
// then the board when the snapshot is of a newer tick than the board's.
void PatternWorker::loop() {
  for (;;) {
    std::vector<int> requested;
    bool stopping = false;
    {
      std::unique_lock lock(m_);
      cv_.wait_for(lock, std::chrono::milliseconds(opt_.period_ms),
                   [this] { return stop_ || !pending_.empty(); });
      requested.swap(pending_);
      stopping = stop_;
    }
    if (!reader_.valid()) {  // every reader of the sim taken: said for each export asked for
      for (int n : requested) {
        SessionPatternExport e;
        e.error = "no snapshot reader left for the pattern worker (session-" + std::to_string(n) +
                  " not written)";
        e.summary = "pattern: " + e.error;
        std::lock_guard lock(m_);
        done_.push_back(std::move(e));
      }
      if (stopping) return;
      continue;
    }
    const sim::SceneSnapshot& snap = reader_.latest();
    for (int n : requested) run_export(snap, n);
    if (stopping) return;
    if (opt_.board && snap.tick != built_tick_) build_board(snap);
  }
}

void PatternWorker::run_export(const sim::SceneSnapshot& snap, int n) {
  SessionPatternExport e = export_snapshot_pattern(snap, opt_.out_dir, n);
  std::lock_guard lock(m_);
  done_.push_back(std::move(e));
}

void PatternWorker::build_board(const sim::SceneSnapshot& snap) {
  const auto t0 = std::chrono::steady_clock::now();
  auto pieces = snapshot_pieces(snap);
  built_tick_ = snap.tick;
  if (!pieces) return;  // a cloth with no triangles yet: the board keeps what it showed
  BoardBuild b;
  b.board = std::make_shared<const render::PatternBoard>(board_of(*pieces));
  b.tick = snap.tick;
  b.snapshot_at = snap.filled_at;
  b.build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::lock_guard lock(m_);
  b.serial = ++serial_;
  board_ = std::move(b);
}

}  // namespace drape::app
