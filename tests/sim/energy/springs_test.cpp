// Tests of sim/energy/springs.cpp: the 8-neighbour network derived from the triangle mesh.
#include "sim/energy/springs.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

using namespace drape::sim;

TEST(Springs, EightNeighbourStencilOnGrid) {
  PanelSpec spec;
  spec.width = 0.1;
  spec.height = 0.08;
  spec.spacing = 0.01;
  Cloth c = make_panel(spec, FabricParams{});
  const int nx = c.topo.grid_nx, ny = c.topo.grid_ny;
  Springs s = build_springs(c);
  EXPECT_EQ(s.count(SpringKind::kStructural), nx * (ny - 1) + ny * (nx - 1));
  EXPECT_EQ(s.count(SpringKind::kDiagonal), 2 * (nx - 1) * (ny - 1));
  // An interior vertex has exactly its 8 grid neighbours.
  const int v = 3 * nx + 4;
  std::set<int> nb;
  for (int k = 0; k < s.size(); ++k) {
    if (s.a[k] == v) nb.insert(s.b[k]);
    if (s.b[k] == v) nb.insert(s.a[k]);
  }
  std::set<int> expect;
  for (int dj = -1; dj <= 1; ++dj)
    for (int di = -1; di <= 1; ++di)
      if (di || dj) expect.insert(v + dj * nx + di);
  EXPECT_EQ(nb, expect);
}

TEST(Springs, StiffnessAndRestFromFabric) {
  FabricParams f;  // muslin: warp 8000, weft 5000, shear 60 N/m
  Cloth c = make_panel(PanelSpec{0.1, 0.1, 0.01}, f);
  const int nx = c.topo.grid_nx;
  Springs s = build_springs(c);
  auto find = [&](int a, int b) {
    for (int k = 0; k < s.size(); ++k)
      if ((s.a[k] == a && s.b[k] == b) || (s.a[k] == b && s.b[k] == a)) return k;
    return -1;
  };
  const int v = 5 * nx + 5;
  const int weft = find(v, v + 1), warp = find(v, v + nx), diag = find(v, v + nx + 1),
            anti = find(v + 1, v + nx);
  ASSERT_GE(weft, 0);
  ASSERT_GE(warp, 0);
  ASSERT_GE(diag, 0);
  ASSERT_GE(anti, 0);
  EXPECT_NEAR(s.k[weft], 5000, 1e-6);
  EXPECT_NEAR(s.k[warp], 8000, 1e-6);
  EXPECT_NEAR(s.k[diag], 60, 1e-9);
  EXPECT_NEAR(s.k[anti], 60, 1e-9);
  EXPECT_NEAR(s.rest[weft], 0.01, 1e-12);
  EXPECT_NEAR(s.rest[diag], 0.01 * std::sqrt(2.0), 1e-12);
  // Border springs represent half the width.
  EXPECT_NEAR(s.k[find(0, 1)], 2500, 1e-6);
  EXPECT_NEAR(s.k[find(0, nx)], 4000, 1e-6);
  // Independent of the spacing on square grids.
  Springs s2 = build_springs(make_panel(PanelSpec{0.1, 0.1, 0.02}, f));
  EXPECT_NEAR(*std::max_element(s2.k.begin(), s2.k.end()), 8000, 1e-6);
  // Stiffness scale.
  Springs s3 = build_springs(c, 0.5);
  EXPECT_NEAR(s3.k[warp], 4000, 1e-6);
}

TEST(Springs, RectangularCellsShearEnergy) {
  // Under a small shear gamma, the two diagonals of a du x dv cell store G gamma^2 A / 2.
  FabricParams f;
  PanelSpec spec;
  spec.width = 0.02;
  spec.height = 0.01;
  spec.nx = 2;
  spec.ny = 2;  // one 2 cm x 1 cm cell
  Cloth c = make_panel(spec, f);
  Springs s = build_springs(c);
  const double gamma = 1e-4;
  double e = 0;
  for (int k = 0; k < s.size(); ++k) {
    if (s.kind[k] != SpringKind::kDiagonal) continue;
    auto shear = [&](int i) {
      const Vec2 m = c.topo.material[i];
      return Vec2(m.x() + gamma * m.y(), m.y());
    };
    const double L = (shear(s.b[k]) - shear(s.a[k])).norm();
    e += 0.5 * s.k[k] * (L - s.rest[k]) * (L - s.rest[k]);
  }
  const double expect = 0.5 * f.shear * gamma * gamma * 0.02 * 0.01;
  std::printf("shear energy %.6e J, continuum %.6e J\n", e, expect);
  EXPECT_NEAR(e / expect, 1.0, 1e-3);
}

TEST(Springs, RebuiltAfterTopologyEdit) {
  Cloth c = make_panel(PanelSpec{0.04, 0.04, 0.01}, FabricParams{});
  Springs before = build_springs(c);
  // Slit: a duplicate of vertex 12 (interior) takes over the triangles on one side.
  const int nx = c.topo.grid_nx;
  const int v = 2 * nx + 2;
  const int d = c.duplicate_vertex(v);
  for (auto& t : c.topo.triangles) {
    double cu = 0;
    for (int k = 0; k < 3; ++k) cu += c.topo.material[t[k]].x();
    if (cu / 3 > c.topo.material[v].x())
      for (int k = 0; k < 3; ++k)
        if (t[k] == v) t[k] = d;
  }
  c.topology_changed();
  c.relump_masses();
  ASSERT_EQ(c.validate(), "");
  Springs after = build_springs(c);
  EXPECT_EQ(after.topology_version, c.topology_version);
  // The vertical edges through v now exist twice (once per side) and no spring joins v and d.
  for (int k = 0; k < after.size(); ++k)
    EXPECT_FALSE((after.a[k] == v && after.b[k] == d) || (after.a[k] == d && after.b[k] == v));
  EXPECT_GT(after.size(), before.size());
  std::printf("springs before %d, after slit %d\n", before.size(), after.size());
}

TEST(Springs, GershgorinBoundAboveTrueEigenvalue) {
  // Two free particles joined by one spring: lambda = k (1/m1 + 1/m2); the bound is
  // 2 k / m_min >= that.
  FabricParams f;
  Cloth c = make_panel(PanelSpec{0.1, 0.1, 0.01}, f);
  Springs s = build_springs(c);
  const double bound = max_eigenvalue_bound(c, s);
  const double interior = 2 * (2 * 8000 + 2 * 5000 + 4 * 60) / c.state.mass[5 * 11 + 5];
  std::printf("lambda bound %.4e, interior row %.4e, stable dt < %.3e s\n", bound, interior,
              2 / std::sqrt(bound));
  EXPECT_GE(bound, interior * (1 - 1e-12));
}
