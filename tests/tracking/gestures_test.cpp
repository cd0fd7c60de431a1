// Gestures (tracking/gestures.cpp) on synthetic joint frames: the thumb's pinch with each
// finger, the fist, the flat hand palm down, the palm up and the push, each with its hysteresis
// and minimum duration; the resting open hand fires nothing and each gesture's neighbours do
// not cross-fire. Palm-only sources' dwell and push, and their two-hand triggers (together,
// apart, both pushed); controller button edges.
#include "tracking/gestures.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace drape::tracking;

namespace {
// The right hand in its palm frame (the mock runtime's skeleton): +x toward the little finger,
// +y out of the back of the hand, the fingers along -z.
const double kHand[kJointCount][3] = {
    {0, 0, 0},
    {0, 0, 0.045},
    {-0.025, -0.01, 0.03},
    {-0.045, -0.015, 0.005},
    {-0.055, -0.02, -0.025},
    {-0.06, -0.022, -0.045},
    {-0.02, 0, 0.035},
    {-0.022, 0, -0.03},
    {-0.023, 0, -0.07},
    {-0.024, 0, -0.095},
    {-0.024, 0, -0.115},
    {0, 0, 0.035},
    {0, 0, -0.035},
    {0, 0, -0.08},
    {0, 0, -0.108},
    {0, 0, -0.13},
    {0.018, 0, 0.035},
    {0.02, 0, -0.03},
    {0.021, 0, -0.07},
    {0.022, 0, -0.095},
    {0.022, 0, -0.115},
    {0.03, 0, 0.035},
    {0.038, 0, -0.02},
    {0.04, 0, -0.05},
    {0.041, 0, -0.068},
    {0.042, 0, -0.085},
};
constexpr int kTip[4] = {int(Joint::IndexTip), int(Joint::MiddleTip), int(Joint::RingTip),
                         int(Joint::LittleTip)};

enum class Shape { Relaxed, Pinch, Fist, Together, ThumbBetween, Point };

// Palm orientations: down (identity: the palm's normal -y), up, sideways, forward (-z).
const Quat kDown = Quat::Identity();
const Quat kUp(Eigen::AngleAxisd(M_PI, Vec3::UnitZ()));
const Quat kSideways(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()));
const Quat kForward(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()));

// A hand of `shape` (Pinch: the thumb tip `d` from finger `finger`'s tip) with its palm at `at`
// turned by `q`, at time t.
HandFrame hand(Shape shape, const Quat& q, double t, Hand side = Hand::Right, int finger = 0,
               double d = 0.005, Vec3 at = Vec3(0, 1.2, -0.3)) {
  Vec3 p[kJointCount];
  for (int j = 0; j < kJointCount; ++j) p[j] = Vec3(kHand[j][0], kHand[j][1], kHand[j][2]);
  const int thumb = int(Joint::ThumbTip);
  // The index's thumb on the thumb's side of its tip, the others' under theirs.
  if (shape == Shape::Pinch)
    p[thumb] = p[kTip[finger]] + (finger ? Vec3(0, -d, 0) : Vec3(-d, 0, 0));
  if (shape == Shape::ThumbBetween) p[thumb] = 0.5 * (p[kTip[0]] + p[kTip[1]]) + Vec3(0, -0.01, 0);
  for (int k = 0; k < 4; ++k) {
    Vec3& tip = p[kTip[k]];
    if (shape == Shape::Fist || (shape == Shape::Point && k > 0)) tip = Vec3(tip.x(), -0.03, -0.02);
    if (shape == Shape::Together) tip.x() *= 0.55;
  }
  HandFrame f;
  f.hand = side;
  f.time = t;
  f.tracked = true;
  f.confidence = 1;
  f.has_joints = true;
  for (int j = 0; j < kJointCount; ++j) {
    if (side == Hand::Left) p[j].x() = -p[j].x();
    f.joints[j] = at + q * p[j];
  }
  f.palm.position = f.joints[0];
  f.palm.orientation = q;
  return f;
}

int count(const std::vector<Trigger>& v, const std::string& c, bool begin) {
  int n = 0;
  for (auto& t : v) n += (t.command == c && t.begin == begin);
  return n;
}
std::string names(const std::vector<Trigger>& v) {
  std::string s;
  for (auto& t : v) s += t.command + (t.begin ? "+ " : "- ");
  return s;
}

