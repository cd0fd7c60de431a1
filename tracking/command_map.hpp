// Command map: which trigger begins or ends which operation (assets/commands.json).
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "tracking/types.hpp"

namespace drape::tracking {

enum class Phase { Begin, End, Toggle, Once };

struct Action {
  std::string operation;  // move, pinch, release, pin, cut, map, undo, redo, "*" (current)
  Phase phase = Phase::Once;
};

struct Binding {
  std::string source;   // gesture | voice | controller | key | "*"
  std::string command;  // e.g. pinch, button.trigger, cut
  std::string edge;     // begin | end | any
  Action action;
};

class CommandMap {
 public:
  static CommandMap defaults();  // hands-busy defaults (same as assets/commands.json)
  static std::optional<CommandMap> load(const std::string& path, std::string* error);
  static std::optional<CommandMap> parse(const std::string& json, const std::string& name,
                                         std::string* error);
  std::optional<Action> lookup(const Trigger& t) const;
  const std::vector<Binding>& bindings() const { return b_; }

 private:
  std::vector<Binding> b_;
};

const char* phase_name(Phase p);

}  // namespace drape::tracking
