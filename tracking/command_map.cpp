#include "tracking/command_map.hpp"

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

namespace drape::tracking {

const char* phase_name(Phase p) {
  switch (p) {
    case Phase::Begin:
      return "begin";
    case Phase::End:
      return "end";
    case Phase::Toggle:
      return "toggle";
    case Phase::Once:
      return "once";
  }
  return "?";
}

namespace {
// Hands-busy defaults: pinch with the fingers or by voice, cut/stop/map/undo by voice.
constexpr const char* kDefaults = R"({
  "format": "drape-commands", "version": 1,
  "bindings": [
    {"source": "gesture", "command": "pinch", "edge": "begin", "operation": "pinch", "phase": "begin"},
    {"source": "gesture", "command": "pinch", "edge": "end", "operation": "pinch", "phase": "end"},
    {"source": "gesture", "command": "grab", "edge": "begin", "operation": "move", "phase": "begin"},
    {"source": "gesture", "command": "grab", "edge": "end", "operation": "move", "phase": "end"},
    {"source": "gesture", "command": "push", "edge": "begin", "operation": "pinch", "phase": "toggle"},
    {"source": "gesture", "command": "dwell", "edge": "begin", "operation": "release", "phase": "once"},
    {"source": "voice", "command": "pinch", "edge": "any", "operation": "pinch", "phase": "begin"},
    {"source": "voice", "command": "release", "edge": "any", "operation": "release", "phase": "once"},
    {"source": "voice", "command": "pin", "edge": "any", "operation": "pin", "phase": "once"},
    {"source": "voice", "command": "cut", "edge": "any", "operation": "cut", "phase": "begin"},
    {"source": "voice", "command": "stop", "edge": "any", "operation": "*", "phase": "end"},
    {"source": "voice", "command": "map", "edge": "any", "operation": "map", "phase": "once"},
    {"source": "voice", "command": "move", "edge": "any", "operation": "move", "phase": "toggle"},
    {"source": "voice", "command": "undo", "edge": "any", "operation": "undo", "phase": "once"},
    {"source": "voice", "command": "redo", "edge": "any", "operation": "redo", "phase": "once"},
    {"source": "controller", "command": "button.trigger", "edge": "begin", "operation": "pinch", "phase": "begin"},
    {"source": "controller", "command": "button.trigger", "edge": "end", "operation": "pinch", "phase": "end"},
    {"source": "controller", "command": "button.squeeze", "edge": "begin", "operation": "move", "phase": "begin"},
    {"source": "controller", "command": "button.squeeze", "edge": "end", "operation": "move", "phase": "end"},
    {"source": "controller", "command": "button.a", "edge": "begin", "operation": "cut", "phase": "toggle"},
    {"source": "controller", "command": "button.b", "edge": "begin", "operation": "undo", "phase": "once"}
  ]
})";
}  // namespace

CommandMap CommandMap::defaults() {
  auto m = parse(kDefaults, "built-in defaults", nullptr);
  return m ? *m : CommandMap{};
}

std::optional<CommandMap> CommandMap::load(const std::string& path, std::string* error) {
  std::ifstream f(path);
  if (!f) {
    if (error) *error = path + ": cannot open";
    return std::nullopt;
  }
  std::stringstream ss;
  ss << f.rdbuf();
  return parse(ss.str(), path, error);
}

std::optional<CommandMap> CommandMap::parse(const std::string& text, const std::string& name,
                                            std::string* error) {
  auto fail = [&](const std::string& m) -> std::optional<CommandMap> {
    if (error) *error = name + ": " + m;
    return std::nullopt;
  };
  auto j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return fail("not valid JSON");
  if (!j.contains("bindings") || !j["bindings"].is_array())
    return fail("missing array field 'bindings'");
  static const std::set<std::string> sources = {"gesture", "voice", "controller", "key", "*"};
  static const std::set<std::string> ops = {"move", "pinch", "release", "pin", "cut",
                                            "map",  "undo",  "redo",    "*"};
  CommandMap m;
  int i = 0;
  for (const auto& b : j["bindings"]) {
    const std::string where = "bindings[" + std::to_string(i++) + "]";
    if (!b.is_object()) return fail(where + " is not an object");
    for (const char* k : {"source", "command", "operation", "phase"})
      if (!b.contains(k) || !b[k].is_string())
        return fail(where + ": missing string field '" + k + "'");
    Binding x;
    x.source = b["source"];
    x.command = b["command"];
    x.edge = b.value("edge", "begin");
    x.action.operation = b["operation"];
    const std::string ph = b["phase"];
    if (!sources.count(x.source)) return fail(where + ": unknown source '" + x.source + "'");
    if (!ops.count(x.action.operation))
      return fail(where + ": unknown operation '" + x.action.operation + "'");
    if (x.edge != "begin" && x.edge != "end" && x.edge != "any")
      return fail(where + ": field 'edge' must be begin, end or any");
    if (ph == "begin")
      x.action.phase = Phase::Begin;
    else if (ph == "end")
      x.action.phase = Phase::End;
    else if (ph == "toggle")
      x.action.phase = Phase::Toggle;
    else if (ph == "once")
      x.action.phase = Phase::Once;
    else
      return fail(where + ": field 'phase' must be begin, end, toggle or once");
    m.b_.push_back(x);
  }
  return m;
}

std::optional<Action> CommandMap::lookup(const Trigger& t) const {
  for (const auto& b : b_) {
    if (b.source != "*" && b.source != t.source) continue;
    if (b.command != t.command) continue;
    if (b.edge == "begin" && !t.begin) continue;
    if (b.edge == "end" && t.begin) continue;
    return b.action;
  }
  return std::nullopt;
}

}  // namespace drape::tracking