// Feeds `frames` frames at 100 Hz of make(t) from time t.
template <class Make>
void feed(GestureRecognizer& g, double& t, int frames, Make make, std::vector<Trigger>& out) {
  for (int i = 0; i < frames; ++i, t += 0.01) g.update(make(t), out);
}
}  // namespace

TEST(Gestures, PinchHysteresisAndMinimumDuration) {
  GestureRecognizer g;  // enter < 2.5 cm, leave > 4 cm, 80 ms
  std::vector<Trigger> out;
  double t = 0;
  auto at = [&](double d, int frames) {
    feed(
        g, t, frames,
        [&](double tt) { return hand(Shape::Pinch, kSideways, tt, Hand::Right, 0, d); }, out);
  };
  at(0.06, 10);
  at(0.02, 5);  // 50 ms below: shorter than min duration -> nothing
  at(0.06, 10);
  EXPECT_EQ(count(out, "pinch", true), 0);
  at(0.02, 12);  // 120 ms -> begins
  EXPECT_EQ(count(out, "pinch", true), 1);
  at(0.035, 30);  // between thresholds: still pinching
  EXPECT_EQ(count(out, "pinch", false), 0);
  EXPECT_TRUE(g.pinching(Hand::Right));
  at(0.045, 12);  // above 4 cm for 120 ms -> ends
  EXPECT_EQ(count(out, "pinch", false), 1);
  // Chatter around 3 cm never re-triggers (hysteresis).
  for (int i = 0; i < 50; ++i) at(i % 2 ? 0.028 : 0.034, 1);
  EXPECT_EQ(count(out, "pinch", true), 1);
  EXPECT_EQ(names(out), "pinch+ pinch- ");
}

TEST(Gestures, EachFingerPinchFiresOnlyItselfWithEitherHand) {
  const char* name[4] = {"pinch", "pinch_middle", "pinch_ring", "pinch_little"};
  for (Hand side : {Hand::Right, Hand::Left}) {
    for (int k = 0; k < 4; ++k) {
      GestureRecognizer g;
      std::vector<Trigger> out;
      double t = 0;
      feed(
          g, t, 10, [&](double tt) { return hand(Shape::Relaxed, kSideways, tt, side); }, out);
      feed(
          g, t, 5, [&](double tt) { return hand(Shape::Pinch, kSideways, tt, side, k); }, out);
      EXPECT_TRUE(out.empty()) << name[k] << ": 50 ms is shorter than the minimum duration";
      feed(
          g, t, 20, [&](double tt) { return hand(Shape::Pinch, kSideways, tt, side, k); }, out);
      feed(
          g, t, 20, [&](double tt) { return hand(Shape::Relaxed, kSideways, tt, side); }, out);
      EXPECT_EQ(names(out), std::string(name[k]) + "+ " + name[k] + "- ") << hand_name(side);
      for (const auto& tr : out) EXPECT_EQ(tr.hand, side);
    }
  }
}

TEST(Gestures, ThumbBetweenTwoFingertipsPinchesNeither) {
  GestureRecognizer g;
  std::vector<Trigger> out;
  double t = 0;
  feed(
      g, t, 50, [&](double tt) { return hand(Shape::ThumbBetween, kSideways, tt); }, out);
  EXPECT_EQ(names(out), "");
}

TEST(Gestures, RestingOpenHandFiresNothing) {
  for (const Quat& q : {kSideways, kDown, kForward}) {
    GestureRecognizer g;
    std::vector<Trigger> out;
    double t = 0;
    // Two seconds of a relaxed hand with a slow drift and a 3 mm tremor.
    feed(
        g, t, 200,
        [&](double tt) {
          auto f = hand(Shape::Relaxed, q, tt);
          const Vec3 drift(0.02 * tt, 0.003 * std::sin(40 * tt), -0.01 * tt);
          for (auto& j : f.joints) j += drift;
          f.palm.position += drift;
          return f;
        },
        out);
    EXPECT_EQ(names(out), "") << q.coeffs().transpose();
  }
}

TEST(Gestures, FistIsGrabAndNoPinch) {
  GestureRecognizer g;
  std::vector<Trigger> out;
  double t = 0;
  feed(
      g, t, 20, [&](double tt) { return hand(Shape::Fist, kSideways, tt); }, out);
  feed(
      g, t, 20, [&](double tt) { return hand(Shape::Relaxed, kSideways, tt); }, out);
  EXPECT_EQ(names(out), "grab+ grab- ");
}

