// The live garment's World (xr_app/app/garment_scene.hpp): the tight skirt, the bodice and the
// dress sewn on the 9AR form with their seam ties in an XPBD solver, its seams closed after ticks
// of the session's solver, the ties dropped when the cloth's vertices change, and the errors naming
// the option.
#include "xr_app/app/garment_scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>

#include "sim/solvers/xpbd/xpbd_ties.hpp"

namespace drape::app {
namespace {

XrAppOptions garment_options(const std::string& design) {
  XrAppOptions o;
  o.garment = std::string(DRAPE_SOURCE_DIR) + "/assets/designs/" + design + ".json";
  o.fabrics_path = std::string(DRAPE_SOURCE_DIR) + "/assets/fabrics.json";
  return o;
}

const sim::XpbdSolver& solver_of(const sim::World& w) {
  const auto* s = dynamic_cast<const sim::XpbdSolver*>(w.solver.get());
  EXPECT_NE(s, nullptr);
  return *s;
}

TEST(GarmentScene, TightSkirtIsSewnWithTiesAndStaysClosed) {
  auto w = make_garment_world(garment_options("tight-skirt"));
  ASSERT_TRUE(w) << w.error();
  const int n = w->cloth.num_vertices();
  EXPECT_GT(n, 5000);
  EXPECT_GT(w->cloth.topo.num_triangles(), 10000);
  ASSERT_TRUE(w->scene.form);
  const auto& ties = solver_of(*w).ties();
  ASSERT_GT(ties.size(), 500u);
  for (const auto& t : ties) {
    ASSERT_LT(t.a, n);
    ASSERT_LT(std::max(t.b0, t.b1), n);
  }
  EXPECT_LT(sim::xpbd::max_tie_gap(ties, w->cloth.state.x), 0.001);
  for (int k = 0; k < 30; ++k) {
    if (w->before_step) w->before_step(*w, 1.0 / 90);
    const sim::StepStats st = w->solver->step(w->cloth, w->scene, 1.0 / 90);
    ASSERT_FALSE(st.diverged) << "tick " << k;
  }
  const double gap = sim::xpbd::max_tie_gap(ties, w->cloth.state.x);
  std::printf("tight skirt: %d vertices, %zu ties, seam gap after 30 ticks %.3f mm\n", n,
              ties.size(), gap * 1000);
  EXPECT_LT(gap, 0.001);
  const std::string status = garment_status(*w, 30);
  EXPECT_NE(status.find("garment: tick 30: " + std::to_string(n) + " vertices"), std::string::npos)
      << status;
  EXPECT_NE(status.find(std::to_string(ties.size()) + " seam ties"), std::string::npos) << status;
}

TEST(GarmentScene, NewVerticesDropTheTies) {
  auto w = make_garment_world(garment_options("tight-skirt"));
  ASSERT_TRUE(w) << w.error();
  ASSERT_FALSE(solver_of(*w).ties().empty());
  // A cut adds vertices (material coordinates, positions): the ties' indices no longer hold.
  w->cloth.topo.material.push_back(w->cloth.topo.material.back());
  w->cloth.state.x.push_back(w->cloth.state.x.back());
  ASSERT_TRUE(w->before_step);
  w->before_step(*w, 1.0 / 90);
  EXPECT_TRUE(solver_of(*w).ties().empty());
  ASSERT_FALSE(w->messages.empty());
  EXPECT_NE(w->messages.back().find("seam ties are dropped"), std::string::npos);
}

// The design's World: over `min_vertices` vertices and `min_ties` ties, every tie naming the
// cloth's vertices; 30 ticks of the session's solver without divergence, the seams then within
// 2 mm.
void expect_sewn_and_closed(const std::string& design, int min_vertices, size_t min_ties) {
  auto w = make_garment_world(garment_options(design));
  ASSERT_TRUE(w) << w.error();
  const int n = w->cloth.num_vertices();
  EXPECT_GT(n, min_vertices);
  const auto& ties = solver_of(*w).ties();
  ASSERT_GT(ties.size(), min_ties);
  for (const auto& t : ties) ASSERT_LT(std::max({t.a, t.b0, t.b1}), n);
  for (int k = 0; k < 30; ++k) {
    if (w->before_step) w->before_step(*w, 1.0 / 90);
    const sim::StepStats st = w->solver->step(w->cloth, w->scene, 1.0 / 90);
    ASSERT_FALSE(st.diverged) << design << " tick " << k;
  }
  const double gap = sim::xpbd::max_tie_gap(ties, w->cloth.state.x);
  std::printf("%s: %d vertices, %zu ties, seam gap after 30 ticks %.3f mm\n", design.c_str(), n,
              ties.size(), gap * 1000);
  EXPECT_LT(gap, 0.002) << design;
}

// The bodice: its zones sewn by ties (darts, side and shoulder seams), closed after 30 ticks.
TEST(GarmentScene, BodiceIsSewnWithTiesAndStaysClosed) {
  expect_sewn_and_closed("bodice", 500, 50);
}

// The dress: the bodice's and the tight skirt's seams and the waist seam joining them (27 991
// vertices, 1 856 ties on 9AR).
TEST(GarmentScene, DressIsSewnWithTiesAndStaysClosed) {
  expect_sewn_and_closed("dress", 20000, 1500);
}

TEST(GarmentScene, ErrorsNameTheOption) {
  // A dress naming a skirt design that does not exist: the error names the option and the part.
  const std::string bad = testing::TempDir() + "bad_dress.json";
  std::ofstream(bad)
      << R"({"name": "bad", "type": "dress", "bodice": "bodice", "skirt": "nosuch"})";
  XrAppOptions o = garment_options("dress");
  o.garment = bad;
  auto dress = make_garment_world(o);
  ASSERT_FALSE(dress);
  EXPECT_NE(dress.error().find("--garment"), std::string::npos) << dress.error();
  EXPECT_NE(dress.error().find("nosuch"), std::string::npos) << dress.error();
  o = garment_options("tight-skirt");
  o.garment_fabric = "silk";
  auto silk = make_garment_world(o);
  ASSERT_FALSE(silk);
  EXPECT_NE(silk.error().find("--garment-fabric silk"), std::string::npos) << silk.error();
  o = garment_options("nosuch");
  auto none = make_garment_world(o);
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().find("--garment"), std::string::npos) << none.error();
  o = garment_options("tight-skirt");
  o.form_size = "99XX";
  auto form = make_garment_world(o);
  ASSERT_FALSE(form);
  EXPECT_NE(form.error().find("--form 99XX"), std::string::npos) << form.error();
}

}  // namespace
}  // namespace drape::app
