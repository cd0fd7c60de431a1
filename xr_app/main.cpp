// Entry point of the `drape` executable: the global options (CLI11), then the registered
// sub-command named by the first positional argument, which parses the rest itself.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "sim/solvers/xpbd/xpbd_kernels.hpp"
#include "xr_app/command.hpp"
#include "xr_app/paths.hpp"

namespace drape::app {
std::vector<Command>& command_registry() {
  static std::vector<Command> registry;
  return registry;
}

int parse_command_line(CLI::App& cli, int argc, char** argv) {
  try {
    cli.parse(argc, argv);
    return -1;
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) {  // --help
      std::printf("%s", cli.help().c_str());
      return 0;
    }
    std::fprintf(stderr, "%s: %s\n(%s --help lists the options)\n", cli.get_name().c_str(),
                 e.what(), cli.get_name().c_str());
    return 2;
  }
}

CLI::Validator positive_up_to(double max) {
  char range[64];
  std::snprintf(range, sizeof range, "in (0, %g]", max);
  return CLI::Validator(
      [max, text = std::string(range)](std::string& s) -> std::string {
        double v = 0;
        char tail = 0;
        if (std::sscanf(s.c_str(), "%lf%c", &v, &tail) == 1 && v > 0 && v <= max) return {};
        return "expected a number " + text + ", got '" + s + "'";
      },
      std::string("NUMBER ") + range);
}
}  // namespace drape::app

namespace {
std::string command_list() {
  auto cmds = drape::app::command_registry();
  std::sort(cmds.begin(), cmds.end(), [](auto& a, auto& b) { return a.name < b.name; });
  std::string s = "Commands (drape <command> --help lists a command's options):\n";
  for (const auto& c : cmds) {
    char line[256];
    std::snprintf(line, sizeof line, "  %-12s %s\n", c.name.c_str(), c.summary.c_str());
    s += line;
  }
  return s;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"drape [OPTIONS] COMMAND [ARGS...]: immersive virtual draping", "drape"};
  // The first positional argument names the command; it and everything after it go to the
  // command (so `drape form --help` is the form command's help).
  cli.prefix_command();
  cli.footer(command_list());
  std::string assets, simd;
  cli.add_option("--assets", assets,
                 "assets directory (fabrics, forms, designs, scenarios); default "
                 "<executable dir>/../share/drape/assets")
      ->type_name("DIR");
  cli.add_option("--simd", simd,
                 "widest SIMD build of the XPBD kernels: none (portable), avx2, widest (the "
                 "default: the widest this CPU runs)")
      ->type_name("LEVEL")
      ->check(CLI::IsMember({"none", "avx2", "widest"}));
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) {
      std::printf("%s", cli.help().c_str());
      return 0;
    }
    std::fprintf(stderr, "drape: %s\n\n%s", e.what(), cli.help().c_str());
    return 2;
  }
  std::vector<std::string> rest = cli.remaining();
  if (rest.empty() || rest[0] == "help") {
    std::fprintf(rest.empty() ? stderr : stdout, "%s", cli.help().c_str());
    return rest.empty() ? 2 : 0;
  }
  if (!assets.empty()) drape::app::set_assets_dir(assets);
  if (!simd.empty()) drape::sim::xpbd::limit_simd(*drape::sim::xpbd::parse_simd_limit(simd));
  std::vector<char*> args;
  for (std::string& a : rest) args.push_back(a.data());
  args.push_back(nullptr);
  for (const auto& c : drape::app::command_registry()) {
    if (c.name == rest[0]) {
      try {
        return c.run(static_cast<int>(rest.size()), args.data());
      } catch (const std::exception& e) {
        std::fprintf(stderr, "drape %s: error: %s\n", rest[0].c_str(), e.what());
        return 1;
      }
    }
  }
  std::fprintf(stderr, "drape: unknown command '%s'\n\n%s", rest[0].c_str(), cli.help().c_str());
  return 2;
}