// The index finger out and the other three curled: "point", not a fist (the four tips' mean
// distance is a fist's), with either hand; a fist is still a grab, not a point.
TEST(Gestures, PointingIsPointAndNoGrab) {
  for (Hand side : {Hand::Right, Hand::Left}) {
    GestureRecognizer g;
    std::vector<Trigger> out;
    double t = 0;
    const HandFrame probe = hand(Shape::Point, kDown, 0, side);
    EXPECT_LT(hand_shape(probe).curl, GestureParams{}.grab_curl) << "a fist's mean curl";
    feed(
        g, t, 20, [&](double tt) { return hand(Shape::Point, kDown, tt, side); }, out);
    feed(
        g, t, 20, [&](double tt) { return hand(Shape::Relaxed, kDown, tt, side); }, out);
    feed(
        g, t, 20, [&](double tt) { return hand(Shape::Fist, kDown, tt, side); }, out);
    EXPECT_EQ(names(out), "point+ point- grab+ ");
    for (const auto& tr : out) EXPECT_EQ(tr.hand, side);
  }
}

TEST(Gestures, FlatHandPalmDownIsFlatAndItsNeighboursAreNot) {
  auto run = [](Shape shape, const Quat& q) {
    GestureRecognizer g;
    std::vector<Trigger> out;
    double t = 0;
    feed(
        g, t, 20, [&](double tt) { return hand(shape, q, tt); }, out);
    feed(
        g, t, 20, [&](double tt) { return hand(Shape::Relaxed, kSideways, tt); }, out);
    return names(out);
  };
  EXPECT_EQ(run(Shape::Together, kDown), "flat+ flat- ");
  EXPECT_EQ(run(Shape::Relaxed, kDown), "");                   // fingers apart: resting on a table
  EXPECT_EQ(run(Shape::Together, kSideways), "");              // a karate chop, not palm down
  EXPECT_EQ(run(Shape::Together, kUp), "palm_up+ palm_up- ");  // palm up, not flat
  EXPECT_EQ(run(Shape::Relaxed, kUp), "palm_up+ palm_up- ");
  EXPECT_EQ(run(Shape::Fist, kUp), "grab+ grab- ");  // a fist turned up is no palm up
  EXPECT_EQ(run(Shape::Pinch, kUp), "pinch+ pinch- ");
}

TEST(Gestures, PushIsTheOpenPalmThrustForward) {
  auto run = [](const Quat& q, Vec3 dir, double dist, Shape shape = Shape::Relaxed) {
    GestureRecognizer g;
    std::vector<Trigger> out;
    double t = 0;
    const Vec3 start(0, 1.2, -0.3);
    feed(
        g, t, 20, [&](double tt) { return hand(shape, q, tt, Hand::Right, 0, 0.005, start); }, out);
    // `dist` along `dir` in 0.2 s, then held there.
    for (int i = 1; i <= 40; ++i, t += 0.01) {
      const double s = std::min(1.0, i / 20.0);
      g.update(hand(shape, q, t, Hand::Right, 0, 0.005, start + dir * dist * s), out);
    }
    return names(out);
  };
  const Vec3 fwd(0, 0, -1);
  EXPECT_EQ(run(kForward, fwd, 0.2), "push+ ");
  EXPECT_EQ(run(kForward, fwd, 0.08), "");                     // too short
  EXPECT_EQ(run(kSideways, fwd, 0.2), "");                     // the palm does not lead
  EXPECT_EQ(run(kDown, Vec3(0, -1, 0), 0.2, Shape::Together),  // smoothing pressed down
            "flat+ ");
  EXPECT_EQ(run(kForward, fwd, 0.2, Shape::Fist), "grab+ ");  // a punch is no push
}

TEST(Gestures, LostHandEndsWhatIsHeld) {
  GestureRecognizer g;
  std::vector<Trigger> out;
  double t = 0;
  feed(
      g, t, 20, [&](double tt) { return hand(Shape::Pinch, kSideways, tt); }, out);
  feed(
      g, t, 20, [&](double tt) { return hand(Shape::Together, kDown, tt, Hand::Left); }, out);
  HandFrame lost;
  lost.time = t;
  g.update(lost, out);
  lost.hand = Hand::Left;
  g.update(lost, out);
  EXPECT_EQ(names(out), "pinch+ flat+ pinch- flat- ");
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
  EXPECT_EQ(count(out, "palm_push", true), 1);
  EXPECT_EQ(count(out, "dwell", true), 1);
}

