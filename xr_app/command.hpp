// Sub-command registry of the `drape` executable: each cmd_*.cpp registers itself, so the
// CLI grows without one file every feature must edit.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace CLI {
class App;
class Validator;
}  // namespace CLI

namespace drape::app {

using CommandFn = std::function<int(int argc, char** argv)>;

struct Command {
  std::string name;
  std::string summary;
  CommandFn run;
};

std::vector<Command>& command_registry();

// Parses a sub-command's arguments (argv[0]: its name) with CLI11 the same way for every
// command: --help prints the help (every option, with its default) and returns 0; a bad
// argument prints "<app name>: <what is wrong>" and returns 2; otherwise returns -1 (go on).
// Name the CLI::App "drape <command>". Defined in main.cpp.
int parse_command_line(CLI::App& cli, int argc, char** argv);
// A CLI11 check: a number in (0, max].
CLI::Validator positive_up_to(double max);

struct CommandRegistrar {
  CommandRegistrar(std::string name, std::string summary, CommandFn fn) {
    command_registry().push_back({std::move(name), std::move(summary), std::move(fn)});
  }
};

}  // namespace drape::app

// DRAPE_COMMAND(form, "dress form tools", fn): argv[0] is the sub-command name.
#define DRAPE_COMMAND(id, summary, fn) \
  static const ::drape::app::CommandRegistrar drape_command_##id(#id, summary, fn)
