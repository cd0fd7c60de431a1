// Entry point of the `drape` executable: dispatches to the registered sub-commands.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <exception>

#include "xr_app/command.hpp"

namespace drape::app {
std::vector<Command>& command_registry() {
  static std::vector<Command> registry;
  return registry;
}
}  // namespace drape::app

namespace {
void print_usage() {
  auto cmds = drape::app::command_registry();
  std::sort(cmds.begin(), cmds.end(), [](auto& a, auto& b) { return a.name < b.name; });
  std::fprintf(stderr,
               "usage: drape <command> [options]   (drape <command> --help)\n\ncommands:\n");
  for (const auto& c : cmds)
    std::fprintf(stderr, "  %-12s %s\n", c.name.c_str(), c.summary.c_str());
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    print_usage();
    return argc < 2 ? 2 : 0;
  }
  for (const auto& c : drape::app::command_registry()) {
    if (c.name == argv[1]) {
      try {
        return c.run(argc - 1, argv + 1);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "drape %s: error: %s\n", argv[1], e.what());
        return 1;
      }
    }
  }
  std::fprintf(stderr, "drape: unknown command '%s'\n\n", argv[1]);
  print_usage();
  return 2;
}