// A source that delivers in bursts (a stalled frame loop polls several packets at once): gaps in
// the samples do not re-arm the dwell; only a move does.
TEST(Gestures, DwellFiresOnceWhenSamplesComeInBursts) {
  GestureRecognizer g;
  std::vector<Trigger> out;
  HandFrame f;
  f.tracked = true;
  f.confidence = 1;
  double t = 0;
  for (int i = 0; i < 180; ++i) {  // 3 s still, with a 0.3 s gap after 1.2 s
    t += i == 72 ? 0.3 : 1 / 60.0;
    f.time = t;
    f.palm.position = Vec3(0, 1, -1);
    g.update(f, out);
  }
  EXPECT_EQ(count(out, "dwell", true), 1);
  for (int i = 0; i < 30; ++i, t += 1 / 30.0) {  // 10 cm sideways in 1 s, then still again
    f.time = t;
    f.palm.position = Vec3(0.1 * std::min(1.0, i / 15.0), 1, -1);
    g.update(f, out);
  }
  for (int i = 0; i < 45; ++i, t += 1 / 30.0) {
    f.time = t;
    g.update(f, out);
  }
  EXPECT_EQ(count(out, "dwell", true), 2);
}

namespace {
// Both palms (palm-only) at 30 Hz for `secs` from t: left(u) and right(u), u in [0, 1].
template <class Left, class Right>
void two_palms(GestureRecognizer& g, double& t, double secs, Left left, Right right,
               std::vector<Trigger>& out) {
  const int n = static_cast<int>(std::lround(secs * 30));
  for (int i = 0; i < n; ++i, t += 1 / 30.0) {
    const double u = (i + 1.0) / n;
    HandFrame f;
    f.tracked = true;
    f.confidence = 1;
    f.time = t;
    f.hand = Hand::Left;
    f.palm.position = left(u);
    g.update(f, out);
    f.hand = Hand::Right;
    f.palm.position = right(u);
    g.update(f, out);
  }
}
Vec3 at(double x, double z = -0.6) {
  return Vec3(x, 1.2, z);
}
// Both palms held at x = -x_apart and +x_apart for `secs`.
void hold(GestureRecognizer& g, double& t, double secs, double x_apart, std::vector<Trigger>& out) {
  two_palms(
      g, t, secs, [=](double) { return at(-x_apart); }, [=](double) { return at(x_apart); }, out);
}
Vec3 mix(const Vec3& a, const Vec3& b, double u) {
  return a + (b - a) * u;
}
const Trigger* find(const std::vector<Trigger>& v, const std::string& c) {
  for (auto& t : v)
    if (t.command == c) return &t;
  return nullptr;
}
}  // namespace

// Palms brought within 10 cm and held 0.3 s: "hands_together" (the right hand's), held while
// together, ended when apart; a slow separation afterwards is no "hands_apart", and the palms
// held still together fire no dwell.
TEST(Gestures, HandsTogetherHeldAndEnded) {
  GestureRecognizer g;
  std::vector<Trigger> out;
  double t = 0;
  hold(g, t, 0.5, 0.3, out);  // apart, seen
  two_palms(
      g, t, 0.8, [](double u) { return mix(at(-0.3), at(-0.03), u); },
      [](double u) { return mix(at(0.3), at(0.03), u); }, out);   // brought together (6 cm)
  EXPECT_EQ(find(out, "hands_together"), nullptr) << names(out);  // not held long enough yet
  hold(g, t, 1.5, 0.03, out);
  ASSERT_EQ(count(out, "hands_together", true), 1) << names(out);
  EXPECT_EQ(find(out, "hands_together")->hand, Hand::Right);
  EXPECT_EQ(count(out, "dwell", true), 0) << names(out);
  EXPECT_EQ(count(out, "hands_together", false), 0);
  two_palms(
      g, t, 2.0, [](double u) { return mix(at(-0.03), at(-0.35), u); },
      [](double u) { return mix(at(0.03), at(0.35), u); }, out);  // slowly apart (70 cm in 2 s)
  EXPECT_EQ(count(out, "hands_together", false), 1) << names(out);
  EXPECT_EQ(count(out, "hands_apart", true), 0) << names(out);
  EXPECT_EQ(count(out, "palm_push", true), 0);
}

