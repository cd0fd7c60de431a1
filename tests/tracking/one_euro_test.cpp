#include "tracking/one_euro.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace drape::tracking;

TEST(OneEuro, ConstantInputPassesThroughExactly) {
  OneEuro f;
  Vec3 y;
  for (int i = 0; i < 100; ++i) y = f.filter(Vec3(0.1, 0.2, 0.3), i / 90.0);
  EXPECT_NEAR((y - Vec3(0.1, 0.2, 0.3)).norm(), 0.0, 1e-12);
}

TEST(OneEuro, ReducesJitterOnStillHand) {
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0, 0.005);  // 5 mm noise
  OneEuro f({1.0, 0.5, 1.0});
  double raw2 = 0, out2 = 0;
  for (int i = 0; i < 600; ++i) {
    const Vec3 x(n(rng), n(rng), n(rng));
    const Vec3 y = f.filter(x, i / 30.0);
    if (i > 30) {
      raw2 += x.squaredNorm();
      out2 += y.squaredNorm();
    }
  }
  const double ratio = std::sqrt(out2 / raw2);
  std::printf("still-hand jitter ratio filtered/raw = %.3f\n", ratio);
  EXPECT_LT(ratio, 0.5);
}

TEST(OneEuro, FirstOrderLowPassAtRestMatchesAnalyticAlpha) {
  // With beta = 0 the filter is an exponential smoother with alpha = 1/(1 + tau/dt).
  OneEuro f({2.0, 0.0, 1.0});
  f.filter(Vec3::Zero(), 0.0);
  const double dt = 0.01, tau = 1.0 / (2 * M_PI * 2.0), a = 1.0 / (1.0 + tau / dt);
  const Vec3 y = f.filter(Vec3(1, 0, 0), dt);
  std::printf("step response %.6f vs alpha %.6f\n", y.x(), a);
  EXPECT_NEAR(y.x(), a, 1e-12);
}

TEST(HandFilter, LossMarksLostAndReacquisitionDoesNotJump) {
  HandFilterParams p;
  p.lost_after = 0.2;
  p.reacquire_blend = 0.2;
  HandFilter hf(p);
  HandFrame f;
  f.tracked = true;
  f.confidence = 1;
  double t = 0;
  for (int i = 0; i < 30; ++i, t += 1 / 30.0) {
    f.time = t;
    f.palm.position = Vec3(0, 1, 0);
    hf.update(f);
  }
  EXPECT_FALSE(hf.lost());
  // Lost for 0.5 s.
  f.tracked = false;
  HandFrame out;
  for (int i = 0; i < 15; ++i, t += 1 / 30.0) {
    f.time = t;
    out = hf.update(f);
  }
  EXPECT_TRUE(hf.lost());
  EXPECT_FALSE(out.tracked);
  // Re-acquired 20 cm away: the first output stays where the hand was shown.
  f.tracked = true;
  f.time = t;
  f.palm.position = Vec3(0.2, 1, 0);
  out = hf.update(f);
  std::printf("first output after re-acquisition moved %.4f m (raw jump 0.2 m)\n",
              (out.palm.position - Vec3(0, 1, 0)).norm());
  EXPECT_TRUE(out.tracked);
  EXPECT_LT((out.palm.position - Vec3(0, 1, 0)).norm(), 0.01);
  double max_step = 0;
  Vec3 prev = out.palm.position;
  for (int i = 0; i < 30; ++i) {
    t += 1 / 30.0;
    f.time = t;
    out = hf.update(f);
    max_step = std::max(max_step, (out.palm.position - prev).norm());
    prev = out.palm.position;
  }
  std::printf("largest per-frame step during blend %.4f m\n", max_step);
  EXPECT_LT(max_step, 0.05);
  EXPECT_LT((out.palm.position - Vec3(0.2, 1, 0)).norm(), 0.005);
}

TEST(HandFilter, PredictionExtrapolatesConstantVelocity) {
  HandFilter hf;
  HandFrame f;
  f.tracked = true;
  f.confidence = 1;
  const double v = 0.5;  // m/s
  for (int i = 0; i < 120; ++i) {
    f.time = i / 60.0;
    f.palm.position = Vec3(v * f.time, 0, 0);
    hf.update(f);
  }
  const HandFrame now = hf.predict(f.time);
  const HandFrame ahead = hf.predict(f.time + 0.02);
  const double dx = ahead.palm.position.x() - now.palm.position.x();
  std::printf("predicted advance over 20 ms: %.5f m (expected %.5f)\n", dx, v * 0.02);
  EXPECT_NEAR(dx, v * 0.02, 0.1 * v * 0.02);
  // Prediction is capped.
  EXPECT_NEAR(hf.predict(f.time + 1.0).time - f.time, 0.05, 1e-12);
}
