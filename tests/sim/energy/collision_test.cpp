// Tests of sim/energy/collision.cpp against analytic distances, and the form's section lookup.
#include "sim/energy/collision.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "sim/form/dress_form.hpp"

using namespace drape::sim;

TEST(Collision, Floor) {
  Vec3 p(0.1, -0.01, 0.2);
  EXPECT_NEAR(collide_floor(p, 0.002), 0.012, 1e-15);
  EXPECT_DOUBLE_EQ(p.y(), 0.002);
  Vec3 q(0, 0.5, 0);
  EXPECT_EQ(collide_floor(q, 0.002), 0.0);
  EXPECT_EQ(q, Vec3(0, 0.5, 0));
}

TEST(Collision, SphereAndCapsule) {
  const Vec3 c(0, 1, 0);
  Vec3 p(0.1, 1, 0);
  EXPECT_NEAR(collide_sphere(p, c, 0.2, 0.01), 0.11, 1e-12);
  EXPECT_NEAR((p - c).norm(), 0.21, 1e-12);
  EXPECT_NEAR(p.y(), 1.0, 1e-12);  // radial
  Vec3 far(0.5, 1, 0);
  EXPECT_EQ(collide_sphere(far, c, 0.2, 0.01), 0.0);
  // Capsule along x from (0,1,0) to (0.3,1,0), radius 0.05: a point above its middle.
  Vec3 q(0.15, 1.02, 0);
  EXPECT_NEAR(collide_capsule(q, c, Vec3(0.3, 1, 0), 0.05, 0.0), 0.03, 1e-12);
  EXPECT_TRUE(q.isApprox(Vec3(0.15, 1.05, 0)));
  // Degenerate capsule = sphere.
  Vec3 r(0, 1.01, 0);
  EXPECT_NEAR(collide_capsule(r, c, c, 0.05, 0.0), 0.04, 1e-12);
}

TEST(Collision, BoxAndPlate) {
  const Vec3 c(0, 1, 0), half(0.1, 0.2, 0.3);
  Vec3 p(0.08, 1.0, 0.0);  // inside, nearest face +x at 0.02
  EXPECT_NEAR(collide_box(p, c, half, 0.005), 0.025, 1e-12);
  EXPECT_NEAR(p.x(), 0.105, 1e-12);
  Vec3 corner(0.103, 1.203, 0.0);  // outside near the edge, distance 0.003*sqrt2
  const double d = 0.003 * std::sqrt(2.0);
  EXPECT_NEAR(collide_box(corner, c, half, 0.005), 0.005 - d, 1e-12);
  EXPECT_NEAR((corner - Vec3(0.1, 1.2, 0.0)).norm(), 0.005, 1e-12);
  Plate plate;  // top face at y = 0.8
  Vec3 q(0.1, 0.799, 0.1);
  EXPECT_NEAR(collide_plate(q, plate, 0.002), 0.003, 1e-12);
  EXPECT_NEAR(q.y(), 0.802, 1e-12);
  Vec3 off_edge(0.5, 0.79, 0.0);  // beside the plate: untouched
  EXPECT_EQ(collide_plate(off_edge, plate, 0.002), 0.0);
}

TEST(Collision, ColliderCullsByBounds) {
  Cloth cloth = make_panel(PanelSpec{0.2, 0.2, 0.05}, FabricParams{});
  place_spread(cloth, Vec3(-0.1, 1.5, -0.1), Vec3::UnitX(), Vec3::UnitZ());
  SceneObjects scene;
  scene.spheres.push_back({Vec3(0, 1.45, 0), 0.1});  // touches the cloth's box
  scene.spheres.push_back({Vec3(3, 1.5, 0), 0.1});   // far away
  scene.boxes.push_back({Vec3(0, 0.5, 0), Vec3(0.1, 0.1, 0.1)});
  Collider col;
  col.prepare(cloth.state, scene);
  EXPECT_EQ(col.active_objects(), 1);  // floor not touched (cloth at 1.5 m), far sphere skipped
  auto st = col.project(cloth.state, scene);
  std::printf("contacts %d, max penetration %.4f m\n", st.contacts, st.max_penetration);
  EXPECT_GT(st.contacts, 0);
  EXPECT_NEAR(st.max_penetration, 0.05 + scene.offset, 1e-12);  // centre vertex 5 cm deep
  for (const Vec3& p : cloth.state.x)
    EXPECT_GE((p - Vec3(0, 1.45, 0)).norm(), 0.1 + scene.offset - 1e-12);
  // Pinned vertices do not collide; eq. 3-7 displacements do not move positions.
  Cloth c2 = make_panel(PanelSpec{0.2, 0.2, 0.05}, FabricParams{});
  place_spread(c2, Vec3(-0.1, 1.5, -0.1), Vec3::UnitX(), Vec3::UnitZ());
  const int centre = 2 * c2.topo.grid_nx + 2;
  c2.state.flags[centre] |= kFlagPinned;
  std::vector<Vec3> disp;
  auto before = c2.state.x;
  auto st2 = col.response_displacements(c2.state, scene, disp);
  EXPECT_EQ(c2.state.x, before);
  EXPECT_EQ(disp[centre], Vec3::Zero());
  EXPECT_EQ(st2.contacts, 8);  // 3x3 around the centre minus the pinned one
}

