#include "tracking/gestures.hpp"

#include <gtest/gtest.h>

using namespace drape::tracking;

namespace {
HandFrame hand_with_pinch(double d, double t, double curl = 0.1) {
  HandFrame f;
  f.time = t;
  f.tracked = true;
  f.confidence = 1;
  f.has_joints = true;
  for (auto& j : f.joints) j = Vec3(0, 0, 0);
  f.joints[int(Joint::ThumbTip)] = Vec3(0, curl, 0);
  f.joints[int(Joint::IndexTip)] = Vec3(d, curl, 0);
  for (Joint tip : {Joint::MiddleTip, Joint::RingTip, Joint::LittleTip})
    f.joints[int(tip)] = Vec3(0, curl, 0);
  return f;
}
int count(const std::vector<Trigger>& v, const std::string& c, bool begin) {
  int n = 0;
  for (auto& t : v) n += (t.command == c && t.begin == begin);
  return n;
}
}  // namespace

TEST(Gestures, PinchHysteresisAndMinimumDuration) {
  GestureRecognizer g;  // enter < 2.5 cm, leave > 4 cm, 80 ms
  std::vector<Trigger> out;
  double t = 0;
  auto feed = [&](double d, int frames) {
    for (int i = 0; i < frames; ++i, t += 0.01) g.update(hand_with_pinch(d, t), out);
  };
  feed(0.06, 10);
  feed(0.02, 5);  // 50 ms below: shorter than min duration -> nothing
  feed(0.06, 10);
  EXPECT_EQ(count(out, "pinch", true), 0);
  feed(0.02, 12);  // 120 ms -> begins
  EXPECT_EQ(count(out, "pinch", true), 1);
  feed(0.035, 30);  // between thresholds: still pinching
  EXPECT_EQ(count(out, "pinch", false), 0);
  EXPECT_TRUE(g.pinching(Hand::Right));
  feed(0.045, 12);  // above 4 cm for 120 ms -> ends
  EXPECT_EQ(count(out, "pinch", false), 1);
  // Chatter around 3 cm never re-triggers (hysteresis).
  for (int i = 0; i < 50; ++i) feed(i % 2 ? 0.028 : 0.034, 1);
  EXPECT_EQ(count(out, "pinch", true), 1);
}

TEST(Gestures, GrabAndOpenPalm) {
  GestureRecognizer g;
  std::vector<Trigger> out;
  double t = 0;
  for (int i = 0; i < 20; ++i, t += 0.01) g.update(hand_with_pinch(0.06, t, 0.03), out);
  EXPECT_EQ(count(out, "grab", true), 1);
  for (int i = 0; i < 20; ++i, t += 0.01) g.update(hand_with_pinch(0.06, t, 0.18), out);
  EXPECT_EQ(count(out, "grab", false), 1);
  EXPECT_EQ(count(out, "open_palm", true), 1);
}

TEST(Gestures, LostHandEndsPinch) {
  GestureRecognizer g;
  std::vector<Trigger> out;
  double t = 0;
  for (int i = 0; i < 20; ++i, t += 0.01) g.update(hand_with_pinch(0.01, t), out);
  HandFrame lost;
  lost.time = t;
  g.update(lost, out);
  EXPECT_EQ(count(out, "pinch", false), 1);
}

TEST(Gestures, DwellAndPushForPalmOnlySources) {
  GestureRecognizer g;
  std::vector<Trigger> out;
  HandFrame f;
  f.tracked = true;
  f.confidence = 1;
  double t = 0;
  for (int i = 0; i < 45; ++i, t += 1 / 30.0) {  // 1.5 s still (1 mm wobble)
    f.time = t;
    f.palm.position = Vec3(0.001 * (i % 2), 1, -1);
    g.update(f, out);
  }
  EXPECT_EQ(count(out, "dwell", true), 1);
  for (int i = 0; i < 9; ++i, t += 1 / 30.0) {  // 20 cm forward (-z) in 0.3 s
    f.time = t;
    f.palm.position = Vec3(0, 1, -1 - 0.2 * (i + 1) / 9.0);
    g.update(f, out);
  }
  EXPECT_EQ(count(out, "push", true), 1);
  EXPECT_EQ(count(out, "dwell", true), 1);
}

TEST(Gestures, ControllerButtonsGiveEdges) {
  ButtonMapper m;
  std::vector<Trigger> out;
  m.update(Hand::Left, "a", false, 0.0, out);
  m.update(Hand::Left, "a", true, 0.1, out);
  m.update(Hand::Left, "a", true, 0.2, out);
  m.update(Hand::Left, "a", false, 0.3, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].command, "button.a");
  EXPECT_TRUE(out[0].begin);
  EXPECT_FALSE(out[1].begin);
  EXPECT_EQ(out[1].hand, Hand::Left);
}