// A quick spread (from 20 cm to 70 cm in 0.3 s) is "hands_apart", once; the same spread too
// slowly (1.5 s), or with one hand only, is not.
TEST(Gestures, HandsApartIsAQuickSpread) {
  auto run = [](double secs) {
    GestureRecognizer g;
    std::vector<Trigger> out;
    double t = 0;
    hold(g, t, 0.5, 0.1, out);
    two_palms(
        g, t, secs, [](double u) { return mix(at(-0.1), at(-0.35), u); },
        [](double u) { return mix(at(0.1), at(0.35), u); }, out);
    hold(g, t, 0.5, 0.35, out);
    return out;
  };
  const auto quick = run(0.3);
  EXPECT_EQ(count(quick, "hands_apart", true), 1) << names(quick);
  EXPECT_EQ(find(quick, "hands_apart")->hand, Hand::Right);
  EXPECT_EQ(count(quick, "hands_together", true), 0) << names(quick);
  const auto slow = run(1.5);
  EXPECT_EQ(count(slow, "hands_apart", true), 0) << names(slow);
  // One hand moving 25 cm quickly: no partner, nothing.
  GestureRecognizer g;
  std::vector<Trigger> out;
  HandFrame f;
  f.tracked = true;
  f.confidence = 1;
  for (int i = 0; i < 30; ++i) {
    f.time = i / 30.0;
    f.palm.position = at(0.1 + 0.5 * std::min(1.0, i / 9.0));
    g.update(f, out);
  }
  EXPECT_EQ(find(out, "hands_apart"), nullptr) << names(out);
}

// Both palms pushed forward (20 cm along -z in 0.3 s) within 0.15 s of each other: one
// "both_push" (the right hand's) and no "palm_push"; one palm pushed while the other is seen: its
// "palm_push" after the pairing window; the other hand lost meanwhile: the push at once.
TEST(Gestures, BothPushedIsOneTriggerAndASinglePushStillWorks) {
  auto push = [](double u) { return std::min(1.0, u * 2.0) * -0.2; };  // in the first half
  {
    GestureRecognizer g;
    std::vector<Trigger> out;
    double t = 0;
    hold(g, t, 0.5, 0.25, out);
    two_palms(
        g, t, 0.6, [&](double u) { return at(-0.25, -0.6 + push(u)); },
        [&](double u) { return at(0.25, -0.6 + push(u)); }, out);
    EXPECT_EQ(count(out, "both_push", true), 1) << names(out);
    EXPECT_EQ(count(out, "palm_push", true), 0) << names(out);
    ASSERT_NE(find(out, "both_push"), nullptr);
    EXPECT_EQ(find(out, "both_push")->hand, Hand::Right);
  }
  {
    GestureRecognizer g;
    std::vector<Trigger> out;
    double t = 0;
    hold(g, t, 0.5, 0.25, out);
    two_palms(
        g, t, 0.6, [](double) { return at(-0.25); },
        [&](double u) { return at(0.25, -0.6 + push(u)); }, out);
    EXPECT_EQ(count(out, "palm_push", true), 1) << names(out);  // (and the left's dwell)
    EXPECT_EQ(find(out, "palm_push")->hand, Hand::Right);
    EXPECT_EQ(find(out, "both_push"), nullptr) << names(out);
  }
  {
    GestureRecognizer g;
    std::vector<Trigger> out;
    double t = 0;
    hold(g, t, 0.5, 0.25, out);
    HandFrame f;
    f.tracked = true;
    f.confidence = 1;
    f.hand = Hand::Right;
    for (int i = -10; i < 9; ++i, t += 1 / 30.0) {  // the left not seen; the right pushes
      f.time = t;
      f.palm.position = at(0.25, -0.6 - 0.2 * std::max(0, i + 1) / 9.0);
      g.update(f, out);
    }
    EXPECT_EQ(count(out, "palm_push", true), 1) << names(out);  // (and the rest's dwell)
    EXPECT_EQ(find(out, "both_push"), nullptr) << names(out);
  }
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
