// The sewn tight skirt simulated on the 9AR form by XPBD (sim/draping/garment_sim.hpp): it
// comes to rest, its seams stay closed, it does not go into the form, and its girths at the
// waist and hip agree with the geometric garment's (the pattern sewn); its waist stays up.
#include "sim/draping/garment_sim.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "sim/draping/pattern_pipeline.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"

using namespace drape::sim;

namespace {

std::shared_ptr<const DressForm> form_9ar() {
  auto m = measurements_for_size("9AR");
  if (!m.ok()) return nullptr;
  auto form = DressForm::from_measurements(*m);
  return form.ok() ? std::make_shared<const DressForm>(std::move(*form)) : nullptr;
}

}  // namespace

TEST(GarmentSim, TightSkirtRestsClosedOnTheForm) {
  const auto form = form_9ar();
  ASSERT_TRUE(form);
  auto d = load_design(std::string(DRAPE_SOURCE_DIR) + "/assets/designs/tight-skirt.json");
  ASSERT_TRUE(d.ok()) << d.error();
  auto fabric = load_fabric(std::string(DRAPE_SOURCE_DIR) + "/assets/fabrics.json", "muslin");
  ASSERT_TRUE(fabric.ok()) << fabric.error();
  auto r = run_pattern_pipeline(*d, *form, *fabric);
  ASSERT_TRUE(r.ok()) << r.error();
  const MappingSurface surf(*form, r->design.ease, true);
  auto s = simulate_garment(r->garment, form, surf, *fabric);
  ASSERT_TRUE(s.ok()) << s.error();
  std::printf(
      "%d frames (%s), %.1f ms (%.2f ms/frame); seam gap %.3f mm (start %.3f mm); "
      "deepest %.3f mm; strain max %.2f %% rms %.2f %%\n",
      s->frames, s->at_rest ? "at rest" : "moving", s->wall_ms, s->ms_per_frame, s->seam_gap_max_mm,
      s->seam_gap_start_mm, s->penetration_max_mm, s->strain_max_pct, s->strain_rms_pct);
  for (const FitBand* b : {&s->waist, &s->hip})
    std::printf("band y %.3f: ease max %.2f mean %.2f mm; girth %.2f mm, geometric %.2f mm\n", b->y,
                b->ease_max_mm, b->ease_mean_mm, b->girth_mm, b->girth_geometric_mm);
  EXPECT_TRUE(s->at_rest);
  // Seams closed: every tie within 0.5 mm (measured 0.34 mm; 0.25 mm at the start).
  EXPECT_LT(s->seam_gap_max_mm, 0.5);
  // Not into the form: no vertex deeper than 0.5 mm (measured 0).
  EXPECT_LT(s->penetration_max_mm, 0.5);
  // Girths of the simulated cloth within 1 % of the geometric garment's (the pattern sewn) plus
  // the contact offset's 2 pi 2 mm = 12.6 mm (the cloth is kept 2 mm off the form; the geometric
  // garment lies on it). Measured: waist +0.19 %, hip +0.25 %.
  for (const FitBand* b : {&s->waist, &s->hip}) {
    EXPECT_GT(b->vertices, 20);
    EXPECT_LT(std::abs(b->girth_error_pct), 1.0);
  }
  // The waist seam stays at the waist: less than 2 cm below its geometric place (measured 2.8).
  EXPECT_LT(s->waist_seam_drop_mm, 20.0);
  // A tight skirt on the form: the hip's mean ease is a few millimetres at most.
  EXPECT_LT(s->hip.ease_mean_mm, 6.0);
  // Strain: rms over the triangles below 15 % (measured 9.7 %; the largest, hundreds of per cent,
  // are the dart tips' millimetre triangles: docs/draping.md).
  EXPECT_LT(s->strain_rms_pct, 15.0);
}
