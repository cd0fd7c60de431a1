// The command map (tracking/command_map.cpp): the bundled assets/commands.json equals the
// built-in defaults, every binding of the plan (gestures per hand, controllers per profile,
// voice), hand- and profile-specific lookups, and bad input named by file and field.
#include "tracking/command_map.hpp"

#include <gtest/gtest.h>

#include <set>
#include <tuple>

using namespace drape::tracking;

namespace {
Trigger trig(const char* command, const char* source, Hand h, bool begin = true) {
  return Trigger{command, source, 0, h, begin};
}
std::string op_of(const CommandMap& m, const Trigger& t, const std::string& profile = "") {
  const auto a = m.lookup(t, profile);
  return a ? a->operation + " " + phase_name(a->phase) : "(none)";
}
}  // namespace

TEST(CommandMap, DefaultsEqualTheAssetFieldByField) {
  const auto d = CommandMap::defaults();
  std::string err;
  auto file = CommandMap::load(std::string(DRAPE_SOURCE_DIR) + "/assets/commands.json", &err);
  ASSERT_TRUE(file) << err;
  ASSERT_EQ(file->bindings().size(), d.bindings().size());
  for (size_t i = 0; i < d.bindings().size(); ++i) {
    const Binding &a = file->bindings()[i], &b = d.bindings()[i];
    EXPECT_EQ(std::tie(a.source, a.command, a.edge, a.hand, a.profile, a.label, a.phrase,
                       a.action.operation),
              std::tie(b.source, b.command, b.edge, b.hand, b.profile, b.label, b.phrase,
                       b.action.operation))
        << i;
    EXPECT_EQ(a.action.phase, b.action.phase) << i;
    EXPECT_FALSE(a.label.empty()) << "binding " << i << " has no label";
  }
}

TEST(CommandMap, EveryGestureBindingPerHand) {
  const auto m = CommandMap::defaults();
  struct Row {
    const char* gesture;
    const char* right;
    const char* left;
  };
  const Row rows[] = {
      {"pinch", "pinch begin", "pinch begin"},       {"grab", "move begin", "move begin"},
      {"flat", "smooth begin", "smooth begin"},      {"pinch_middle", "pin once", "release once"},
      {"pinch_ring", "cut toggle", "map once"},      {"pinch_little", "undo once", "redo once"},
      {"palm_up", "next once", "help begin"},        {"push", "stop once", "stop once"},
      {"palm_push", "pinch toggle", "pinch toggle"}, {"dwell", "release once", "release once"},
  };
  for (const Row& r : rows) {
    EXPECT_EQ(op_of(m, trig(r.gesture, "gesture", Hand::Right)), r.right) << r.gesture;
    EXPECT_EQ(op_of(m, trig(r.gesture, "gesture", Hand::Left)), r.left) << r.gesture;
  }
  // Held gestures end their operation; one-shot ones map nothing on release.
  EXPECT_EQ(op_of(m, trig("pinch", "gesture", Hand::Right, false)), "pinch end");
  EXPECT_EQ(op_of(m, trig("grab", "gesture", Hand::Left, false)), "move end");
  EXPECT_EQ(op_of(m, trig("flat", "gesture", Hand::Right, false)), "smooth end");
  EXPECT_EQ(op_of(m, trig("palm_up", "gesture", Hand::Left, false)), "help end");
  EXPECT_EQ(op_of(m, trig("palm_up", "gesture", Hand::Right, false)), "(none)");
  EXPECT_EQ(op_of(m, trig("pinch_middle", "gesture", Hand::Right, false)), "(none)");
  EXPECT_EQ(op_of(m, trig("open_palm", "gesture", Hand::Right)), "(none)");
}

