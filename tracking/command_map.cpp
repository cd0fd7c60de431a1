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
// The built-in copy of assets/commands.json (a test keeps the two equal).
constexpr const char* kDefaults = R"json({
  "format": "drape-commands",
  "version": 2,
  "bindings": [
    {"source": "gesture", "command": "pinch", "edge": "begin", "label": "thumb-index pinch (held)", "operation": "pinch", "phase": "begin"},
    {"source": "gesture", "command": "pinch", "edge": "end", "label": "thumb-index pinch (held)", "operation": "pinch", "phase": "end"},
    {"source": "gesture", "command": "grab", "edge": "begin", "label": "fist (held)", "operation": "move", "phase": "begin"},
    {"source": "gesture", "command": "grab", "edge": "end", "label": "fist (held)", "operation": "move", "phase": "end"},
    {"source": "gesture", "command": "flat", "edge": "begin", "label": "flat hand, fingers together, palm down (held)", "operation": "smooth", "phase": "begin"},
    {"source": "gesture", "command": "flat", "edge": "end", "label": "flat hand, fingers together, palm down (held)", "operation": "smooth", "phase": "end"},
    {"source": "gesture", "command": "pinch_middle", "edge": "begin", "hand": "right", "label": "thumb-middle pinch", "operation": "pin", "phase": "once"},
    {"source": "gesture", "command": "pinch_middle", "edge": "begin", "hand": "left", "label": "thumb-middle pinch", "operation": "release", "phase": "once"},
    {"source": "gesture", "command": "pinch_ring", "edge": "begin", "hand": "right", "label": "thumb-ring pinch", "operation": "cut", "phase": "toggle"},
    {"source": "gesture", "command": "pinch_ring", "edge": "begin", "hand": "left", "label": "thumb-ring pinch", "operation": "map", "phase": "once"},
    {"source": "gesture", "command": "pinch_little", "edge": "begin", "hand": "right", "label": "thumb-little pinch", "operation": "undo", "phase": "once"},
    {"source": "gesture", "command": "pinch_little", "edge": "begin", "hand": "left", "label": "thumb-little pinch", "operation": "redo", "phase": "once"},
    {"source": "gesture", "command": "palm_up", "edge": "begin", "hand": "right", "label": "palm up", "operation": "next", "phase": "once"},
    {"source": "gesture", "command": "palm_up", "edge": "begin", "hand": "left", "label": "palm up (held)", "operation": "help", "phase": "begin"},
    {"source": "gesture", "command": "palm_up", "edge": "end", "hand": "left", "label": "palm up (held)", "operation": "help", "phase": "end"},
    {"source": "gesture", "command": "push", "edge": "begin", "label": "push: open palm thrust forward", "operation": "stop", "phase": "once"},
    {"source": "gesture", "command": "point", "edge": "begin", "hand": "right", "label": "point: index finger out, the others curled", "operation": "pattern", "phase": "once"},
    {"source": "gesture", "command": "point", "edge": "begin", "hand": "left", "label": "point: index finger out, the others curled", "operation": "colours", "phase": "once"},
    {"source": "gesture", "command": "palm_push", "edge": "begin", "label": "palm push (palm-only trackers: Kinect, UDP)", "operation": "pinch", "phase": "toggle"},
    {"source": "gesture", "command": "dwell", "edge": "begin", "label": "hand still for 1 s (palm-only trackers)", "operation": "release", "phase": "once"},
    {"source": "gesture", "command": "both_push", "edge": "begin", "label": "both palms pushed at once (palm-only trackers)", "operation": "cut", "phase": "toggle"},
    {"source": "gesture", "command": "hands_together", "edge": "begin", "label": "palms together for 0.3 s (palm-only trackers)", "operation": "pin", "phase": "once"},
    {"source": "gesture", "command": "hands_apart", "edge": "begin", "label": "palms spread apart quickly (palm-only trackers)", "operation": "undo", "phase": "once"},
    {"source": "voice", "command": "pinch", "edge": "any", "label": "\"pinch cloth\"", "phrase": "pinch cloth", "operation": "pinch", "phase": "begin"},
    {"source": "voice", "command": "release", "edge": "any", "label": "\"release it\"", "phrase": "release it", "operation": "release", "phase": "once"},
    {"source": "voice", "command": "pin", "edge": "any", "label": "\"pin here\"", "phrase": "pin here", "operation": "pin", "phase": "once"},
    {"source": "voice", "command": "cut", "edge": "any", "label": "\"cut across\"", "phrase": "cut across", "operation": "cut", "phase": "begin"},
    {"source": "voice", "command": "stop", "edge": "any", "label": "\"stop now\"", "phrase": "stop now", "operation": "stop", "phase": "once"},
    {"source": "voice", "command": "map", "edge": "any", "label": "\"map pattern\"", "phrase": "map pattern", "operation": "map", "phase": "once"},
    {"source": "voice", "command": "move", "edge": "any", "label": "\"move cloth\"", "phrase": "move cloth", "operation": "move", "phase": "toggle"},
    {"source": "voice", "command": "undo", "edge": "any", "label": "\"undo change\"", "phrase": "undo change", "operation": "undo", "phase": "once"},
    {"source": "voice", "command": "redo", "edge": "any", "label": "\"redo change\"", "phrase": "redo change", "operation": "redo", "phase": "once"},
    {"source": "voice", "command": "smooth", "edge": "any", "label": "\"smooth out\"", "phrase": "smooth out", "operation": "smooth", "phase": "toggle"},
    {"source": "voice", "command": "next", "edge": "any", "label": "\"next layer\"", "phrase": "next layer", "operation": "next", "phase": "once"},
    {"source": "voice", "command": "help", "edge": "any", "label": "\"show help\"", "phrase": "show help", "operation": "help", "phase": "toggle"},
    {"source": "voice", "command": "pattern", "edge": "any", "label": "\"make pattern\"", "phrase": "make pattern", "operation": "pattern", "phase": "once"},
    {"source": "voice", "command": "colours", "edge": "any", "label": "\"strain map\"", "phrase": "strain map", "operation": "colours", "phase": "once"},
    {"source": "voice", "command": "save", "edge": "any", "label": "\"save session\"", "phrase": "save session", "operation": "save", "phase": "once"},
    {"source": "controller", "command": "button.trigger", "edge": "begin", "profile": "khr/simple", "label": "select (held)", "operation": "pinch", "phase": "begin"},
    {"source": "controller", "command": "button.trigger", "edge": "end", "profile": "khr/simple", "label": "select (held)", "operation": "pinch", "phase": "end"},
    {"source": "controller", "command": "button.trigger", "edge": "begin", "label": "trigger (held)", "operation": "pinch", "phase": "begin"},
    {"source": "controller", "command": "button.trigger", "edge": "end", "label": "trigger (held)", "operation": "pinch", "phase": "end"},
    {"source": "controller", "command": "button.squeeze", "edge": "begin", "label": "squeeze (held)", "operation": "move", "phase": "begin"},
    {"source": "controller", "command": "button.squeeze", "edge": "end", "label": "squeeze (held)", "operation": "move", "phase": "end"},
    {"source": "controller", "command": "button.a", "edge": "begin", "profile": "valve/index", "label": "A", "operation": "cut", "phase": "toggle"},
    {"source": "controller", "command": "button.a", "edge": "begin", "label": "A (right) / X (left)", "operation": "cut", "phase": "toggle"},
    {"source": "controller", "command": "button.b", "edge": "begin", "profile": "valve/index", "label": "B", "operation": "undo", "phase": "once"},
    {"source": "controller", "command": "button.b", "edge": "begin", "label": "B (right) / Y (left)", "operation": "undo", "phase": "once"},
    {"source": "controller", "command": "button.menu", "edge": "begin", "profile": "khr/simple", "label": "menu", "operation": "undo", "phase": "once"},
    {"source": "controller", "command": "button.menu", "edge": "begin", "label": "menu", "operation": "stop", "phase": "once"},
    {"source": "controller", "command": "button.menu_hold", "edge": "begin", "label": "menu held 1 s", "operation": "save", "phase": "once"},
    {"source": "controller", "command": "stick.up", "edge": "begin", "label": "thumbstick up", "operation": "pin", "phase": "once"},
    {"source": "controller", "command": "stick.down", "edge": "begin", "label": "thumbstick down", "operation": "release", "phase": "once"},
    {"source": "controller", "command": "stick.left", "edge": "begin", "label": "thumbstick left", "operation": "next", "phase": "once"},
    {"source": "controller", "command": "stick.right", "edge": "begin", "label": "thumbstick right", "operation": "redo", "phase": "once"},
    {"source": "controller", "command": "button.stick", "edge": "begin", "hand": "right", "label": "thumbstick click (held)", "operation": "smooth", "phase": "begin"},
    {"source": "controller", "command": "button.stick", "edge": "end", "hand": "right", "label": "thumbstick click (held)", "operation": "smooth", "phase": "end"},
    {"source": "controller", "command": "button.stick", "edge": "begin", "hand": "left", "label": "thumbstick click", "operation": "map", "phase": "once"},
    {"source": "controller", "command": "trackpad.up", "edge": "begin", "profile": "htc/vive", "label": "trackpad up (click)", "operation": "pin", "phase": "once"},
    {"source": "controller", "command": "trackpad.down", "edge": "begin", "profile": "htc/vive", "label": "trackpad down (click)", "operation": "release", "phase": "once"},
    {"source": "controller", "command": "trackpad.center", "edge": "begin", "profile": "htc/vive", "label": "trackpad centre (click)", "operation": "cut", "phase": "toggle"},
    {"source": "controller", "command": "trackpad.left", "edge": "begin", "hand": "right", "profile": "htc/vive", "label": "trackpad left (click)", "operation": "next", "phase": "once"},
    {"source": "controller", "command": "trackpad.right", "edge": "begin", "hand": "right", "profile": "htc/vive", "label": "trackpad right (click)", "operation": "redo", "phase": "once"},
    {"source": "controller", "command": "trackpad.left", "edge": "begin", "hand": "left", "profile": "htc/vive", "label": "trackpad left (click)", "operation": "undo", "phase": "once"},
    {"source": "controller", "command": "trackpad.right", "edge": "begin", "hand": "left", "profile": "htc/vive", "label": "trackpad right (click)", "operation": "map", "phase": "once"},
    {"source": "controller", "command": "trackpad.up", "edge": "begin", "profile": "microsoft/motion", "label": "trackpad up (click)", "operation": "cut", "phase": "toggle"},
    {"source": "controller", "command": "trackpad.down", "edge": "begin", "profile": "microsoft/motion", "label": "trackpad down (click)", "operation": "undo", "phase": "once"},
    {"source": "controller", "command": "palm_up", "edge": "begin", "hand": "left", "label": "controller rolled palm up (held)", "operation": "help", "phase": "begin"},
    {"source": "controller", "command": "palm_up", "edge": "end", "hand": "left", "label": "controller rolled palm up (held)", "operation": "help", "phase": "end"}
  ]
}
)json";
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

