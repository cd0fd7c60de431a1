// The cut primitive (sim/cut.cpp): edge paths, splitting on the left of the cut direction,
// components, material coordinates and mass kept, bad strokes refused.
#include "sim/cut.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace drape::sim {
namespace {

Cloth flat(int n, double size = 0.4) {
  PanelSpec spec;
  spec.width = spec.height = size;
  spec.nx = spec.ny = n;
  spec.spacing = size / (n - 1);
  Cloth c = make_panel(spec, FabricParams{});
  place_spread(c, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());  // x = u, y = v, z = 0
  c.relump_masses();
  return c;
}

double total_mass(const Cloth& c) {
  double m = 0;
  for (double x : c.state.mass) m += x;
  return m;
}

double material_area(const Cloth& c) {
  double a = 0;
  for (const auto& t : c.topo.triangles) {
    const Vec2 e1 = c.topo.material[t[1]] - c.topo.material[t[0]];
    const Vec2 e2 = c.topo.material[t[2]] - c.topo.material[t[0]];
    a += 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());  // signed: all CCW
  }
  return a;
}

// Every duplicate keeps its origin's material coordinates and position.
void expect_material_kept(const Cloth& c, const CutResult& r) {
  for (int32_t nv : r.new_vertices) {
    const int32_t o = c.topo.vertex_origin[nv];
    ASSERT_GE(o, 0);
    EXPECT_EQ(c.topo.material[nv], c.topo.material[o]);
    EXPECT_EQ(c.state.x[nv], c.state.x[o]);
  }
}

TEST(Cut, HorizontalLineAcrossSplitsInTwo) {
  const int n = 11;
  Cloth c = flat(n);
  const double m0 = total_mass(c), a0 = material_area(c);
  const uint64_t v0 = c.topology_version;
  CutResult r = cut_along_material(c, {Vec2(0, 0.2), Vec2(0.4, 0.2)});
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.path.size(), static_cast<size_t>(n));          // straight along the grid row
  EXPECT_EQ(r.new_vertices.size(), static_cast<size_t>(n));  // both ends on the boundary
  EXPECT_EQ(r.components_before, 1);
  EXPECT_EQ(r.components_after, 2);
  EXPECT_EQ(count_components(c), 2);
  EXPECT_GT(c.topology_version, v0);
  EXPECT_NEAR(total_mass(c), m0, 1e-15);
  EXPECT_NEAR(material_area(c), a0, 1e-15);
  EXPECT_TRUE(c.validate().empty()) << c.validate();
  expect_material_kept(c, r);
  // Left of +u is +v: every triangle holding a duplicate lies above the cut.
  for (const auto& t : c.topo.triangles) {
    bool has_new = false;
    double vc = 0;
    for (int k = 0; k < 3; ++k) {
      has_new = has_new || t[k] >= n * n;
      vc += c.topo.material[t[k]].y() / 3;
    }
    if (has_new) {
      EXPECT_GT(vc, 0.2);
    }
  }
  // Components: the labels split at v = 0.2 exactly.
  auto lab = component_labels(c);
  for (int i = 0; i < n * n; ++i) {
    const double v = c.topo.material[i].y();
    if (v < 0.2 - 1e-9) {
      EXPECT_EQ(lab[i], lab[0]);
    }
    if (v > 0.2 + 1e-9) {
      EXPECT_NE(lab[i], lab[0]);
    }
  }
  std::printf("horizontal cut: %zu path vertices, %zu new, %.3f ms\n", r.path.size(),
              r.new_vertices.size(), r.ms);
}

TEST(Cut, HalfLinesMakeSlitsWithoutSeparating) {
  const int n = 11;
  struct Line {
    const char* name;
    Vec2 a, b;
    size_t path_len;
  };
  // Vertical from the top edge down, horizontal from the left edge in, diagonal from a corner.
  const Line lines[] = {{"vertical", {0.2, 0.4}, {0.2, 0.2}, 6},
                        {"horizontal", {0.0, 0.2}, {0.2, 0.2}, 6},
                        {"diagonal", {0.0, 0.4}, {0.2, 0.2}, 0}};
  for (const Line& l : lines) {
    Cloth c = flat(n);
    CutResult r = cut_along_material(c, {l.a, l.b});
    ASSERT_TRUE(r.ok) << l.name << ": " << r.reason;
    if (l.path_len) {
      EXPECT_EQ(r.path.size(), l.path_len) << l.name;
    }
    // The interior end is a slit tip: not duplicated; every other path vertex is.
    EXPECT_EQ(r.new_vertices.size(), r.path.size() - 1) << l.name;
    EXPECT_EQ(count_components(c), 1) << l.name;
    EXPECT_TRUE(c.validate().empty());
    expect_material_kept(c, r);
    // The path stays near the straight line in material space (within one cell diagonal).
    for (int32_t v : r.path) {
      const Vec2 d = l.b - l.a, p = c.topo.material[v] - l.a;
      const double dist = std::abs(d.x() * p.y() - d.y() * p.x()) / d.norm();
      EXPECT_LE(dist, 0.04 * std::sqrt(2.0) + 1e-12) << l.name;
    }
    std::printf("%s slit: %zu path vertices, %zu new\n", l.name, r.path.size(),
                r.new_vertices.size());
  }
}

