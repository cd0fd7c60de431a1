// Tests of sim/core/cloth.cpp: panel generation, masses, initial states, duplication, validation,
// hash.
#include "sim/core/cloth.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace drape::sim;

TEST(Cloth, PanelCountsAndCrissCross) {
  PanelSpec spec;
  spec.width = 0.3;
  spec.height = 0.2;
  spec.spacing = 0.01;
  Cloth c = make_panel(spec, FabricParams{});
  EXPECT_EQ(c.topo.grid_nx, 31);
  EXPECT_EQ(c.topo.grid_ny, 21);
  EXPECT_EQ(c.num_vertices(), 31 * 21);
  EXPECT_EQ(c.topo.num_triangles(), 2 * 30 * 20);
  EXPECT_EQ(c.validate(), "");
  // Every triangle counter-clockwise in (u, v) with area du*dv/2.
  for (const auto& t : c.topo.triangles) {
    const Vec2 e1 = c.topo.material[t[1]] - c.topo.material[t[0]];
    const Vec2 e2 = c.topo.material[t[2]] - c.topo.material[t[0]];
    EXPECT_NEAR(e1.x() * e2.y() - e1.y() * e2.x(), 1e-4, 1e-12);
  }
  // Criss-cross: neighbouring cells use different diagonals. Cell (0,0) joins a to e, cell
  // (1,0) joins b to d: check which diagonal each cell's first triangle contains.
  auto has_edge = [&](int tri, int a, int b) {
    const auto& t = c.topo.triangles[tri];
    int hits = 0;
    for (int k = 0; k < 3; ++k) hits += (t[k] == a) + (t[k] == b);
    return hits == 2;
  };
  const int nx = 31;
  EXPECT_TRUE(has_edge(0, 0, nx + 1));  // cell (0,0): diagonal (0,0)-(1,1)
  EXPECT_TRUE(has_edge(2, 2, nx + 1));  // cell (1,0): diagonal (2,0)-(1,1)
}

TEST(Cloth, MassesSumToPanelWeight) {
  PanelSpec spec{0.5, 0.4, 0.02};
  FabricParams f;
  Cloth c = make_panel(spec, f);
  double m = 0;
  for (double mi : c.state.mass) m += mi;
  const double expect = 0.5 * 0.4 * f.areal_density;
  std::printf("panel mass %.9f kg, expected %.9f\n", m, expect);
  EXPECT_NEAR(m, expect, 1e-12);
  // Criss-cross interior vertices alternate between 8 and 4 triangles (a third of each):
  // two neighbours together carry two cells' mass.
  const int nx = c.topo.grid_nx;
  EXPECT_NEAR(c.state.mass[5 * nx + 5], 8.0 / 6 * 0.02 * 0.02 * f.areal_density, 1e-12);
  EXPECT_NEAR(c.state.mass[5 * nx + 5] + c.state.mass[5 * nx + 6],
              2 * 0.02 * 0.02 * f.areal_density, 1e-12);
  // Pinned vertices get zero inverse mass after relumping.
  c.state.flags[0] |= kFlagPinned;
  c.relump_masses();
  EXPECT_EQ(c.state.inv_mass[0], 0.0);
  EXPECT_GT(c.state.inv_mass[1], 0.0);
}

TEST(Cloth, ResolutionOverride) {
  PanelSpec spec;
  spec.width = 1.0;
  spec.height = 0.5;
  spec.nx = 21;
  spec.ny = 11;
  Cloth c = make_panel(spec, FabricParams{});
  EXPECT_EQ(c.num_vertices(), 21 * 11);
  EXPECT_NEAR(c.topo.material.back().x(), 1.0, 1e-12);
  EXPECT_NEAR(c.topo.material.back().y(), 0.5, 1e-12);
}

