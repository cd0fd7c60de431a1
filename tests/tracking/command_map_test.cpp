#include "tracking/command_map.hpp"

#include <gtest/gtest.h>

using namespace drape::tracking;

TEST(CommandMap, DefaultsAreHandsBusyAndMatchAsset) {
  const auto d = CommandMap::defaults();
  ASSERT_FALSE(d.bindings().empty());
  auto a = d.lookup(Trigger{"pinch", "gesture", 0, Hand::Right, true});
  ASSERT_TRUE(a);
  EXPECT_EQ(a->operation, "pinch");
  EXPECT_EQ(a->phase, Phase::Begin);
  a = d.lookup(Trigger{"pinch", "gesture", 0, Hand::Right, false});
  ASSERT_TRUE(a);
  EXPECT_EQ(a->phase, Phase::End);
  a = d.lookup(Trigger{"stop", "voice", 0, Hand::Right, true});
  ASSERT_TRUE(a);
  EXPECT_EQ(a->operation, "*");
  EXPECT_EQ(a->phase, Phase::End);
  // Every voice command is bound.
  for (const char* c : {"pinch", "release", "pin", "cut", "stop", "map", "move", "undo", "redo"})
    EXPECT_TRUE(d.lookup(Trigger{c, "voice", 0, Hand::Right, true})) << c;
  EXPECT_FALSE(d.lookup(Trigger{"hello", "voice", 0, Hand::Right, true}));
  std::string err;
  auto file = CommandMap::load(std::string(DRAPE_SOURCE_DIR) + "/assets/commands.json", &err);
  ASSERT_TRUE(file) << err;
  ASSERT_EQ(file->bindings().size(), d.bindings().size());
  for (size_t i = 0; i < d.bindings().size(); ++i) {
    EXPECT_EQ(file->bindings()[i].command, d.bindings()[i].command);
    EXPECT_EQ(file->bindings()[i].action.operation, d.bindings()[i].action.operation);
  }
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
  EXPECT_FALSE(CommandMap::load("/nonexistent/commands.json", &err));
}