namespace {
const std::set<std::string> kSources = {"gesture", "voice", "controller", "key", "*"};
const std::set<std::string> kOperations = {"move",    "pinch",   "release", "pin",  "cut",  "map",
                                           "smooth",  "next",    "undo",    "redo", "stop", "help",
                                           "pattern", "colours", "save",    "*"};
const std::set<std::string> kProfiles = {"oculus/touch", "valve/index", "htc/vive",
                                         "microsoft/motion", "khr/simple"};

std::optional<Phase> parse_phase(const std::string& ph) {
  if (ph == "begin") return Phase::Begin;
  if (ph == "end") return Phase::End;
  if (ph == "toggle") return Phase::Toggle;
  if (ph == "once") return Phase::Once;
  return std::nullopt;
}

// One binding object; an empty string on success, else what is wrong (the field named).
std::string parse_binding(const nlohmann::json& b, Binding& x) {
  if (!b.is_object()) return "is not an object";
  for (const char* k : {"source", "command", "operation", "phase"})
    if (!b.contains(k) || !b[k].is_string()) return std::string("missing string field '") + k + "'";
  for (const char* k : {"edge", "hand", "profile", "label", "phrase"})
    if (b.contains(k) && !b[k].is_string()) return std::string("field '") + k + "' is not a string";
  x.source = b["source"];
  x.command = b["command"];
  x.edge = b.value("edge", "begin");
  x.hand = b.value("hand", "");
  x.profile = b.value("profile", "");
  x.label = b.value("label", "");
  x.phrase = b.value("phrase", "");
  x.action.operation = b["operation"];
  if (!kSources.count(x.source)) return "unknown source '" + x.source + "'";
  if (!kOperations.count(x.action.operation))
    return "unknown operation '" + x.action.operation + "'";
  if (x.edge != "begin" && x.edge != "end" && x.edge != "any")
    return "field 'edge' must be begin, end or any";
  if (!x.hand.empty() && x.hand != "left" && x.hand != "right")
    return "field 'hand' must be left or right (absent: both)";
  if (!x.profile.empty() && !kProfiles.count(x.profile))
    return "field 'profile': unknown interaction profile family '" + x.profile +
           "' (oculus/touch, valve/index, htc/vive, microsoft/motion, khr/simple)";
  const auto ph = parse_phase(b["phase"]);
  if (!ph) return "field 'phase' must be begin, end, toggle or once";
  x.action.phase = *ph;
  return {};
}
}  // namespace

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
  CommandMap m;
  int i = 0;
  for (const auto& b : j["bindings"]) {
    Binding x;
    const std::string why = parse_binding(b, x);
    if (!why.empty()) return fail("bindings[" + std::to_string(i) + "]: " + why);
    ++i;
    m.b_.push_back(x);
  }
  return m;
}