TEST(Cloth, PlaceSpreadKeepsDistances) {
  Cloth c = make_panel(PanelSpec{0.2, 0.2, 0.02}, FabricParams{});
  place_spread(c, Vec3(1, 2, 3), Vec3(0, 0, 2), Vec3(0, -1, 0));
  EXPECT_TRUE(c.state.x[0].isApprox(Vec3(1, 2, 3)));
  const int last = c.num_vertices() - 1;
  EXPECT_TRUE(c.state.x[last].isApprox(Vec3(1, 1.8, 3.2)));
  EXPECT_EQ(c.state.x, c.state.x_prev);
}

TEST(Cloth, PlaceRolledPreservesArcLength) {
  PanelSpec spec{0.3, 0.6, 0.01};
  Cloth c = make_panel(spec, FabricParams{});
  const Vec3 origin(0, 1, 0);
  place_rolled(c, origin, Vec3::UnitX(), Vec3::UnitY(), 0.02);
  const int nx = c.topo.grid_nx, ny = c.topo.grid_ny;
  // The outer end (v = height) at the origin line.
  EXPECT_NEAR((c.state.x[(ny - 1) * nx] - origin).norm(), 0.0, 1e-9);
  // Neighbours along the warp stay about one spacing apart (chord of the spiral arc).
  double worst = 0;
  for (int j = 0; j + 1 < ny; ++j) {
    const double d = (c.state.x[(j + 1) * nx] - c.state.x[j * nx]).norm();
    worst = std::max(worst, std::abs(d - 0.01) / 0.01);
  }
  std::printf("rolled: worst warp spacing error %.3e (relative)\n", worst);
  EXPECT_LT(worst, 0.02);
  // Along the weft: a straight line parallel to the axis.
  EXPECT_NEAR((c.state.x[nx - 1] - c.state.x[0]).norm(), 0.3, 1e-9);
  // Every point lies within the roll's outer radius of its axis.
  double rmax = 0;
  for (const Vec3& p : c.state.x)
    rmax = std::max(rmax, std::hypot(p.y() - c.state.x[(ny - 1) * nx].y(), p.z()));
  EXPECT_LT(rmax, 0.2);  // 0.6 m rolled: a few cm across, not spread out
}

TEST(Cloth, DuplicateVertexAndValidate) {
  Cloth c = make_panel(PanelSpec{0.1, 0.1, 0.05}, FabricParams{});
  const int n = c.num_vertices();
  c.topo.vertex_zone[4] = 3;
  const int d = c.duplicate_vertex(4);
  EXPECT_EQ(d, n);
  EXPECT_EQ(c.num_vertices(), n + 1);
  EXPECT_EQ(c.topo.vertex_origin[d], 4);
  EXPECT_EQ(c.topo.vertex_zone[d], 3);
  EXPECT_EQ(c.topo.material[d], c.topo.material[4]);
  EXPECT_EQ(c.validate(), "");
  const int d2 = c.duplicate_vertex(d);
  EXPECT_EQ(c.topo.vertex_origin[d2], 4);  // origin of the origin

  Cloth bad = c;
  bad.topo.triangles[0][1] = 999;
  EXPECT_NE(bad.validate().find("out of range"), std::string::npos) << bad.validate();
  bad = c;
  bad.state.x[2].x() = std::nan("");
  EXPECT_NE(bad.validate().find("non-finite"), std::string::npos);
  bad = c;
  bad.state.v.pop_back();
  EXPECT_NE(bad.validate().find("v has"), std::string::npos) << bad.validate();
}

TEST(Cloth, StateHashSeesPositionsFlagsTopology) {
  Cloth a = make_panel(PanelSpec{0.1, 0.1, 0.02}, FabricParams{});
  Cloth b = a;
  EXPECT_EQ(state_hash(a), state_hash(b));
  b.state.x[3].y() = std::nextafter(b.state.x[3].y(), 1.0);
  EXPECT_NE(state_hash(a), state_hash(b));
  b = a;
  b.state.flags[0] = kFlagPinned;
  EXPECT_NE(state_hash(a), state_hash(b));
  b = a;
  std::swap(b.topo.triangles[0], b.topo.triangles[1]);
  EXPECT_NE(state_hash(a), state_hash(b));
}
