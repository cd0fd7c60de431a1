// The XR adapter's controller triggers (tracking/xr_source.cpp): buttons' edges, the
// thumbstick's directions with hysteresis, the trackpad's region taken at its click, the
// controller rolled palm up, the menu button held 1 s.
#include <gtest/gtest.h>

#include <cmath>

#include "tracking/hand_source.hpp"

using namespace drape::tracking;

namespace {
std::string names(const std::vector<Trigger>& v) {
  std::string s;
  for (auto& t : v) s += t.command + (t.begin ? "+ " : "- ");
  return s;
}
XrControllerInput held(double t) {
  XrControllerInput c;
  c.active = true;
  c.time = t;
  c.grip.position = Vec3(0.1, 1.0, -0.3);
  return c;
}
}  // namespace

TEST(XrSource, ButtonsGiveEdgesWhileTheControllerIsActive) {
  XrHandSource xr;
  auto c = held(0);
  c.menu = c.stick_click = true;
  xr.feed_controller(Hand::Left, c);
  c.menu = false;
  xr.feed_controller(Hand::Left, c);
  c.active = false;  // a lost controller releases what it held
  xr.feed_controller(Hand::Left, c);
  const auto t = xr.take_triggers();
  // The menu is a tap: its begin and end come when it is let go.
  EXPECT_EQ(names(t), "button.stick+ button.menu+ button.menu- button.stick- ");
  for (const auto& tr : t) EXPECT_EQ(tr.hand, Hand::Left);
}

// The menu let go before 1 s: a tap ("button.menu" when let go); held 1 s: "button.menu_hold"
// alone, ended when let go (no tap, so a save never also stops or undoes); a controller lost
// with the button down: nothing.
TEST(XrSource, MenuHeldOneSecondIsItsOwnTrigger) {
  XrHandSource xr;
  auto feed = [&](double t, bool menu) {
    auto c = held(t);
    c.menu = menu;
    xr.feed_controller(Hand::Left, c);
  };
  for (double t = 0; t < 0.95; t += 0.1) feed(t, true);  // 0.9 s: not yet
  feed(0.95, false);
  EXPECT_EQ(names(xr.take_triggers()), "button.menu+ button.menu- ");
  for (double t = 1.0; t < 2.25; t += 0.1) feed(t, true);  // held 1.2 s
  feed(2.3, false);
  EXPECT_EQ(names(xr.take_triggers()), "button.menu_hold+ button.menu_hold- ");
  for (double t = 2.4; t < 2.65; t += 0.1) feed(t, true);
  auto lost = held(2.7);
  lost.active = false;
  xr.feed_controller(Hand::Left, lost);
  EXPECT_EQ(names(xr.take_triggers()), "");
}

TEST(XrSource, StickDirectionsWithHysteresis) {
  XrHandSource xr;
  double t = 0;
  auto stick = [&](double x, double y) {
    auto c = held(t += 0.011);
    c.stick_x = x;
    c.stick_y = y;
    xr.feed_controller(Hand::Right, c);
  };
  stick(0, 0.5);  // not far enough
  EXPECT_EQ(names(xr.take_triggers()), "");
  stick(0.1, 0.8);
  stick(0.2, 0.5);  // still up (above the leave threshold)
  stick(0.3, 0.75);
  EXPECT_EQ(names(xr.take_triggers()), "stick.up+ ");
  stick(0, 0.3);
  EXPECT_EQ(names(xr.take_triggers()), "stick.up- ");
  stick(0, -0.9);
  stick(0, 0);
  stick(-0.9, 0.1);
  stick(0, 0);
  stick(0.95, -0.2);
  stick(0, 0);
  EXPECT_EQ(names(xr.take_triggers()),
            "stick.down+ stick.down- stick.left+ stick.left- stick.right+ stick.right- ");
  // Chatter about the entry threshold fires once.
  for (int i = 0; i < 20; ++i) stick(0, i % 2 ? 0.72 : 0.6);
  EXPECT_EQ(names(xr.take_triggers()), "stick.up+ ");
}

TEST(XrSource, TrackpadRegionIsTakenAtTheClick) {
  XrHandSource xr;
  double t = 0;
  auto pad = [&](double x, double y, bool click) {
    auto c = held(t += 0.011);
    c.pad_x = x;
    c.pad_y = y;
    c.pad_click = click;
    xr.feed_controller(Hand::Left, c);
  };
  pad(0, 0.8, false);  // touching without a click: nothing
  EXPECT_EQ(names(xr.take_triggers()), "");
  pad(0, 0.8, true);
  pad(0.9, 0, true);  // the thumb slides while clicked: still up
  pad(0.9, 0, false);
  pad(0.1, -0.1, true);
  pad(0.1, -0.1, false);
  pad(-0.7, 0.2, true);
  pad(-0.7, 0.2, false);
  pad(0.1, -0.8, true);
  pad(0.1, -0.8, false);
  EXPECT_EQ(names(xr.take_triggers()),
            "trackpad.up+ trackpad.up- trackpad.center+ trackpad.center- trackpad.left+ "
            "trackpad.left- trackpad.down+ trackpad.down- ");
}

TEST(XrSource, ControllerRolledPalmUp) {
  for (Hand h : {Hand::Left, Hand::Right}) {
    XrHandSource xr;
    // The grip's +x is the left palm's normal, -x the right one's: roll so it points up.
    const double s = h == Hand::Left ? 1 : -1;
    auto roll = [&](double deg, double t) {
      auto c = held(t);
      c.grip.orientation = Quat(Eigen::AngleAxisd(s * deg * M_PI / 180, Vec3::UnitZ()));
      xr.feed_controller(h, c);
    };
    roll(0, 0);
    roll(30, 0.1);  // a held controller's tilt: nothing
    EXPECT_EQ(names(xr.take_triggers()), "") << hand_name(h);
    roll(80, 0.2);
    roll(40, 0.3);  // between the thresholds (sin 40° = 0.64): still palm up
    EXPECT_EQ(names(xr.take_triggers()), "palm_up+ ") << hand_name(h);
    roll(20, 0.4);
    EXPECT_EQ(names(xr.take_triggers()), "palm_up- ") << hand_name(h);
  }
}
