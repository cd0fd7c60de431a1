// The live pattern board and the mid-session export (xr_app/app/pattern_board.hpp): the pieces
// of a snapshot's cloth are those of the sim's own cloth (outline extents, areas, cut edges); the
// board carries each piece's outline, grain line and notches; the worker builds boards from the
// sim's snapshots and writes each export asked for into its own numbered directory; a snapshot
// that does not hold together is an error naming what is wrong.
#include "xr_app/app/pattern_board.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <thread>

#include "sim/draping/session_pattern.hpp"
#include "sim/ops/cut.hpp"
#include "sim/solvers/verlet_solver.hpp"

using namespace drape;
namespace fs = std::filesystem;

namespace {

// A 0.4 m square panel (41 x 41 nodes, 10 mm), flat: x = u, y = v, z = 0.
sim::Cloth flat_panel() {
  sim::PanelSpec spec;
  spec.width = spec.height = 0.4;
  spec.nx = spec.ny = 41;
  spec.spacing = 0.01;
  sim::Cloth c = sim::make_panel(spec, sim::FabricParams{});
  sim::place_spread(c, sim::Vec3::Zero(), sim::Vec3::UnitX(), sim::Vec3::UnitY());
  return c;
}

// A gentle slanted curve across the panel, edge to edge (material space).
std::vector<sim::Vec2> stroke() {
  std::vector<sim::Vec2> s;
  for (int k = 0; k <= 80; ++k) {
    const double u = 0.4 * k / 80.0;
    s.emplace_back(u, 0.2 + 0.03 * std::sin(u / 0.4 * 6.283185307179586) + 0.1 * (u - 0.2));
  }
  return s;
}

// The panel cut along the stroke, with its snapshot as the sim publishes it (the stroke on the
// flat cloth as the operations put it there).
struct CutWorld {
  sim::World world;
  sim::SceneSnapshot snap;
};
CutWorld cut_world() {
  CutWorld c;
  c.world.cloth = flat_panel();
  const sim::CutResult r = sim::cut_along_material(c.world.cloth, stroke());
  EXPECT_TRUE(r.ok) << r.reason;
  c.world.decorate_snapshot = [](const sim::World&, sim::SceneSnapshot& s) {
    std::vector<sim::Vec2f> uv;
    for (const auto& q : stroke()) uv.push_back(q.cast<float>());
    s.cut_strokes_material = {uv};
  };
  sim::fill_snapshot(c.world, c.snap);
  return c;
}

struct Box {
  sim::Vec2 lo{1e9, 1e9}, hi{-1e9, -1e9};
};
Box extent(const std::vector<sim::Vec2>& pts) {
  Box b;
  for (const auto& p : pts) {
    b.lo = b.lo.cwiseMin(p);
    b.hi = b.hi.cwiseMax(p);
  }
  return b;
}

}  // namespace

TEST(PatternBoard, SnapshotPiecesAreTheClothsPieces) {
  CutWorld c = cut_world();
  auto from_snap = app::snapshot_pieces(c.snap);
  ASSERT_TRUE(from_snap) << from_snap.error();
  auto direct = sim::extract_session_pieces(c.world.cloth, {stroke()});
  ASSERT_TRUE(direct) << direct.error();
  ASSERT_EQ(from_snap->size(), 2u);
  ASSERT_EQ(from_snap->size(), direct->size());
  for (size_t i = 0; i < direct->size(); ++i) {
    const Box a = extent((*from_snap)[i].outline), b = extent((*direct)[i].outline);
    const double err =
        std::max((a.lo - b.lo).cwiseAbs().maxCoeff(), (a.hi - b.hi).cwiseAbs().maxCoeff());
    std::printf("piece %zu: outline extent differs by %.2e m, area %.6f vs %.6f m^2\n", i, err,
                (*from_snap)[i].area(), (*direct)[i].area());
    EXPECT_LT(err, 1e-5);  // float snapshot coordinates
    EXPECT_NEAR((*from_snap)[i].area(), (*direct)[i].area(), 1e-6);
    // The cut edge is the stroke, as in the session pattern.
    EXPECT_NEAR((*from_snap)[i].seam_length(sim::kSessionCutLabel),
                (*direct)[i].seam_length(sim::kSessionCutLabel), 1e-5);
    EXPECT_GT((*from_snap)[i].seam_length(sim::kSessionCutLabel), 0.4);
  }
}

