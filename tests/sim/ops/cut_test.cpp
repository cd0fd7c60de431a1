// The cut primitive (sim/ops/cut.cpp): edge paths, splitting on the left of the cut direction,
// components, material coordinates and mass kept, bad strokes refused.
#include "sim/ops/cut.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "sim/solvers/solver_vbd.hpp"
#include "sim/testbeds/testbed.hpp"

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

// The incidence kept with the cloth and updated in place by each split must equal a rebuild
// from scratch: same triangles per vertex, same partition into components, and the masses
// re-lumped only at the split vertices equal a full relump_masses() bit for bit.
void expect_incidence_consistent(const Cloth& c) {
  const ClothIncidence& I = c.incidence;
  ASSERT_TRUE(I.built);
  ASSERT_EQ(I.version, c.topology_version);
  Cloth fresh = c;
  fresh.incidence = ClothIncidence{};
  ensure_incidence(fresh);
  const ClothIncidence& F = fresh.incidence;
  ASSERT_EQ(I.start.size(), F.start.size());
  for (int v = 0; v < c.num_vertices(); ++v) {
    std::vector<int32_t> a(I.tris.begin() + I.start[v], I.tris.begin() + I.start[v] + I.count[v]);
    std::vector<int32_t> b(F.tris.begin() + F.start[v], F.tris.begin() + F.start[v] + F.count[v]);
    ASSERT_EQ(a, b) << "vertex " << v;  // same triangles, same (ascending) order
  }
  int n_full = 0;
  const std::vector<int32_t> full = component_labels(c, &n_full);
  ASSERT_EQ(I.components, n_full);
  std::map<int32_t, int32_t> kept_to_full, full_to_kept;
  for (int v = 0; v < c.num_vertices(); ++v) {
    ASSERT_EQ(I.component[v] < 0, full[v] < 0) << v;
    if (full[v] < 0) continue;
    auto [i1, new1] = kept_to_full.emplace(I.component[v], full[v]);
    auto [i2, new2] = full_to_kept.emplace(full[v], I.component[v]);
    ASSERT_EQ(i1->second, full[v]) << "vertex " << v;  // a bijection between the labellings
    ASSERT_EQ(i2->second, I.component[v]) << "vertex " << v;
  }
  Cloth relumped = c;
  relumped.relump_masses();
  for (int v = 0; v < c.num_vertices(); ++v) {
    ASSERT_EQ(c.state.mass[v], relumped.state.mass[v]) << "vertex " << v;
    ASSERT_EQ(c.state.inv_mass[v], relumped.state.inv_mass[v]) << "vertex " << v;
  }
}

TEST(Cut, KeptIncidenceEqualsARebuildAfterManyCuts) {
  Cloth c = flat(17);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(0, 0.4);
  for (int i = 0; i < 25; ++i) {
    if (i % 3 == 2) {  // a 3D stroke now and then
      const double y = U(rng);
      cut_along(c, {Vec3(-0.05, y, 0.01), Vec3(0.2, y + 0.05, 0.01), Vec3(0.45, y, 0.01)});
    } else {
      cut_along_material(c, {Vec2(U(rng), U(rng)), Vec2(U(rng), U(rng))});
    }
    ASSERT_NO_FATAL_FAILURE(expect_incidence_consistent(c)) << "after cut " << i;
  }
  // The other edits bump topology_version: the incidence is then stale and rebuilt on demand.
  c.topology_changed();
  EXPECT_TRUE(ensure_incidence(c));
  EXPECT_FALSE(ensure_incidence(c));
  std::printf("25 cuts: %d pieces, %d vertices, kept incidence = rebuild\n", count_components(c),
              c.num_vertices());
}

// A stroke drawn across the cloth from beyond one edge to beyond the other, whose ends are far
// from the surface (more than max_distance: dropped as off the cloth), must still reach both
// edges and separate the cloth into exactly two pieces.
void expect_split_in_two(Cloth& c, const std::vector<Vec3>& stroke, const char* what) {
  const double m0 = total_mass(c), a0 = material_area(c);
  const int before = count_components(c);
  CutResult r = cut_along(c, stroke);
  ASSERT_TRUE(r.ok) << what << ": " << r.reason;
  EXPECT_TRUE(r.extended[0] && r.extended[1]) << what;
  EXPECT_EQ(count_components(c), before + 1) << what;
  EXPECT_EQ(r.components_after, before + 1) << what;
  EXPECT_NEAR(total_mass(c), m0, 1e-12) << what;
  EXPECT_NEAR(material_area(c), a0, 1e-12) << what;
  EXPECT_TRUE(c.validate().empty()) << c.validate();
  expect_material_kept(c, r);
  // The smooth stroke kept for the pattern outline reaches the edges too.
  double umin = 1e9, umax = -1e9;
  for (const Vec2& q : r.smooth_stroke_uv)
    umin = std::min(umin, q.x()), umax = std::max(umax, q.x());
  std::printf("%s: %zu path vertices, %zu new, %d -> %d pieces, stroke u in [%.3f, %.3f] m\n", what,
              r.path.size(), r.new_vertices.size(), before, count_components(c), umin, umax);
}

TEST(Cut, StrokeFromBeyondTheEdgesSplitsASpreadCloth) {
  Cloth c = flat(17);  // x = u in [0, 0.4], y = v, z = 0
  // Hovering 8 cm in front of the cloth beyond its edges, touching it only in the middle third.
  std::vector<Vec3> stroke;
  for (int i = 0; i <= 80; ++i) {
    const double x = -0.15 + 0.7 * i / 80.0;
    const double z = std::clamp(0.08 - 0.5 * (0.13 - std::abs(x - 0.2)), 0.01, 0.08);
    stroke.emplace_back(x, 0.21 + 0.02 * x, z);
  }
  expect_split_in_two(c, stroke, "spread");
  expect_incidence_consistent(c);
}

