// XPBD's incremental re-cook after a topology change (XpbdOptions::incremental_cook,
// ClothEnergy::update): the solver keeps the bending rows and blocks of the triangles a cut did
// not reach. A drape cut twice (across, then a slit from the side) and stepped on must come out
// bit for bit as with a full cook after each cut, on one and on two threads: the kept rows are
// the values a full build makes (the same arithmetic on the same inputs), and everything after
// them (colours, packs, the sweep's plan) is cooked as in a full cook. (In the TSan build:
// "thread" in the name.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "sim/ops/cut.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"
#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

namespace {

struct CutDrape {
  std::vector<Vec3> x, v;
  std::vector<XpbdSolver::CookStats> cooks;  // the cook after each cut
  int triangles = 0;
  // The pieces after the cuts, and the energy's bending rows whose columns lie in more than one
  // (the solver joins the pieces by the triangles alone: there must be none).
  int pieces = 0, rows_across_pieces = 0;
};

// The form drape at res^2: 30 frames, a cut across at half height, 30 frames, a slit from the
// left edge to the middle a quarter above it, 30 frames.
CutDrape cut_drape(int res, int threads, bool incremental) {
  Testbed sc = make_scene("form", res);
  XpbdOptions o;
  o.air_drag = sc.air_drag;
  o.threads = threads;
  o.min_parallel_triangles = 0;  // small test cloths run on two threads too
  o.freeze = true;
  o.incremental_cook = incremental;
  o.finish_thread = false;  // (on its own thread the finish lands on a frame the scheduler picks)
  XpbdSolver s(o);
  double umin = 1e9, umax = -1e9, vmin = 1e9, vmax = -1e9;
  for (const Vec2& m : sc.cloth.topo.material) {
    umin = std::min(umin, m.x()), umax = std::max(umax, m.x());
    vmin = std::min(vmin, m.y()), vmax = std::max(vmax, m.y());
  }
  const double dv = (vmax - vmin) / (res - 1);
  const double v1 = 0.5 * (vmin + vmax) + 0.25 * dv, v2 = 0.75 * vmax + 0.25 * vmin + 0.25 * dv;
  CutDrape r;
  auto frames = [&](int k) {
    for (int f = 0; f < k; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
  };
  frames(30);
  EXPECT_TRUE(cut_along_material(sc.cloth, {Vec2(umin - 0.01, v1), Vec2(umax + 0.01, v1)}).ok);
  frames(30);
  r.cooks.push_back(s.last_cook());
  EXPECT_TRUE(
      cut_along_material(sc.cloth, {Vec2(umin - 0.01, v2), Vec2(0.5 * (umin + umax), v2)}).ok);
  frames(30);
  r.cooks.push_back(s.last_cook());
  r.x = sc.cloth.state.x;
  r.v = sc.cloth.state.v;
  r.triangles = sc.cloth.topo.num_triangles();
  r.pieces = s.rest().num_pieces();
  const auto& piece = s.rest().piece_of();
  const auto& ro = s.energy().bending_row_offsets();
  const auto& rc = s.energy().bending_row_columns();
  for (size_t row = 0; row + 1 < ro.size(); ++row)
    for (int k = ro[row]; k < ro[row + 1]; ++k)
      if (piece[rc[k]] != piece[rc[ro[row]]]) {
        ++r.rows_across_pieces;
        break;
      }
  return r;
}

double max_diff(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double m = 0;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, (a[i] - b[i]).cwiseAbs().maxCoeff());
  return m;
}

void expect_incremental_equals_full(int res, int threads) {
  const CutDrape inc = cut_drape(res, threads, true), full = cut_drape(res, threads, false);
  ASSERT_EQ(inc.x.size(), full.x.size());
  for (size_t k = 0; k < inc.cooks.size(); ++k) {
    const auto &a = inc.cooks[k], &b = full.cooks[k];
    std::printf(
        "%d^2, %d thread(s), cut %zu: incremental cook %.2f ms (energy %.2f, bending %.2f; %d of "
        "%d triangles' rows made again), full cook %.2f ms (energy %.2f, bending %.2f)\n",
        res, threads, k + 1, a.total_ms, a.energy_ms, a.bending_ms, a.rebuilt_triangles,
        inc.triangles, b.total_ms, b.energy_ms, b.bending_ms);
    EXPECT_TRUE(a.incremental);
    EXPECT_FALSE(b.incremental);
    EXPECT_GT(a.rebuilt_triangles, 0);
    EXPECT_LT(a.rebuilt_triangles, inc.triangles / 8);
    EXPECT_EQ(b.rebuilt_triangles, full.triangles);
  }
  EXPECT_GE(inc.pieces, 2);  // the cut across separates the cloth
  EXPECT_EQ(inc.rows_across_pieces, 0);
  const double dx = max_diff(inc.x, full.x), dv = max_diff(inc.v, full.v);
  std::printf("after 90 frames and two cuts: positions differ by %.3g m, velocities by %.3g m/s\n",
              dx, dv);
  EXPECT_EQ(dx, 0.0);
  EXPECT_EQ(dv, 0.0);
}

}  // namespace

TEST(XpbdIncrementalCook, CutDrapeEqualsFullCookBitForBitOnOneThread) {
  expect_incremental_equals_full(32, 1);
}

TEST(XpbdIncrementalCook, CutDrapeEqualsFullCookBitForBitOnTwoThreads) {
  expect_incremental_equals_full(32, 2);
}