TEST(Cut, CrossingCutsMakeFourPieces) {
  Cloth c = flat(11);
  ASSERT_TRUE(cut_along_material(c, {Vec2(0, 0.2), Vec2(0.4, 0.2)}).ok);
  CutResult r = cut_along_material(c, {Vec2(0.2, 0.4), Vec2(0.2, 0.0)});
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(count_components(c), 4);
  EXPECT_TRUE(c.validate().empty());
}

TEST(Cut, NoisyHandStrokeIn3D) {
  Cloth c = flat(17);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.003);  // 3 mm tracking noise
  std::vector<Vec3> stroke;
  for (int i = 0; i <= 60; ++i) {
    const double u = -0.02 + 0.44 * i / 60.0;  // starts and ends off the cloth edge
    stroke.emplace_back(u + noise(rng), 0.23 + 0.05 * u + noise(rng), 0.01 + noise(rng));
  }
  CutResult r = cut_along(c, stroke);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(count_components(c), 2);
  EXPECT_GE(r.smooth_stroke.size(), 2u);
  EXPECT_EQ(r.smooth_stroke.size(), r.smooth_stroke_uv.size());
  // The smooth stroke in material space follows the drawn line (x = u on this flat cloth)
  // closer than the raw noisy samples do.
  auto rms_dev = [](const std::vector<Vec2>& pts) {
    double s = 0;
    for (const Vec2& q : pts) s += std::pow(q.y() - (0.23 + 0.05 * q.x()), 2);
    return std::sqrt(s / pts.size());
  };
  std::vector<Vec2> raw;
  for (const Vec3& p : stroke) raw.emplace_back(p.x(), p.y());
  const double smooth = rms_dev(r.smooth_stroke_uv), noisy = rms_dev(raw);
  std::printf("3D stroke: RMS deviation from the drawn line %.2f mm raw, %.2f mm smoothed\n",
              noisy * 1e3, smooth * 1e3);
  EXPECT_LT(smooth, 0.7 * noisy);
  expect_material_kept(c, r);
}

TEST(Cut, EdgePathFollowsEdges) {
  Cloth c = flat(9);
  auto path = edge_path(c, {0, 80});  // corner to corner
  ASSERT_GE(path.size(), 9u);
  EXPECT_EQ(path.front(), 0);
  EXPECT_EQ(path.back(), 80);
  // consecutive vertices share a triangle edge
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    bool edge = false;
    for (const auto& t : c.topo.triangles) {
      int hits = 0;
      for (int k = 0; k < 3; ++k) hits += (t[k] == path[i] || t[k] == path[i + 1]);
      edge = edge || hits == 2;
    }
    EXPECT_TRUE(edge) << path[i] << "-" << path[i + 1];
  }
}

TEST(Cut, BadStrokesAreRefusedAndChangeNothing) {
  Cloth c = flat(9);
  const uint64_t h = state_hash(c);
  CutResult r1 = cut_along(c, {Vec3(0.1, 0.1, 0)});
  EXPECT_FALSE(r1.ok);
  EXPECT_NE(r1.reason.find("fewer than 2"), std::string::npos) << r1.reason;
  CutResult r2 = cut_along(c, {Vec3(0.1, 0.1, 1.0), Vec3(0.3, 0.1, 1.0)});
  EXPECT_FALSE(r2.ok);
  EXPECT_NE(r2.reason.find("off the cloth"), std::string::npos) << r2.reason;
  const double nan = std::nan("");
  CutResult r3 = cut_along(c, {Vec3(nan, 0, 0), Vec3(0.1, nan, 0), Vec3(0.2, 0.2, 0)});
  EXPECT_FALSE(r3.ok);
  CutResult r4 = cut_path(c, {0, 40});  // no shared edge
  EXPECT_FALSE(r4.ok);
  CutResult r5 = cut_path(c, {0, 100000});
  EXPECT_FALSE(r5.ok);
  EXPECT_EQ(state_hash(c), h);
  std::printf("reasons: %s | %s | %s | %s\n", r1.reason.c_str(), r2.reason.c_str(),
              r3.reason.c_str(), r4.reason.c_str());
}

TEST(Cut, ManyRandomCutsKeepAValidMesh) {
  Cloth c = flat(17);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(0, 0.4);
  const double m0 = total_mass(c);
  int ok = 0;
  for (int i = 0; i < 30; ++i) {
    CutResult r = cut_along_material(c, {Vec2(U(rng), U(rng)), Vec2(U(rng), U(rng))});
    ok += r.ok;
    ASSERT_TRUE(c.validate().empty()) << c.validate();
    expect_material_kept(c, r);
  }
  EXPECT_GT(ok, 15);
  EXPECT_NEAR(total_mass(c), m0, 1e-12);
  std::printf("30 random cuts: %d applied, %d pieces, %d vertices\n", ok, count_components(c),
              c.num_vertices());
}

}  // namespace
}  // namespace drape::sim
