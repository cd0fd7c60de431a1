// CalibrationMode (xr_app/app/calibration_mode.cpp): palm frames resting on the four markers as a
// turned and moved tracker sees them -> each taken on its dwell, then the transform within 1 mm;
// touches on one line -> refused with its reason and asked for again from the first marker; a
// hand that moves on without resting takes nothing.
#include "xr_app/app/calibration_mode.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>

#include "tracking/one_euro.hpp"

using namespace drape;
using namespace drape::app;
using tracking::Vec3;

namespace {
// Feeds the right palm at 60 Hz: `secs` from a to b, then still at b for `rest` s; through a
// HandFilter as the session does. Returns the events.
std::vector<CalibrationMode::Event> move(CalibrationMode& cm, tracking::HandFilter& filter,
                                         double& t, const Vec3& a, const Vec3& b, double secs,
                                         double rest) {
  std::vector<CalibrationMode::Event> events;
  const int n = static_cast<int>(secs * 60), m = static_cast<int>(rest * 60);
  for (int i = 0; i < n + m; ++i, t += 1 / 60.0) {
    tracking::HandFrame f;
    f.hand = tracking::Hand::Right;
    f.time = t;
    f.tracked = true;
    f.confidence = 0.9;
    f.palm.position = i < n ? a + (b - a) * ((i + 1.0) / n) : b;
    for (auto& e : cm.update(f, filter.update(f))) events.push_back(e);
  }
  return events;
}
}  // namespace

TEST(CalibrationMode, FourRestsGiveTheTrackersTransform) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.6, Vec3(0.2, 1, 0.1).normalized()).matrix();
  const Vec3 t0(0.3, 0.8, -1.4);  // stage = R tracker + t0
  CalibrationMode cm;
  tracking::HandFilter filter;
  double t = 0;
  Vec3 at = R.transpose() * (calibration_markers()[0].stage - t0);
  EXPECT_NE(cm.guidance().find("marker 1 of 4"), std::string::npos) << cm.guidance();
  std::vector<CalibrationMode::Event> all;
  for (const auto& mk : calibration_markers()) {
    const Vec3 next = R.transpose() * (mk.stage - t0);
    for (auto& e : move(cm, filter, t, at, next, 0.8, 1.5)) all.push_back(e);
    at = next;
  }
  ASSERT_EQ(all.size(), 5u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(all[i].kind, CalibrationMode::Event::Taken);
    EXPECT_EQ(all[i].marker, i);
    EXPECT_LT((all[i].tracker - R.transpose() * (calibration_markers()[i].stage - t0)).norm(),
              1e-4);
  }
  EXPECT_EQ(all[4].kind, CalibrationMode::Event::Computed);
  ASSERT_TRUE(cm.done());
  const tracking::Calibration& c = *cm.result();
  for (const Vec3& p : {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)})
    EXPECT_LT((c.apply(p) - (R * p + t0)).norm(), 1e-3) << p.transpose();
  std::printf("rms %.3g m, max %.3g m, scale %.6f\n", c.rms_residual, c.max_residual, c.scale);
  EXPECT_EQ(c.pairs, 4);
}

TEST(CalibrationMode, CollinearTouchesAreRefusedAndAskedForAgain) {
  CalibrationMode cm;
  tracking::HandFilter filter;
  double t = 0;
  std::vector<CalibrationMode::Event> all;
  Vec3 at(0, 0, -1);
  for (int i = 0; i < 4; ++i) {
    const Vec3 next(0.1 * i, 0.2 * i, -1);
    for (auto& e : move(cm, filter, t, at, next, 0.8, 1.5)) all.push_back(e);
    at = next;
  }
  ASSERT_EQ(all.size(), 5u);
  EXPECT_EQ(all[4].kind, CalibrationMode::Event::Refused);
  EXPECT_NE(all[4].message.find("collinear"), std::string::npos) << all[4].message;
  EXPECT_FALSE(cm.done());
  EXPECT_EQ(cm.current(), 0);
  EXPECT_NE(cm.guidance().find("marker 1 of 4"), std::string::npos) << cm.guidance();
}

TEST(CalibrationMode, AHandThatNeverRestsTakesNothing) {
  CalibrationMode cm;
  tracking::HandFilter filter;
  double t = 0;
  // 2 m back and forth at 0.5 m/s: never 1 s within 3 cm.
  auto events = move(cm, filter, t, Vec3(0, 1, -1), Vec3(1, 1, -1), 2.0, 0.0);
  for (auto& e : move(cm, filter, t, Vec3(1, 1, -1), Vec3(0, 1, -1), 2.0, 0.0)) events.push_back(e);
  EXPECT_TRUE(events.empty());
  EXPECT_EQ(cm.current(), 0);
}