const Binding* CommandMap::find(const Trigger& t, const std::string& profile) const {
  const Binding* any_profile = nullptr;
  for (const auto& b : b_) {
    if (b.source != "*" && b.source != t.source) continue;
    if (b.command != t.command) continue;
    if (b.edge == "begin" && !t.begin) continue;
    if (b.edge == "end" && t.begin) continue;
    if (!b.hand.empty() && b.hand != hand_name(t.hand)) continue;
    if (!b.profile.empty() && b.profile != profile) continue;
    if (!b.profile.empty()) return &b;  // the hand's own profile first
    if (!any_profile) any_profile = &b;
  }
  return any_profile;
}

std::optional<Action> CommandMap::lookup(const Trigger& t, const std::string& profile) const {
  const Binding* b = find(t, profile);
  if (!b) return std::nullopt;
  return b->action;
}

std::string profile_family(const std::string& path) {
  const std::string prefix = "/interaction_profiles/";
  if (path.rfind(prefix, 0) != 0) return {};
  std::string rest = path.substr(prefix.size());
  const std::string suffix = "_controller";
  if (rest.size() > suffix.size() &&
      rest.compare(rest.size() - suffix.size(), suffix.size(), suffix) == 0)
    rest.resize(rest.size() - suffix.size());
  return rest;
}

}  // namespace drape::tracking
