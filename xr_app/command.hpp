// Sub-command registry of the `drape` executable: each cmd_*.cpp registers itself, so the
// CLI grows without one file every feature must edit.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace drape::app {

using CommandFn = std::function<int(int argc, char** argv)>;

struct Command {
  std::string name;
  std::string summary;
  CommandFn run;
};

std::vector<Command>& command_registry();

struct CommandRegistrar {
  CommandRegistrar(std::string name, std::string summary, CommandFn fn) {
    command_registry().push_back({std::move(name), std::move(summary), std::move(fn)});
  }
};

}  // namespace drape::app

// DRAPE_COMMAND(form, "dress form tools", fn): argv[0] is the sub-command name.
#define DRAPE_COMMAND(id, summary, fn) \
  static const ::drape::app::CommandRegistrar drape_command_##id(#id, summary, fn)