// Strokes down the cloth within two grid spacings of its left edge and off the bottom edge: the
// last hits lie on the boundary row, and the edge anchor of the end's extension is the next
// boundary node. The cut ends where it reaches the edge instead of going on along it: a leg along
// boundary edges separates nothing and left the strip attached by a slit tip (80 of these 1280
// strokes before).
TEST(Cut, StrokeNearlyAlongTheEdgeSeparatesTheStrip) {
  int attached = 0, total = 0;
  for (int a = 0; a < 40; ++a)
    for (int b = 0; b < 8; ++b)
      for (int e = 0; e < 4; ++e) {
        Cloth c = flat(41);  // 10 mm grid
        const double u0 = 0.005 + 0.0005 * a, slope = 0.05 * b, y_end = -0.01 - 0.02 * e;
        std::vector<Vec3> stroke;
        for (int i = 0; i <= 100; ++i) {
          const double y = 0.43 - (0.43 - y_end) * i / 100.0;
          stroke.emplace_back(u0 + slope * std::max(0.0, y - 0.2), y, 0.002);
        }
        const CutResult r = cut_along(c, stroke);
        ++total;
        if (!r.ok || r.components_after != 2 || count_components(c) != 2) {
          ++attached;
          ADD_FAILURE() << "u0 " << u0 << " slope " << slope << " end " << y_end << ": "
                        << (r.ok ? "components " + std::to_string(r.components_after) : r.reason);
        }
      }
  std::printf("strokes near the edge: %d of %d left the strip attached\n", attached, total);
}

TEST(Cut, StrokeFromBeyondTheEdgesSplitsARolledCloth) {
  Cloth c = flat(17);
  place_rolled(c, Vec3(0, 1.0, 0), Vec3::UnitX(), Vec3::UnitY(), 0.02);
  // Along the outer turn (grid row j, all its vertices share y and z), 5 mm outside it in the
  // middle and 8 cm outside beyond the edges (x < 0, x > 0.4).
  const int n = 17, j = n - 4;
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& p : c.state.x) centroid += p / c.num_vertices();
  const Vec3 p0 = c.state.x[j * n + n / 2];
  const Vec3 e_u = c.state.x[j * n + n / 2 + 1] - p0, e_v = c.state.x[(j + 1) * n + n / 2] - p0;
  Vec3 out = e_u.cross(e_v).normalized();
  if (out.dot(p0 - centroid) < 0) out = -out;
  std::vector<Vec3> stroke;
  for (int i = 0; i <= 80; ++i) {
    const double x = -0.15 + 0.7 * i / 80.0;
    const double lift = std::clamp(0.08 - 0.5 * (0.13 - std::abs(x - 0.2)), 0.005, 0.08);
    stroke.push_back(Vec3(x, p0.y(), p0.z()) + lift * out);
  }
  expect_split_in_two(c, stroke, "rolled");
}

// The app's default scenario: a 12 x 12 panel pinned across the chest of the 9AR form drapes
// over the bust; the stroke goes straight across at 22 cm below the top edge, 13 cm in front
// of the form's centre line, from 25 cm beyond the left edge to 25 cm beyond the right edge.
TEST(Cut, ScenarioStrokeAcrossADrapedClothSplitsIt) {
  Testbed sc = make_form_drape(12);
  ASSERT_TRUE(sc.objects.form);
  VbdOptions o;
  o.threads = 1;
  VbdSolver solver(o);
  for (int i = 0; i < 90; ++i) solver.step(sc.cloth, sc.objects, 1.0 / 90);
  double top = -1e9;
  for (const Vec3& p : sc.cloth.state.x) top = std::max(top, p.y());
  std::vector<Vec3> stroke;
  for (int i = 0; i <= 60; ++i) stroke.emplace_back(-0.5 + i / 60.0, top - 0.22, 0.13);
  expect_split_in_two(sc.cloth, stroke, "draped (default scenario stroke)");
  // Both pieces keep their material coordinates: the upper piece is every vertex above the
  // cut in material space (v), the lower every vertex below.
  const auto lab = component_labels(sc.cloth);
  int upper = -1, lower = -1;
  for (int v = 0; v < sc.cloth.num_vertices(); ++v) {
    const double m = sc.cloth.topo.material[v].y();
    if (m > 0.49) upper = lab[v];
    if (m < 0.01) lower = lab[v];
  }
  EXPECT_NE(upper, lower);
}

// A stroke that begins hovering above the middle of the cloth and comes down onto it is a
// slit from where it touches, not a cut from the edge: nothing is extended, one piece stays.
TEST(Cut, StrokeStartingAboveTheInteriorIsNotExtended) {
  Cloth c = flat(17);
  std::vector<Vec3> stroke;
  for (int i = 0; i <= 40; ++i) {  // from 10 cm above (0.1, 0.2) down and along +x
    const double x = 0.1 + 0.15 * i / 40.0;
    stroke.emplace_back(x, 0.2, std::max(0.005, 0.1 - 0.6 * (x - 0.1)));
  }
  CutResult r = cut_along(c, stroke);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_FALSE(r.extended[0]);
  EXPECT_FALSE(r.extended[1]);
  EXPECT_EQ(count_components(c), 1);
  expect_incidence_consistent(c);
}

}  // namespace
}  // namespace drape::sim