TEST(PatternBoard, BoardHoldsOutlinesGrainAndNotches) {
  CutWorld c = cut_world();
  sim::SessionPatternOptions opt;
  opt.waist_y = 0.35;  // a line across the upper piece's side edges
  opt.hip_y = 0.05;    // and the lower's
  auto pieces = sim::extract_session_pieces(c.world.cloth, {stroke()}, opt);
  ASSERT_TRUE(pieces) << pieces.error();
  const render::PatternBoard b = app::board_of(*pieces);
  ASSERT_EQ(b.pieces.size(), pieces->size());
  for (size_t i = 0; i < b.pieces.size(); ++i) {
    const auto& bp = b.pieces[i];
    const auto& pc = (*pieces)[i];
    ASSERT_EQ(bp.outline.size(), pc.outline.size());
    for (size_t k = 0; k < bp.outline.size(); ++k)
      EXPECT_LT((bp.outline[k].cast<double>() - pc.outline[k]).norm(), 1e-6);
    EXPECT_EQ(bp.notches.size(), pc.notches.size());
    EXPECT_EQ(bp.notches.size(), 2u) << "piece " << i << ": a line crosses both side edges";
    // The grain line runs along the warp (v), inside the piece's extent.
    const sim::Vec2 g = (pc.grain_b - pc.grain_a);
    EXPECT_GT(g.norm(), 0.05);
    EXPECT_LT(std::abs(g.x()), 1e-9);
    EXPECT_LT((bp.grain_a.cast<double>() - pc.grain_a).norm(), 1e-6);
  }
}

TEST(PatternBoard, InconsistentSnapshotIsAnErrorNamingIt) {
  CutWorld c = cut_world();
  sim::SceneSnapshot s = c.snap;
  s.material.pop_back();
  auto r = app::cloth_of_snapshot(s);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("material coordinates"), std::string::npos) << r.error();
  s = c.snap;
  s.indices.back() = static_cast<uint32_t>(s.positions.size());
  auto r2 = app::snapshot_pieces(s);
  ASSERT_FALSE(r2);
  EXPECT_NE(r2.error().find("names a vertex past"), std::string::npos) << r2.error();
  sim::SceneSnapshot empty;
  auto r3 = app::snapshot_pieces(empty);
  EXPECT_FALSE(r3);  // no triangles: no pieces, said so
}

// The worker on a lock-step sim: boards from the sim's snapshots (the tick they came from), and
// two exports asked for written into session-1 and session-2, the second from a later tick.
TEST(PatternBoard, WorkerBuildsBoardsAndNumbersExports) {
  const fs::path dir = fs::path(DRAPE_BINARY_DIR) / "xr_test_out" / "pattern_worker";
  fs::remove_all(dir);
  CutWorld c = cut_world();
  c.world.solver = std::make_unique<sim::VerletSolver>();
  c.world.paused = true;  // the cloth stays as cut
  sim::SimThreadOptions so;
  so.lock_step = true;
  sim::SimThread sim(std::move(c.world), so);
  sim.start();
  app::PatternWorkerOptions po;
  po.out_dir = dir.string();
  po.period_ms = 20;
  app::PatternWorker w(sim.make_reader(), po);
  sim.advance(3);
  EXPECT_EQ(w.request_export(), 1);
  // The board: within a few periods of the ticks.
  app::BoardBuild b;
  for (int i = 0; i < 500 && !b.board; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    b = w.latest_board();
  }
  ASSERT_TRUE(b.board);
  EXPECT_EQ(b.board->pieces.size(), 2u);
  EXPECT_GE(b.tick, 1u);
  EXPECT_LE(b.tick, 3u);
  sim.advance(5);
  EXPECT_EQ(w.request_export(), 2);
  EXPECT_EQ(w.next_number(), 3);
  w.stop();
  sim.stop();
  const auto done = w.take_exports();
  ASSERT_EQ(done.size(), 2u);
  for (int n = 1; n <= 2; ++n) {
    const auto& e = done[n - 1];
    EXPECT_TRUE(e.error.empty()) << e.error;
    EXPECT_EQ(e.dir, (dir / "pattern" / ("session-" + std::to_string(n))).string());
    EXPECT_TRUE(fs::exists(fs::path(e.dir) / "report.json"));
    EXPECT_TRUE(fs::exists(fs::path(e.dir) / "pattern.dxf"));
    EXPECT_NE(e.summary.find("2 piece(s), 1 cut edge(s)"), std::string::npos) << e.summary;
  }
  EXPECT_LE(done[0].tick, 3u);
  EXPECT_EQ(done[1].tick, 8u);
}

// A worker with no snapshot reader (every reader of the sim taken) writes nothing and says so
// for each export asked for.
TEST(PatternBoard, WorkerWithoutReaderSaysWhyNothingWasWritten) {
  app::PatternWorkerOptions po;
  po.out_dir = (fs::path(DRAPE_BINARY_DIR) / "xr_test_out" / "pattern_no_reader").string();
  fs::remove_all(po.out_dir);
  app::PatternWorker w(sim::SnapshotReader{}, po);
  EXPECT_EQ(w.request_export(), 1);
  w.stop();
  const auto done = w.take_exports();
  ASSERT_EQ(done.size(), 1u);
  EXPECT_NE(done[0].error.find("no snapshot reader"), std::string::npos) << done[0].error;
  EXPECT_NE(done[0].error.find("session-1 not written"), std::string::npos) << done[0].error;
  EXPECT_TRUE(done[0].files.empty());
  EXPECT_FALSE(fs::exists(po.out_dir));
  EXPECT_FALSE(w.latest_board().board);
}
