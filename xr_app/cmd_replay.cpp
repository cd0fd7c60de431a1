// `drape replay DIR`: rebuilds the recorded session's starting World from its journal's header,
// runs the sim in lock step headless with each journaled input fed at its tick, and prints and
// writes (DIR/replay.json) the final state hash. See docs/sessions.md.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <string>

#include "xr_app/command.hpp"
#ifdef DRAPE_HAVE_XR_APP
#include "xr_app/app/session_record.hpp"
#endif

namespace {

int cmd_replay(int argc, char** argv) {
#ifndef DRAPE_HAVE_XR_APP
  (void)argc;
  (void)argv;
  std::fprintf(stderr, "drape replay: built without the OpenXR app (DRAPE_BUILD_XR=OFF)\n");
  return 2;
#else
  std::string dir, out;
  uint64_t until = 0;
  bool from_start = false;
  CLI::App cli(
      "Replays a recorded session (drape run/xr --record DIR) headless in lock step and prints "
      "the final state hash. Exit codes: 0 ok (and the hash equals the recorded one when the "
      "journal has its end), 1 a different hash or a failure, 2 usage or a bad journal.",
      "drape replay");
  cli.add_option("DIR", dir, "the session directory (holds journal.bin)")->required();
  cli.add_option("--until-tick", until, "stop after this many ticks (0: the journal's end)");
  cli.add_flag("--from-start", from_start,
               "replay the whole journal from the session's start (no checkpoint)");
  cli.add_option("--out", out, "write the result as JSON there (default: DIR/replay.json)");
  if (const int rc = drape::app::parse_command_line(cli, argc, argv); rc >= 0) return rc;
  const drape::app::ReplayResult r =
      drape::app::replay_journal(dir, until, nullptr, nullptr, nullptr, from_start);
  if (!r.error.empty()) {
    std::fprintf(stderr, "drape replay: %s\n", r.error.c_str());
    return 2;
  }
  if (!r.cut_message.empty()) std::fprintf(stderr, "drape replay: %s\n", r.cut_message.c_str());
  for (const auto& n : r.notes) std::fprintf(stderr, "drape replay: %s\n", n.c_str());
  if (r.checkpoint.empty())
    std::fprintf(stderr, "drape replay: from the session's start\n");
  else
    std::fprintf(stderr, "drape replay: from %s (tick %llu)\n", r.checkpoint.c_str(),
                 static_cast<unsigned long long>(r.start_tick));
  char hash[24], recorded[24];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(r.state_hash));
  std::snprintf(recorded, sizeof recorded, "%016llx",
                static_cast<unsigned long long>(r.recorded_hash));
  std::fprintf(stderr, "drape replay: %zu input records, %llu ticks in %.2f s\n", r.records,
               static_cast<unsigned long long>(r.ticks), r.seconds);
  std::printf("final state hash %s at tick %llu\n", hash, static_cast<unsigned long long>(r.ticks));
  const bool compared = r.has_end && until == 0;
  const bool same = !compared || (r.recorded_hash == r.state_hash && r.recorded_ticks == r.ticks);
  if (compared)
    std::fprintf(stderr, "drape replay: the recorded run ended with %s at tick %llu: %s\n",
                 recorded, static_cast<unsigned long long>(r.recorded_ticks),
                 same ? "the same" : "DIFFERENT");
  if (out.empty()) out = dir + "/replay.json";
  std::ofstream o(out);
  o << "{\"final_state_hash\": \"" << hash << "\", \"ticks\": " << r.ticks
    << ", \"records\": " << r.records << ", \"start_tick\": " << r.start_tick
    << ", \"seconds\": " << r.seconds << ", \"recorded_state_hash\": \""
    << (r.has_end ? recorded : "") << "\", \"same\": " << (same ? "true" : "false")
    << ", \"cut_off\": " << (r.cut_message.empty() ? "false" : "true") << "}\n";
  if (!o) {
    std::fprintf(stderr, "drape replay: --out %s: cannot write\n", out.c_str());
    return 1;
  }
  return same ? 0 : 1;
#endif
}

}  // namespace

DRAPE_COMMAND(replay, "replay a recorded session's journal headless (drape replay DIR)",
              cmd_replay);
