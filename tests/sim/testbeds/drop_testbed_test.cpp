// The standard drop (sim/testbeds/drop_testbed.hpp, the same scene as bench/baseline_bench.cpp): a
// muslin panel held at its top edge above the bust swings down and falls against the front of the
// 9AR form. After the drop no vertex is inside the form beyond the offset. Prints the max
// penetration.
#include "sim/testbeds/drop_testbed.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "sim/solvers/verlet_solver.hpp"

using namespace drape::sim;

namespace {
std::shared_ptr<const DressForm> form_9ar() {
  auto form = DressForm::from_measurements(FormMeasurements{});
  if (!form) return nullptr;
  return std::make_shared<const DressForm>(std::move(form.value()));
}
}  // namespace

TEST(Drop, SceneIsHeldAboveTheBustInFrontOfTheForm) {
  auto form = form_9ar();
  ASSERT_TRUE(form);
  DropTestbed d = make_front_drop(form, 17);
  const FormLandmarks& lm = form->landmarks();
  EXPECT_NEAR(d.hinge_y, lm.bust_y + 0.10, 1e-12);
  int pinned = 0;
  for (int i = 0; i < d.cloth.num_vertices(); ++i) {
    const Vec3& p = d.cloth.state.x[i];
    EXPECT_GT(form->signed_distance(p), 0.015) << "vertex " << i << " starts at/inside the form";
    if (d.cloth.state.flags[i] & kFlagPinned) {
      ++pinned;
      EXPECT_NEAR(p.y(), d.hinge_y, 1e-12);
      EXPECT_NEAR(p.z(), d.hinge_z, 1e-12);
    }
  }
  EXPECT_EQ(pinned, 17);
}

TEST(Drop, PanelOnFormStaysOutside) {
  auto form = form_9ar();
  ASSERT_TRUE(form);
  const DressForm& f = *form;
  DropTestbed d = make_front_drop(form, 17);  // 0.4 m, 2.5 cm spacing
  Cloth& c = d.cloth;
  VerletParams vp;
  vp.air_drag = 2.0;
  VerletSolver s(vp);
  double pen = 0, coll_ms = 0, max_inside_during = 0;
  int substeps = 0;
  for (int k = 0; k < 90; ++k) {  // 1 s: the panel swings down and settles against the bust
    StepStats st = s.step(c, d.scene, 1.0 / 90);
    ASSERT_FALSE(st.diverged) << "frame " << k;
    pen = std::max(pen, st.max_penetration);
    coll_ms += st.collision_ms;
    substeps = st.substeps;
    for (const Vec3& p : c.state.x) {
      const double sd = f.signed_distance(p);
      if (std::isfinite(sd)) max_inside_during = std::max(max_inside_during, -sd);
    }
  }
  double inside = 0, min_dist = 1e9, lowest = 1e9;
  int touching = 0, in_range = 0;
  for (const Vec3& p : c.state.x) {
    lowest = std::min(lowest, p.y());
    const double sd = f.signed_distance(p);
    if (!std::isfinite(sd)) continue;
    ++in_range;
    min_dist = std::min(min_dist, sd);
    inside = std::max(inside, -sd);
    touching += sd < d.scene.offset + 0.002;
  }
  std::printf(
      "drop: %d substeps/frame, max penetration into the offset shell before response %.3e m; "
      "after 1 s: min distance to form %.3e m (offset %.3f), deepest inside the surface %.3e m "
      "(during the drop %.3e m), %d vertices within 2 mm of the offset, %d/%d in the form's "
      "height range, lowest y %.3f, collision %.1f ms total\n",
      substeps, pen, min_dist, d.scene.offset, std::max(0.0, inside), max_inside_during, touching,
      in_range, c.num_vertices(), lowest, coll_ms);
  EXPECT_EQ(in_range, c.num_vertices());       // the scene never leaves the section model
  EXPECT_LT(lowest, d.hinge_y - 0.3);          // it did fall (hangs down, not held up)
  EXPECT_GT(touching, 10);                     // it did land against the form
  EXPECT_GE(min_dist, 0.0);                    // no vertex inside the form
  EXPECT_GT(min_dist, d.scene.offset - 1e-3);  // nor deeper than 1 mm into the offset shell
  EXPECT_LT(pen, 0.01);                        // no vertex ever got 1 cm into the shell
  EXPECT_LT(max_inside_during, 0.005);         // nor 5 mm inside the surface at a frame end
}
