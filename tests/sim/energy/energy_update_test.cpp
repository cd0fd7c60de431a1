// ClothEnergy::update: after a topology change the tensor bending rows of the triangles the
// change did not reach are kept, the others made again; the rows must be those of a full build
// bit for bit (after a cut across, its undo, the cut again, a slit, and pins that make triangles
// rigid), also when made on a spare copy of the energy, and the cases update() does not serve
// must fall back to a full build.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "sim/energy/energy.hpp"
#include "sim/ops/cut.hpp"

using namespace drape::sim;

namespace {

Cloth panel(int n) {
  PanelSpec p;
  p.width = p.height = 0.4;
  p.nx = p.ny = n;
  Cloth c = make_panel(p, FabricParams{});
  place_spread(c, Vec3(0, 1, 0), Vec3::UnitX(), Vec3::UnitY());
  c.relump_masses();
  return c;
}

EnergyOptions row_options() {
  EnergyOptions o;
  o.bending_matrix = false;  // as XPBD cooks it
  return o;
}

int count(const std::vector<char>& v) {
  return static_cast<int>(std::count(v.begin(), v.end(), 1));
}

// update() on `kept` (built for the cloth before the edit) against build() of the edited cloth:
// the same rows, bit for bit.
void expect_rows_equal(ClothEnergy& kept, const Cloth& c, const char* what) {
  ASSERT_TRUE(kept.update(c, row_options())) << what;
  ClothEnergy full;
  full.build(c, row_options());
  const int made = count(kept.rebuilt_triangles());
  std::printf("%s: %d of %d triangles' rows made again\n", what, made, full.num_triangles());
  EXPECT_GT(made, 0) << what;
  EXPECT_LT(made, full.num_triangles() / 8) << what;
  EXPECT_EQ(kept.bending_row_offsets(), full.bending_row_offsets()) << what;
  EXPECT_EQ(kept.bending_row_columns(), full.bending_row_columns()) << what;
  EXPECT_EQ(kept.bending_row_values(), full.bending_row_values()) << what;
  for (int r = 0; r < full.num_bending_rows(); ++r)
    ASSERT_EQ(kept.bending_row_stiffness(r), full.bending_row_stiffness(r)) << what;
}

}  // namespace

TEST(EnergyUpdate, RowsAfterACutASlitAndPinsEqualAFullBuild) {
  const int n = 40;
  Cloth c = panel(n);
  ClothEnergy e;
  e.build(c, row_options());
  EXPECT_EQ(count(e.rebuilt_triangles()), e.num_triangles());
  const double dv = 0.4 / (n - 1);
  const std::vector<Vec2> across{Vec2(-0.01, 0.2 + 0.25 * dv), Vec2(0.41, 0.2 + 0.25 * dv)};
  const Cloth uncut = c;
  ASSERT_TRUE(cut_along_material(c, across).ok);
  expect_rows_equal(e, c, "cut across");
  // An undo puts the uncut cloth back (fewer vertices, the cut triangles' old indices).
  const uint64_t version = c.topology_version;
  c = uncut;
  c.topology_version = version + 1;
  expect_rows_equal(e, c, "undo of the cut");
  ASSERT_TRUE(cut_along_material(c, across).ok);
  expect_rows_equal(e, c, "cut across again");
  ASSERT_TRUE(cut_along_material(c, {Vec2(0.2 + 0.25 * dv, 0.41), Vec2(0.2 + 0.25 * dv, 0.3)}).ok);
  expect_rows_equal(e, c, "slit from the top");
  // Pins on the bottom two rows of a third of the width: triangles there become rigid (no topology
  // change, but their rows and their neighbours' change).
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < n / 3; ++i) c.state.flags[j * n + i] |= kFlagPinned;
  c.topology_changed();
  expect_rows_equal(e, c, "pinned corner");
}

// A spare copy (what update() reads) updates to the energy that update() of the original and
// a full build give: the same triangles, hinges and rows.
TEST(EnergyUpdate, ASpareCopyUpdatesAsTheEnergyItWasCopiedFrom) {
  const int n = 40;
  Cloth c = panel(n);
  ClothEnergy e;
  e.build(c, row_options());
  ClothEnergy spare = e.spare_copy();
  EXPECT_EQ(spare.num_triangles(), e.num_triangles());
  EXPECT_EQ(spare.bending_row_values(), e.bending_row_values());
  EXPECT_EQ(spare.num_hinges(), 0) << "what update() remakes is not copied";
  const double dv = 0.4 / (n - 1);
  ASSERT_TRUE(
      cut_along_material(c, {Vec2(-0.01, 0.2 + 0.25 * dv), Vec2(0.41, 0.2 + 0.25 * dv)}).ok);
  expect_rows_equal(spare, c, "spare copy, cut across");
  ASSERT_TRUE(e.update(c, row_options()));
  EXPECT_EQ(spare.rebuilt_triangles(), e.rebuilt_triangles());
  ASSERT_EQ(spare.num_hinges(), e.num_hinges());
  for (int h = 0; h < e.num_hinges(); ++h) {
    ASSERT_EQ(spare.hinge(h), e.hinge(h));
    ASSERT_EQ(spare.hinge_K(h), e.hinge_K(h));
    ASSERT_EQ(spare.hinge_w(h), e.hinge_w(h));
  }
  for (int t = 0; t < e.num_triangles(); ++t) {
    ASSERT_EQ(spare.tri(t), e.tri(t));
    ASSERT_EQ(spare.tri_D(t), e.tri_D(t));
    ASSERT_EQ(spare.rest_area(t), e.rest_area(t));
  }
  EXPECT_EQ(spare.bending_row_offsets(), e.bending_row_offsets());
  EXPECT_EQ(spare.bending_row_columns(), e.bending_row_columns());
  EXPECT_EQ(spare.bending_row_values(), e.bending_row_values());
}

TEST(EnergyUpdate, FallsBackToAFullBuildItDoesNotServe) {
  Cloth c = panel(24);
  ClothEnergy e;
  EXPECT_FALSE(e.update(c, row_options()));  // nothing built yet: a full build
  EXPECT_EQ(count(e.rebuilt_triangles()), e.num_triangles());
  c.topology_changed();
  EnergyOptions with_p = row_options();
  with_p.bending_matrix = true;  // the matrix P is global
  EXPECT_FALSE(e.update(c, with_p));
  c.topology_changed();
  EXPECT_FALSE(e.update(c, row_options()));  // the last build had P
  c.topology_changed();
  ASSERT_TRUE(e.update(c, row_options()));  // nothing changed: every row kept
  EXPECT_EQ(count(e.rebuilt_triangles()), 0);
  ClothEnergy full;
  full.build(c, row_options());
  EXPECT_EQ(e.bending_row_values(), full.bending_row_values());
  // Every vertex pinned: every triangle rigid, more than an eighth changed.
  for (auto& f : c.state.flags) f |= kFlagPinned;
  c.topology_changed();
  EXPECT_FALSE(e.update(c, row_options()));
  EXPECT_EQ(count(e.rebuilt_triangles()), e.num_triangles());
}