TEST(Collision, DressFormSectionLookup) {
  auto form = DressForm::from_measurements(FormMeasurements{});
  ASSERT_TRUE(form) << form.error();
  auto shared = std::make_shared<const DressForm>(std::move(form.value()));
  SceneObjects scene;
  scene.form = shared;
  scene.floor = false;
  scene.offset = 0.003;
  const Aabb box = form_bounds(*shared);
  std::printf("form bounds (%.3f %.3f %.3f) - (%.3f %.3f %.3f)\n", box.lo.x(), box.lo.y(),
              box.lo.z(), box.hi.x(), box.hi.y(), box.hi.z());
  // Points on a ring inside the waist end up `offset` outside the surface.
  const double y = shared->landmarks().waist_y;
  ClothState st;
  for (int k = 0; k < 64; ++k) {
    const double th = 2 * M_PI * k / 64;
    st.x.push_back(Vec3(0.05 * std::sin(th), y, 0.05 * std::cos(th)));
  }
  st.flags.assign(st.x.size(), 0);
  Collider col;
  auto cs = col.project(st, scene);
  EXPECT_EQ(cs.contacts, 64);
  double worst = 0;
  for (const Vec3& p : st.x) worst = std::max(worst, std::abs(shared->signed_distance(p) - 0.003));
  std::printf("form: max |distance - offset| after push %.3e m\n", worst);
  EXPECT_LT(worst, 1e-9);
  // A vertex outside the form's bounds is not touched at all (bounds test skips the form).
  ClothState far;
  far.x = {Vec3(2, 1, 2)};
  far.flags = {0};
  auto cf = col.project(far, scene);
  EXPECT_EQ(cf.objects_tested, 0);
}

TEST(Collision, DiscWithRoundedRim) {
  const Disc d{Vec3(0, 0, 0), 0.09, 0.004, 0.002};  // top at y = 0, rim a 2 mm half-torus
  Vec3 n;
  EXPECT_NEAR(disc_distance(Vec3(0.03, 0.01, 0), d, &n), 0.01, 1e-12);  // above the top
  EXPECT_NEAR(n.y(), 1, 1e-12);
  EXPECT_NEAR(disc_distance(Vec3(0.1, -0.002, 0), d, &n), 0.01, 1e-12);  // beside the rim
  EXPECT_NEAR(n.x(), 1, 1e-12);
  // Off the rounded corner: distance from the rim's circle of centres (r 0.088, y -0.002).
  const Vec3 corner(0.088 + 0.01 * std::cos(0.7), -0.002 + 0.01 * std::sin(0.7), 0);
  EXPECT_NEAR(disc_distance(corner, d, &n), 0.008, 1e-12);
  EXPECT_NEAR(n.dot(Vec3(std::cos(0.7), std::sin(0.7), 0)), 1, 1e-12);
  EXPECT_LT(disc_distance(Vec3(0.05, -0.001, 0), d, nullptr), 0);  // inside
  // A point inside is pushed out to the offset, along the nearest face (the top here).
  Vec3 p(0.05, -0.0005, 0.01);
  EXPECT_NEAR(collide_disc(p, d, 0.001), 0.0015, 1e-12);
  EXPECT_NEAR(p.y(), 0.001, 1e-12);
  Vec3 q(0.2, 0.0, 0);  // far: untouched
  EXPECT_EQ(collide_disc(q, d, 0.001), 0);
  EXPECT_EQ(q, Vec3(0.2, 0.0, 0));
}
