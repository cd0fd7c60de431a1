// The session journal's cost (sim/runtime/journal.hpp): one tick record per tick of a 90 Hz sim
// for `--minutes` of session, hands moving every tick and an operation every `--op-every` ticks
// (flushed at once; the rest at least every 100 ms), as the sim thread writes them. Prints the
// write time per tick (p50, p99, max, mean), the flushes, the bytes per minute and the time to
// load the journal back per minute of session; writes out/bench/journal.csv.
// `./drape bench journal [--minutes M] [--op-every K] [--dir DIR]`.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "sim/runtime/journal.hpp"

using namespace drape::sim;

namespace {
double pct(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())))];
}
}  // namespace

int main(int argc, char** argv) {
  double minutes = 2;
  int op_every = 30;
  std::string dir = "out/bench";
  CLI::App cli("The session journal's write cost per tick and load time per minute of session.",
               "journal_bench");
  cli.add_option("--minutes", minutes, "minutes of session at 90 ticks per second")
      ->check(CLI::Range(0.01, 600.0));
  cli.add_option("--op-every", op_every, "an operation every K ticks")
      ->check(CLI::Range(1, 100000));
  cli.add_option("--dir", dir, "where the journal and journal.csv go");
  CLI11_PARSE(cli, argc, argv);
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/journal_bench.bin";
  const int ticks = static_cast<int>(std::lround(minutes * 60 * 90));

  JournalHeader h;
  h.fields["resolution"] = "128";
  JournalWriter w;
  if (std::string e = w.create(path, h); !e.empty()) {
    std::fprintf(stderr, "journal_bench: %s\n", e.c_str());
    return 1;
  }
  std::vector<double> us;
  us.reserve(static_cast<size_t>(ticks));
  JournalTick t;
  t.hands[0].id = 0;
  t.hands[1].id = 1;
  t.hands[1].tracked = true;
  const auto wall0 = std::chrono::steady_clock::now();
  for (int k = 0; k < ticks; ++k) {
    t.tick = static_cast<uint64_t>(k);
    const double s = k / 90.0;
    t.hands[1].position = Vec3(0.1 * std::sin(s), 1.1 + 0.05 * std::cos(s), 0.2);
    t.hands[1].tip = t.hands[1].position;
    t.ops.clear();
    if (k % op_every == 0) t.ops.push_back({"pinch", 0, 1});
    const auto t0 = std::chrono::steady_clock::now();
    if (std::string e = w.write(t); !e.empty()) {
      std::fprintf(stderr, "journal_bench: %s\n", e.c_str());
      return 1;
    }
    us.push_back(
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    // Real time: a tick every 1/90 s would leave the 100 ms flush to the clock; here the ticks
    // run back to back, so the time-based flushes are fewer than in a live session.
  }
  const double write_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const uint64_t bytes = w.bytes(), flushes = w.flushes();
  w.close();
  const auto l0 = std::chrono::steady_clock::now();
  JournalContents c;
  if (std::string e = load_journal(path, c); !e.empty() || c.ticks.size() != us.size()) {
    std::fprintf(stderr, "journal_bench: load: %s (%zu records)\n", e.c_str(), c.ticks.size());
    return 1;
  }
  const double load_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - l0).count();
  double mean = 0;
  for (double v : us) mean += v;
  mean /= static_cast<double>(us.size());
  std::printf("%-10s %8s %8s %8s %8s %8s %10s %14s %14s\n", "minutes", "ticks", "p50_us", "p99_us",
              "max_us", "mean_us", "flushes", "bytes_per_min", "load_ms_per_min");
  std::printf("%-10.2f %8d %8.2f %8.2f %8.1f %8.2f %10llu %14.0f %14.2f\n", minutes, ticks,
              pct(us, 0.5), pct(us, 0.99), pct(us, 1.0), mean,
              static_cast<unsigned long long>(flushes), static_cast<double>(bytes) / minutes,
              1e3 * load_s / minutes);
  std::printf("(written back to back in %.2f s)\n", write_s);
  const std::string csv = dir + "/journal.csv";
  std::ofstream o(csv);
  o << "minutes,ticks,op_every,write_us_p50,write_us_p99,write_us_max,write_us_mean,flushes,"
       "bytes_per_minute,load_ms_per_minute\n"
    << minutes << "," << ticks << "," << op_every << "," << pct(us, 0.5) << "," << pct(us, 0.99)
    << "," << pct(us, 1.0) << "," << mean << "," << flushes << ","
    << static_cast<double>(bytes) / minutes << "," << 1e3 * load_s / minutes << "\n";
  std::filesystem::remove(path);
  std::printf("wrote %s\n", csv.c_str());
  return o ? 0 : 1;
}
