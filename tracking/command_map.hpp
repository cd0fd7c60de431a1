// Command map: which trigger begins or ends which operation (assets/commands.json). A binding
// may name a hand (left or right; both when absent) and, for controllers, an interaction
// profile family ("oculus/touch", "valve/index", "htc/vive", "microsoft/motion", "khr/simple")
// where that profile's component differs; its label names the input for people (help overlay,
// `drape run --help`).
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "tracking/types.hpp"

namespace drape::tracking {

enum class Phase { Begin, End, Toggle, Once };

struct Action {
  // move, pinch, release, pin, cut, map, smooth, next, undo, redo, help, "*" (stop: ends what
  // is in progress). "help" is the app's (the help shown while held), not the sim's.
  std::string operation;
  Phase phase = Phase::Once;
};

struct Binding {
  std::string source;   // gesture | voice | controller | key | "*"
  std::string command;  // e.g. pinch, button.trigger, stick.up, cut
  std::string edge;     // begin | end | any
  std::string hand;     // "" (both), left, right
  std::string profile;  // controllers: "" (every profile) or a profile family
  std::string label;    // the input for people: "thumb-middle pinch", "thumbstick up"
  std::string phrase;   // voice: the spoken phrase
  Action action;
};

class CommandMap {
 public:
  static CommandMap defaults();  // the built-in copy of assets/commands.json
  static std::optional<CommandMap> load(const std::string& path, std::string* error);
  static std::optional<CommandMap> parse(const std::string& json, const std::string& name,
                                         std::string* error);
  // The binding for a trigger of a hand; for controllers, one naming `profile` (the family of
  // the hand's current interaction profile) comes before one for every profile.
  std::optional<Action> lookup(const Trigger& t, const std::string& profile = "") const;
  const Binding* find(const Trigger& t, const std::string& profile = "") const;
  const std::vector<Binding>& bindings() const { return b_; }

 private:
  std::vector<Binding> b_;
};

const char* phase_name(Phase p);
// "/interaction_profiles/oculus/touch_controller" -> "oculus/touch" ("" when not a profile).
std::string profile_family(const std::string& interaction_profile_path);

}  // namespace drape::tracking
