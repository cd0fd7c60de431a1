// Panel with dart slits: node duplication, zones, validation errors by field.
#include "sim/draping/panel.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "sim/form/dress_form.hpp"

using namespace drape::sim;

namespace {
PanelDesign two_darts() {
  PanelDesign d;
  d.width = 0.20;
  d.height = 0.30;
  d.spacing = 0.01;
  d.slits = {{0.05, 0.10, 0.01}, {0.12, 0.08, 0.01}};
  return d;
}
}  // namespace

TEST(Panel, GridAndSlitDuplication) {
  auto p = build_panel(two_darts(), FabricParams{});
  ASSERT_TRUE(p.ok()) << p.error();
  EXPECT_EQ(p->nx, 21);
  EXPECT_EQ(p->ny, 31);
  // Slit 0: tip row 20, rows 21..30 duplicated (10 nodes); slit 1: tip row 22, 8 nodes.
  ASSERT_EQ(p->slits.size(), 2u);
  EXPECT_EQ(p->slits[0].far_nodes.size(), 10u);
  EXPECT_EQ(p->slits[1].far_nodes.size(), 8u);
  const auto& t = p->cloth.topo;
  EXPECT_EQ(t.num_vertices(), 21 * 31 + 18);
  EXPECT_EQ(t.num_triangles(), 2 * 20 * 30);
  for (size_t s = 0; s < 2; ++s) {
    const PanelSlit& sl = p->slits[s];
    for (size_t k = 0; k < sl.far_nodes.size(); ++k) {
      const int a = sl.near_nodes[k], b = sl.far_nodes[k];
      EXPECT_EQ(t.material[a], t.material[b]);  // same material point, two sides
      EXPECT_EQ(t.vertex_origin[b], a);
      EXPECT_EQ(t.vertex_zone[a], static_cast<int>(s));
      EXPECT_EQ(t.vertex_zone[b], static_cast<int>(s) + 1);
    }
  }
  // Every triangle uses only vertices of its own zone side: a triangle's zone equals the zone
  // of its duplicated vertices, and no triangle references both a node and its twin.
  for (int ti = 0; ti < t.num_triangles(); ++ti) {
    const auto& tri = t.triangles[ti];
    for (int v : tri) {
      if (t.vertex_origin[v] != v) {
        EXPECT_EQ(t.triangle_zone[ti], t.vertex_zone[v]);
      }
    }
    for (int a : tri) {
      for (int b : tri) {
        if (a != b) {
          EXPECT_NE(t.vertex_origin[a], t.vertex_origin[b]);
        }
      }
    }
  }
  // Zones from the slit extensions: left of column 5 zone 0, 5..11 zone 1, 12.. zone 2.
  EXPECT_EQ(t.triangle_zone[p->cell_triangle(2, 3, 0)], 0);
  EXPECT_EQ(t.triangle_zone[p->cell_triangle(7, 3, 1)], 1);
  EXPECT_EQ(t.triangle_zone[p->cell_triangle(15, 29, 0)], 2);
  // The slit is open: the twin nodes are not joined by any triangle edge to the far side twin.
  double area = 0;
  for (const auto& tri : t.triangles) {
    const Vec2 e1 = t.material[tri[1]] - t.material[tri[0]],
               e2 = t.material[tri[2]] - t.material[tri[0]];
    const double a = 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
    EXPECT_GT(a, 0);  // counter-clockwise
    area += a;
  }
  EXPECT_NEAR(area, 0.20 * 0.30, 1e-12);
  double mass = 0;
  for (double m : p->cloth.state.mass) mass += m;
  EXPECT_NEAR(mass, 0.06 * FabricParams{}.areal_density, 1e-12);
  Vec3 b;
  const int tri = p->locate(Vec2(0.123, 0.271), &b);
  ASSERT_GE(tri, 0);
  EXPECT_EQ(t.triangle_zone[tri], 2);
  EXPECT_GE(b.minCoeff(), 0);
}

TEST(Panel, RightCentreEdge) {
  PanelDesign d = two_darts();
  d.centre_edge_left = false;
  auto p = build_panel(d, FabricParams{});
  ASSERT_TRUE(p.ok()) << p.error();
  EXPECT_EQ(p->slits[0].column, 20 - 5);
  EXPECT_EQ(p->cloth.topo.triangle_zone[p->cell_triangle(19, 3, 0)], 0);
  EXPECT_EQ(p->cloth.topo.triangle_zone[p->cell_triangle(2, 3, 0)], 2);
  EXPECT_NEAR(p->centre_distance(0.15), 0.05, 1e-12);
}

TEST(Panel, BadInputNamesTheField) {
  {
    PanelDesign d = two_darts();
    d.slits[1].position = 0.055;  // same grid column as slits[0]
    auto p = build_panel(d, FabricParams{}, "front.panel");
    ASSERT_FALSE(p.ok());
    std::printf("%s\n", p.error().c_str());
    EXPECT_NE(p.error().find("front.panel.slits[1].position: overlapping slits"),
              std::string::npos);
  }
  {
    PanelDesign d = two_darts();
    d.slits[0].position = 0.25;
    auto p = build_panel(d, FabricParams{}, "front.panel");
    ASSERT_FALSE(p.ok());
    std::printf("%s\n", p.error().c_str());
    EXPECT_NE(p.error().find("front.panel.slits[0].position: slit off the panel"),
              std::string::npos);
  }
  {
    PanelDesign d = two_darts();
    d.slits[1].depth = 0.31;
    auto p = build_panel(d, FabricParams{}, "front.panel");
    ASSERT_FALSE(p.ok());
    std::printf("%s\n", p.error().c_str());
    EXPECT_NE(p.error().find("front.panel.slits[1].depth: slit off the panel"), std::string::npos);
  }
  {
    PanelDesign d = two_darts();
    d.spacing = -1;
    EXPECT_NE(validate_panel(d, "p").find("p.spacing"), std::string::npos);
  }
  {
    auto m = measurements_for_size("9AR");
    ASSERT_TRUE(m.ok());
    auto form = DressForm::from_measurements(*m);
    ASSERT_TRUE(form.ok()) << form.error();
    PanelDesign d = two_darts();
    d.width = 0.5;  // the 9AR hip girth is 0.91 m: half is 0.455 m
    const std::string e = validate_panel(d, "front.panel", &*form, 0.0, 1.0);
    std::printf("%s\n", e.c_str());
    EXPECT_NE(e.find("front.panel.width: panel larger than the form"), std::string::npos);
    d.width = 0.2;
    d.height = 1.2;
    EXPECT_NE(validate_panel(d, "front.panel", &*form, 0.0, 1.0).find("front.panel.height"),
              std::string::npos);
    d.height = 0.3;
    EXPECT_EQ(validate_panel(d, "front.panel", &*form, 0.0, 1.0), "");
  }
}