TEST(CommandMap, EveryControllerBindingPerProfile) {
  const auto m = CommandMap::defaults();
  auto c = [&](const char* cmd, Hand h, const char* profile, bool begin = true) {
    return op_of(m, trig(cmd, "controller", h, begin), profile);
  };
  for (const char* p :
       {"oculus/touch", "valve/index", "htc/vive", "microsoft/motion", "khr/simple"}) {
    for (Hand h : {Hand::Left, Hand::Right}) {
      EXPECT_EQ(c("button.trigger", h, p), "pinch begin") << p;
      EXPECT_EQ(c("button.trigger", h, p, false), "pinch end") << p;
    }
  }
  for (const char* p : {"oculus/touch", "valve/index", "microsoft/motion"}) {
    for (Hand h : {Hand::Left, Hand::Right}) {
      EXPECT_EQ(c("button.squeeze", h, p), "move begin") << p;
      EXPECT_EQ(c("button.squeeze", h, p, false), "move end") << p;
      EXPECT_EQ(c("stick.up", h, p), "pin once") << p;
      EXPECT_EQ(c("stick.down", h, p), "release once") << p;
      EXPECT_EQ(c("stick.left", h, p), "next once") << p;
      EXPECT_EQ(c("stick.right", h, p), "redo once") << p;
      EXPECT_EQ(c("button.menu", h, p), "stop once") << p;
    }
    EXPECT_EQ(c("button.stick", Hand::Right, p), "smooth begin") << p;
    EXPECT_EQ(c("button.stick", Hand::Right, p, false), "smooth end") << p;
    EXPECT_EQ(c("button.stick", Hand::Left, p), "map once") << p;
    EXPECT_EQ(c("button.stick", Hand::Left, p, false), "(none)") << p;
  }
  EXPECT_EQ(c("button.a", Hand::Right, "oculus/touch"), "cut toggle");
  EXPECT_EQ(c("button.b", Hand::Left, "valve/index"), "undo once");
  // The menu held 1 s saves the session, on every profile with a menu button.
  for (const char* p : {"oculus/touch", "htc/vive", "microsoft/motion", "khr/simple"})
    EXPECT_EQ(c("button.menu_hold", Hand::Left, p), "save once") << p;
  // khr/simple: select = pinch, menu = undo (not stop).
  EXPECT_EQ(c("button.menu", Hand::Right, "khr/simple"), "undo once");
  // Vive: trackpad regions (on click) for what it lacks (a stick, A/B).
  EXPECT_EQ(c("trackpad.up", Hand::Right, "htc/vive"), "pin once");
  EXPECT_EQ(c("trackpad.down", Hand::Left, "htc/vive"), "release once");
  EXPECT_EQ(c("trackpad.center", Hand::Left, "htc/vive"), "cut toggle");
  EXPECT_EQ(c("trackpad.left", Hand::Right, "htc/vive"), "next once");
  EXPECT_EQ(c("trackpad.right", Hand::Right, "htc/vive"), "redo once");
  EXPECT_EQ(c("trackpad.left", Hand::Left, "htc/vive"), "undo once");
  EXPECT_EQ(c("trackpad.right", Hand::Left, "htc/vive"), "map once");
  EXPECT_EQ(c("button.menu", Hand::Left, "htc/vive"), "stop once");
  // Windows Mixed Reality: a stick, and trackpad up/down (click) for A/B.
  EXPECT_EQ(c("trackpad.up", Hand::Right, "microsoft/motion"), "cut toggle");
  EXPECT_EQ(c("trackpad.down", Hand::Left, "microsoft/motion"), "undo once");
  // The trackpad regions of one profile are nothing on another.
  EXPECT_EQ(c("trackpad.up", Hand::Right, "valve/index"), "(none)");
  EXPECT_EQ(c("trackpad.center", Hand::Right, "microsoft/motion"), "(none)");
  // The left controller rolled palm up shows the help while held.
  EXPECT_EQ(c("palm_up", Hand::Left, "oculus/touch"), "help begin");
  EXPECT_EQ(c("palm_up", Hand::Left, "oculus/touch", false), "help end");
  EXPECT_EQ(c("palm_up", Hand::Right, "oculus/touch"), "(none)");
}

TEST(CommandMap, EveryVoicePhraseAndEveryOperationIsBound) {
  const auto m = CommandMap::defaults();
  for (const char* c : {"pinch", "release", "pin", "cut", "stop", "map", "move", "undo", "redo"}) {
    const Binding* b = m.find(trig(c, "voice", Hand::Right));
    ASSERT_TRUE(b) << c;
    EXPECT_FALSE(b->phrase.empty()) << c;
  }
  EXPECT_EQ(op_of(m, trig("stop", "voice", Hand::Right)), "stop once");
  EXPECT_FALSE(m.lookup(trig("hello", "voice", Hand::Right)));
  std::set<std::string> ops;
  for (const auto& b : m.bindings()) ops.insert(b.action.operation);
  for (const char* o : {"move", "pinch", "release", "pin", "cut", "map", "undo", "redo", "stop",
                        "smooth", "next", "help"})
    EXPECT_TRUE(ops.count(o)) << o << " has no binding";
}

TEST(CommandMap, ProfileFamilyOfAnInteractionProfilePath) {
  EXPECT_EQ(profile_family("/interaction_profiles/oculus/touch_controller"), "oculus/touch");
  EXPECT_EQ(profile_family("/interaction_profiles/khr/simple_controller"), "khr/simple");
  EXPECT_EQ(profile_family("/user/hand/left"), "");
}

TEST(CommandMap, BadInputNamesField) {
  std::string err;
  EXPECT_FALSE(CommandMap::parse("{", "m.json", &err));
  EXPECT_NE(err.find("m.json"), std::string::npos);
  EXPECT_FALSE(CommandMap::parse(R"({"bindings": [{"source": "voice", "command": "cut"}]})",
                                 "m.json", &err));
  EXPECT_NE(err.find("operation"), std::string::npos);
  EXPECT_FALSE(CommandMap::parse(
      R"({"bindings": [{"source": "voice", "command": "cut", "operation": "fly", "phase": "once"}]})",
      "m.json", &err));
  EXPECT_NE(err.find("fly"), std::string::npos);
  EXPECT_FALSE(CommandMap::parse(
      R"({"bindings": [{"source": "gesture", "command": "x", "hand": "middle", "operation": "pin", "phase": "once"}]})",
      "m.json", &err));
  EXPECT_NE(err.find("bindings[0]: field 'hand'"), std::string::npos) << err;
  EXPECT_FALSE(CommandMap::parse(
      R"({"bindings": [{"source": "controller", "command": "x", "profile": "sony/move", "operation": "pin", "phase": "once"}]})",
      "m.json", &err));
  EXPECT_NE(err.find("sony/move"), std::string::npos) << err;
  EXPECT_FALSE(CommandMap::parse(
      R"({"bindings": [{"source": "voice", "command": "x", "label": 3, "operation": "pin", "phase": "once"}]})",
      "m.json", &err));
  EXPECT_NE(err.find("'label'"), std::string::npos) << err;
  EXPECT_FALSE(CommandMap::load("/nonexistent/commands.json", &err));
}
