// Calibration from a photo: synthetic top-view photos of drapes of known bending (a projection
// raster of the simulated drape, the specimen's circle printed around it, noise) give back the
// drape's DC and nodes, and the bending through the calibration; malformed photos are refused
// with a message naming what is wrong.
#include "sim/fabric_test/drape_photo.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "sim/fabric_test/calibrate.hpp"
#include "sim/fabric_test/drape_tester.hpp"
#include "tests/sim/fabric_test/small_drape.hpp"

namespace drape::sim {
namespace {

const std::string kDir = std::string(DRAPE_BINARY_DIR) + "/test_out/drape_photo";

std::string path(const std::string& name) {
  std::filesystem::create_directories(kDir);
  return kDir + "/" + name;
}

TEST(DrapePhoto, SyntheticPhotoGivesTheDrapesFiguresAndBending) {
  const double b_true = 6e-6;
  auto drape = run_drape_test(with_bending(b_true), small());
  ASSERT_TRUE(drape) << drape.error();
  const DrapeMeasureOptions mo;
  for (double ppm : {1500.0, 2600.0}) {  // 1.5 and 2.6 pixels per mm
    SCOPED_TRACE(ppm);
    const std::string p = path("drape_" + std::to_string(static_cast<int>(ppm)) + ".png");
    ASSERT_EQ(write_synthetic_photo(drape->shadow, mo, ppm, 8.0, p), "");
    auto ph = shadow_from_photo(p, mo);
    ASSERT_TRUE(ph) << ph.error();
    std::printf("%.0f px/m: scale error %+.3f %%, DC %.4f (drape %.4f), nodes %d (drape %d)\n", ppm,
                (ph->metres_per_pixel * ppm - 1) * 100, ph->measures.dc, drape->measures.dc,
                ph->measures.nodes, drape->measures.nodes);
    EXPECT_NEAR(ph->metres_per_pixel * ppm, 1.0, 0.005);  // the scale from the printed circle
    EXPECT_NEAR(ph->measures.dc, drape->measures.dc, 0.01);
    EXPECT_NEAR(ph->measures.nodes, drape->measures.nodes, 1);
    EXPECT_NEAR(ph->measures.r_max, drape->measures.r_max, 0.002);
    EXPECT_TRUE(ph->warnings.empty());
  }
  // The bending back from the photo's DC (within a factor 1.5 on this coarse specimen, as the
  // calibration from a simulated drape's own DC: sim_drape_tester_test).
  auto ph = shadow_from_photo(path("drape_2600.png"), mo);
  ASSERT_TRUE(ph) << ph.error();
  CalibrationOptions o;
  o.test = small();
  o.seeds = 1;
  o.warp_weft_ratio = 1;
  o.dc_tolerance = 0.003;
  auto cal = calibrate_bending(130, ph->measures.dc, o);
  ASSERT_TRUE(cal) << cal.error();
  std::printf("bending from the photo: %.3g N m (true %.3g, ratio %.3f)\n",
              cal->fabric.bending_warp, b_true, cal->fabric.bending_warp / b_true);
  EXPECT_NEAR(std::log(cal->fabric.bending_warp / b_true), 0, std::log(1.5));
}

ShadowRaster disc_shadow(double radius) {
  ShadowRaster r;
  r.reset(0.25, 0.0005);
  std::vector<Vec2> c;
  for (int q = 0; q < 720; ++q)
    c.emplace_back(radius * std::cos(q * M_PI / 360), radius * std::sin(q * M_PI / 360));
  rasterize_polygon(c, r);
  return r;
}

TEST(DrapePhoto, MalformedPhotosAreRefused) {
  const DrapeMeasureOptions mo;
  std::ofstream(path("not_an_image.png")) << "hello";
  auto r = shadow_from_photo(path("not_an_image.png"), mo);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("not_an_image.png: cannot read it as an image"), std::string::npos);
  EXPECT_FALSE(shadow_from_photo(path("missing.png"), mo));
  // Nothing on the table.
  ASSERT_EQ(write_synthetic_photo(disc_shadow(0.0), mo, 1500, 4, path("empty.png")), "");
  r = shadow_from_photo(path("empty.png"), mo);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("no dark drape"), std::string::npos) << r.error();
  // No printed circle: no scale.
  ASSERT_EQ(write_synthetic_photo(disc_shadow(0.12), mo, 1500, 4, path("no_circle.png"), false),
            "");
  r = shadow_from_photo(path("no_circle.png"), mo);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("scale is unknown"), std::string::npos) << r.error();
  // A drape larger than the frame.
  ASSERT_EQ(write_synthetic_photo(disc_shadow(0.2), mo, 1500, 4, path("cut.png")), "");
  r = shadow_from_photo(path("cut.png"), mo);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("cut off by the frame"), std::string::npos) << r.error();
}

}  // namespace
}  // namespace drape::sim
