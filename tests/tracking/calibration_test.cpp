#include "tracking/calibration.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <random>

using namespace drape::tracking;

TEST(Calibration, RecoversSimilarityAndReportsResidual) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Vec3(0.2, 1, 0.3).normalized()).toRotationMatrix();
  const double s = 1.25;
  const Vec3 T(0.3, -1.2, 2.0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> noise(0, 0.002);
  std::vector<Vec3> src, dst, dst_noisy;
  for (int i = 0; i < 8; ++i) {
    const Vec3 p(u(rng), u(rng), u(rng));
    src.push_back(p);
    dst.push_back(s * R * p + T);
    dst_noisy.push_back(dst.back() + Vec3(noise(rng), noise(rng), noise(rng)));
  }
  std::string err;
  auto c = calibrate(src, dst, &err);
  ASSERT_TRUE(c) << err;
  std::printf("exact: scale err %.2e, rot err %.2e, residual %.2e m\n", std::abs(c->scale - s),
              (c->rotation - R).norm(), c->rms_residual);
  EXPECT_NEAR(c->scale, s, 1e-9);
  EXPECT_LT((c->rotation - R).norm(), 1e-9);
  EXPECT_LT((c->translation - T).norm(), 1e-9);
  EXPECT_LT(c->rms_residual, 1e-9);
  auto cn = calibrate(src, dst_noisy, &err);
  ASSERT_TRUE(cn);
  std::printf("noisy (2 mm): residual rms %.4f m max %.4f m\n", cn->rms_residual, cn->max_residual);
  EXPECT_GT(cn->rms_residual, 0.0005);
  EXPECT_LT(cn->rms_residual, 0.004);
  // Three points are enough.
  auto c3 = calibrate({src[0], src[1], src[2]}, {dst[0], dst[1], dst[2]}, &err);
  ASSERT_TRUE(c3) << err;
  EXPECT_LT((c3->apply(src[5]) - dst[5]).norm(), 1e-9);
}

TEST(Calibration, RejectsTooFewCollinearOrNonFinite) {
  std::string err;
  EXPECT_FALSE(calibrate({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(0, 0, 0), Vec3(1, 0, 0)}, &err));
  EXPECT_NE(err.find("at least 3"), std::string::npos);
  EXPECT_FALSE(calibrate({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)},
                         {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)}, &err));
  EXPECT_NE(err.find("collinear"), std::string::npos);
  EXPECT_FALSE(calibrate({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, NAN, 0)},
                         {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, &err));
}

TEST(Calibration, SaveLoadRoundTripAndBadFiles) {
  Calibration c;
  c.scale = 0.9;
  c.rotation = Eigen::AngleAxisd(0.3, Vec3::UnitY()).toRotationMatrix();
  c.translation = Vec3(1, 2, 3);
  c.rms_residual = 0.004;
  c.pairs = 4;
  const std::string path = std::string(DRAPE_BINARY_DIR) + "/calib_test.json";
  ASSERT_TRUE(save_calibration(c, path));
  std::string err;
  auto l = load_calibration(path, &err);
  ASSERT_TRUE(l) << err;
  EXPECT_NEAR(l->scale, 0.9, 1e-12);
  EXPECT_LT((l->rotation - c.rotation).norm(), 1e-12);
  EXPECT_NEAR(l->rms_residual, 0.004, 1e-12);
  const std::string bad = std::string(DRAPE_BINARY_DIR) + "/calib_bad.json";
  std::ofstream(bad)
      << R"({"scale": 1, "rotation": [[1,0,0],[0,1,0],[0,0,2]], "translation": [0,0,0]})";
  EXPECT_FALSE(load_calibration(bad, &err));
  EXPECT_NE(err.find("rotation"), std::string::npos) << err;
  std::ofstream(bad) << "{ not json";
  EXPECT_FALSE(load_calibration(bad, &err));
  EXPECT_NE(err.find(bad), std::string::npos);
  EXPECT_FALSE(load_calibration(bad + ".missing", &err));
}
