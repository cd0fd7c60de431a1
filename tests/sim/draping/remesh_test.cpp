// Remeshing a piece (constrained Delaunay refinement): conforming to the
// outline, quality bound met, area kept, seam labels on the boundary vertices.
#include "sim/draping/remesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace drape::sim;

namespace {
// A 20 x 30 cm piece with a 2 cm wide, 8 cm deep dart V in its top edge.
PatternPiece test_piece() {
  PatternPiece p;
  p.name = "test";
  p.labels = {"hem", "side", "waist", "dart1_leg2", "dart1_leg1", "centre_front"};
  const auto add = [&](double x, double y, int label) {
    p.outline.emplace_back(x, y);
    p.seg_label.push_back(label);
  };
  add(0, 0, 0);
  add(0.2, 0, 1);
  add(0.2, 0.3, 2);
  add(0.11, 0.3, 3);
  add(0.10, 0.22, 4);
  add(0.09, 0.3, 2);
  add(0, 0.3, 5);
  p.darts.push_back({4, 5, 3, 0.02});
  return p;
}
}  // namespace

TEST(Remesh, ConformingQualityMesh) {
  const PatternPiece p = test_piece();
  RemeshOptions o;
  o.max_edge = 0.02;
  auto m = remesh_piece(p, o);
  ASSERT_TRUE(m.ok()) << m.error();
  std::printf(
      "%zu vertices, %zu triangles, min angle %.1f deg, max edge %.1f mm, area %.6f vs %.6f\n",
      m->material.size(), m->triangles.size(), m->min_angle_deg, m->max_edge * 1000, m->area,
      p.area());
  EXPECT_NEAR(m->area, p.area(), 1e-9);
  EXPECT_LE(m->max_edge, 0.02 * 1.5);
  // The dart V's 14 degree tip bounds the smallest angle; elsewhere CGAL's 20.7 degree bound.
  EXPECT_GT(m->min_angle_deg, 5.0);
  // Every outline point is a mesh vertex.
  for (const Vec2& q : p.outline) {
    double best = 1;
    for (const Vec2& v : m->material) best = std::min(best, (v - q).norm());
    EXPECT_LT(best, 1e-12);
  }
  // Triangles counter-clockwise, inside the outline.
  for (const auto& t : m->triangles) {
    const Vec2 a = m->material[t[0]], b = m->material[t[1]], c = m->material[t[2]];
    EXPECT_GT((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x(), 0);
    EXPECT_TRUE(inside_polygon(p.outline, (a + b + c) / 3));
  }
  // Seam vertices ordered along the seam; the side seam runs from (0.2, 0) to (0.2, 0.3).
  const std::vector<int> side = m->seam_vertices(p, "side");
  ASSERT_GE(side.size(), 16u);  // 30 cm at <= 2 cm edges
  EXPECT_NEAR(m->material[side.front()].y(), 0.0, 1e-12);
  EXPECT_NEAR(m->material[side.back()].y(), 0.3, 1e-12);
  for (size_t i = 1; i < side.size(); ++i) {
    EXPECT_NEAR(m->material[side[i]].x(), 0.2, 1e-9);
    EXPECT_GT(m->material[side[i]].y(), m->material[side[i - 1]].y());
  }
  const std::vector<int> leg1 = m->seam_vertices(p, "dart1_leg1");
  ASSERT_GE(leg1.size(), 2u);
  EXPECT_NEAR((m->material[leg1.front()] - Vec2(0.10, 0.22)).norm(), 0, 1e-12);
  // Interior vertices carry no label, boundary ones do.
  int labelled = 0;
  for (size_t v = 0; v < m->material.size(); ++v) labelled += m->vertex_label[v] >= 0;
  EXPECT_GT(labelled, 40);
  EXPECT_LT(labelled, static_cast<int>(m->material.size()));
}

TEST(Remesh, BadInput) {
  PatternPiece p;
  p.outline = {Vec2(0, 0), Vec2(1, 0)};
  p.seg_label = {0, 0};
  p.labels = {"x"};
  auto m = remesh_piece(p);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().find("fewer than 3"), std::string::npos);
}
