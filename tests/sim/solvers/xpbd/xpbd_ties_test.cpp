// Ties (sim/solvers/xpbd/xpbd_ties.hpp): one projection closes a tie and keeps the momentum of
// the free vertices; a fixed vertex stays; two panels tied edge to edge hang as one (the tied
// one, pinned nowhere, is held by the ties alone), and fall apart without them.
#include "sim/solvers/xpbd/xpbd_ties.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "sim/solvers/xpbd/solver_xpbd.hpp"

using namespace drape::sim;

TEST(XpbdTies, OneProjectionClosesATieAndKeepsMomentum) {
  std::vector<Vec3> x = {{0, 0.01, 0}, {-0.01, 0, 0}, {0.02, 0, 0}};
  const double w[3] = {1.0, 2.0, 0.5};
  const std::vector<xpbd::Tie> ties = {{0, 1, 2, 0.25}};
  Vec3 momentum = Vec3::Zero();
  for (int i = 0; i < 3; ++i) momentum += x[i] / w[i];
  std::vector<int> moved;
  xpbd::project_ties(ties, x, w, &moved);
  EXPECT_LT(xpbd::tie_gap(ties[0], x), 1e-15);
  Vec3 after = Vec3::Zero();
  for (int i = 0; i < 3; ++i) after += x[i] / w[i];
  EXPECT_LT((after - momentum).norm(), 1e-15);
  EXPECT_EQ(moved.size(), 3u);
}

TEST(XpbdTies, AFixedVertexStaysAndATieOntoOneVertexMeetsIt) {
  std::vector<Vec3> x = {{0, 0.01, 0}, {0.03, 0, 0}, {0.03, 0, 0}};
  const double w[3] = {1.0, 0.0, 0.0};
  xpbd::project_ties({{0, 1, 1, 0.7}}, x, w, nullptr);  // b1 == b0: onto vertex 1 whatever t
  EXPECT_LT((x[0] - Vec3(0.03, 0, 0)).norm(), 1e-15);
  EXPECT_EQ(x[1], Vec3(0.03, 0, 0));
}

namespace {

// Two 0.16 m panels side by side in the plane z = 0, B's left column on A's right column; A's
// top row pinned. The ties: each vertex of B's left column onto its twin of A's right column.
struct TwoPanels {
  Cloth cloth;
  std::vector<xpbd::Tie> ties;
  int na = 0;
};
TwoPanels two_panels() {
  PanelSpec spec;
  spec.nx = spec.ny = 9;
  spec.width = spec.height = 0.16;
  const FabricParams fab;
  Cloth a = make_panel(spec, fab), b = make_panel(spec, fab);
  place_spread(a, Vec3(-0.16, 1.0, 0), Vec3::UnitX(), Vec3::UnitY());
  place_spread(b, Vec3(0.0, 1.0, 0), Vec3::UnitX(), Vec3::UnitY());
  TwoPanels p;
  p.na = a.num_vertices();
  Cloth& c = p.cloth;
  c = a;
  auto& T = c.topo;
  for (auto t : b.topo.triangles) T.triangles.push_back({t[0] + p.na, t[1] + p.na, t[2] + p.na});
  for (const Vec2& m : b.topo.material) T.material.push_back(m + Vec2(0.2, 0));
  T.vertex_zone.resize(T.material.size(), 0);
  T.triangle_zone.resize(T.triangles.size(), 0);
  T.vertex_origin.resize(T.material.size());
  for (int i = 0; i < static_cast<int>(T.material.size()); ++i) T.vertex_origin[i] = i;
  T.grid_nx = T.grid_ny = 0;
  c.state.x.insert(c.state.x.end(), b.state.x.begin(), b.state.x.end());
  c.state.x_prev = c.state.x;
  c.state.v.assign(c.state.x.size(), Vec3::Zero());
  c.state.flags.assign(c.state.x.size(), 0);
  for (int i = 0; i < 9; ++i) {
    c.state.flags[8 * 9 + i] = kFlagPinned;                     // A's top row
    p.ties.push_back({p.na + i * 9, i * 9 + 8, i * 9 + 8, 0});  // B's left onto A's right
  }
  c.relump_masses();
  return p;
}

}  // namespace

TEST(XpbdTies, TwoPanelsTiedHangAsOne) {
  for (const bool tied : {true, false}) {
    TwoPanels p = two_panels();
    ASSERT_EQ(p.cloth.validate(), "");
    XpbdOptions o;
    o.single_precision = false;
    XpbdSolver s(o);
    if (tied) s.set_ties(p.ties);
    SceneObjects scene;
    for (int f = 0; f < 90; ++f) s.step(p.cloth, scene, 1.0 / 90);
    double lowest_b = 1e9;
    for (int i = p.na; i < p.cloth.num_vertices(); ++i)
      lowest_b = std::min(lowest_b, p.cloth.state.x[i].y());
    const double gap = xpbd::max_tie_gap(p.ties, p.cloth.state.x);
    std::printf("%s: panel B's lowest point %.4f m, largest tie gap %.4f mm\n",
                tied ? "tied" : "untied", lowest_b, gap * 1000);
    if (tied) {
      EXPECT_GT(lowest_b, 0.9);  // hangs from A (its bottom starts at 1.0 m; measured 0.998)
      EXPECT_LT(gap, 1e-4);
    } else {
      EXPECT_LT(lowest_b, 0.05);  // fell to the floor
    }
  }
}

// With sleep on, tied panels are one piece: they fall asleep together, and moving A's pinned row
// wakes B too (a B asleep on its own would hold A's seam still).
TEST(XpbdTies, TiedPanelsSleepAndWakeAsOne) {
  TwoPanels p = two_panels();
  XpbdOptions o;
  o.single_precision = false;
  o.freeze = true;
  o.finish = false;
  o.rest_holds_at_detection = true;
  XpbdSolver s(o);
  s.set_ties(p.ties);
  SceneObjects scene;
  const int free_vertices = p.cloth.num_vertices() - 9;
  int asleep_at = -1;
  for (int f = 0; f < 1800 && asleep_at < 0; ++f) {
    s.step(p.cloth, scene, 1.0 / 90);
    if (s.frozen_count() == free_vertices) asleep_at = f;
    // Never one panel asleep without the other.
    ASSERT_TRUE(s.frozen_count() == 0 || s.frozen_count() == free_vertices) << "frame " << f;
  }
  std::printf("tied panels asleep at frame %d\n", asleep_at);
  ASSERT_GE(asleep_at, 0) << "the tied panels never fell asleep";
  for (int i = 0; i < 9; ++i) p.cloth.state.x[8 * 9 + i] += Vec3(0, 0, 0.01);  // A's top row
  s.step(p.cloth, scene, 1.0 / 90);
  EXPECT_EQ(s.frozen_count(), 0);
  double vb = 0;
  for (int i = p.na; i < p.cloth.num_vertices(); ++i) vb = std::max(vb, p.cloth.state.v[i].norm());
  EXPECT_GT(vb, 0.0) << "panel B moves with A";
}
