// What a session's checkpoints cost (sim/ops/checkpoint.hpp): the cloth of `--res` falling onto
// the dress form with the session's solver (XPBD, pieces at rest sleep, the finish in the tick),
// a checkpoint taken at the start of every `--every`-th of `--ticks` ticks. Prints, per
// checkpoint, the time it takes on the sim thread (the copy of the World with the solver's
// state: CheckpointTaker::take), its encoding and writing on the writer's thread, the file's
// size and the solver state's share, the time to load it and restore it into a fresh World (the
// start of a resume, the solver's cook included; the World's build from the header not) and
// whether that World, stepped to the end, reaches the live run's state hash; then the sim
// thread's cost spread over the ticks of the default interval (10 s = 900 ticks) against a
// tick's step. Writes out/bench/checkpoint.csv; exits 1 when a restored World ends elsewhere.
// `./drape bench checkpoint [--res N] [--ticks T] [--every K] [--dir DIR]`.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "sim/ops/checkpoint.hpp"
#include "sim/solvers/solver_factory.hpp"
#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

namespace {

constexpr double kDt = 1.0 / 90;
constexpr int kDefaultIntervalTicks = 900;  // XrAppOptions::checkpoint_every_s = 10 s

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

struct Session {
  World w;
  OperationController ops;
  explicit Session(int res) : w(testbed_world(make_form_drape(res, {}, true), solver())) {
    ops.install(w);
  }
  static std::unique_ptr<Solver> solver() {  // the session's (app::make_session_solver)
    SolverConfig cfg;
    cfg.freeze = true;
    cfg.finish_thread = false;
    return std::move(make_solver("xpbd", cfg).value());
  }
  double step_to(uint64_t tick) {  // returns the wall ms of the steps
    const auto t0 = Clock::now();
    for (; w.tick < tick; ++w.tick) {
      if (w.before_step) w.before_step(w, kDt);
      w.last_step = w.solver->step(w.cloth, w.scene, kDt);
      if (w.after_step) w.after_step(w, kDt);
    }
    return ms_since(t0);
  }
};

struct Row {
  uint64_t tick = 0;
  double take_ms = 0, write_ms = 0, restore_ms = 0;
  size_t bytes = 0, solver_bytes = 0;
  bool same = false;
};

}  // namespace

int main(int argc, char** argv) {
  int res = 128, ticks = 360, every = 90;
  std::string dir = "out/bench";
  CLI::App cli("A session checkpoint's cost on the sim thread, its size and its restore.",
               "checkpoint_bench");
  cli.add_option("--res", res, "cloth resolution (vertices per side)")->check(CLI::Range(4, 256));
  cli.add_option("--ticks", ticks, "ticks of session")->check(CLI::Range(2, 100000));
  cli.add_option("--every", every, "a checkpoint every K ticks")->check(CLI::Range(1, 100000));
  cli.add_option("--dir", dir, "where the checkpoint files and checkpoint.csv go");
  CLI11_PARSE(cli, argc, argv);
  std::filesystem::create_directories(dir);
  const std::string file = dir + "/checkpoint_bench.bin";

  Session live(res);
  CheckpointTaker taker;
  std::vector<Row> rows;
  std::vector<std::shared_ptr<WorldCheckpoint>> taken;
  double step_ms = 0;
  for (int at = every; at < ticks; at += every) {
    step_ms += live.step_to(static_cast<uint64_t>(at));
    Row r;
    r.tick = static_cast<uint64_t>(at);
    auto t0 = Clock::now();
    taken.push_back(taker.take(live.w, live.ops, {{"resolution", std::to_string(res)}}));
    r.take_ms = ms_since(t0);
    r.solver_bytes = taken.back()->solver_state.size();
    rows.push_back(r);
  }
  step_ms += live.step_to(static_cast<uint64_t>(ticks));
  const uint64_t want = state_hash(live.w.cloth);
  for (size_t k = 0; k < rows.size(); ++k) {
    Row& r = rows[k];
    auto t0 = Clock::now();
    if (std::string e = write_checkpoint_file(file, *taken[k]); !e.empty()) {
      std::fprintf(stderr, "checkpoint_bench: %s\n", e.c_str());
      return 1;
    }
    r.write_ms = ms_since(t0);
    r.bytes = std::filesystem::file_size(file);
    Session back(res);  // the World rebuilt from the header (the form): not counted
    t0 = Clock::now();
    WorldCheckpoint c;
    std::string e = load_checkpoint(file, c);
    if (e.empty()) e = restore_checkpoint(c, back.w, back.ops);
    r.restore_ms = ms_since(t0);
    if (!e.empty()) {
      std::fprintf(stderr, "checkpoint_bench: %s\n", e.c_str());
      return 1;
    }
    back.step_to(static_cast<uint64_t>(ticks));
    r.same = state_hash(back.w.cloth) == want;
  }
  std::filesystem::remove(file);

  const double tick_ms = step_ms / ticks;
  std::printf("%dx%d cloth, %d ticks, a step %.2f ms on average\n", res, res, ticks, tick_ms);
  std::printf("%8s %10s %10s %12s %12s %12s %6s\n", "tick", "take_ms", "write_ms", "file_bytes",
              "solver_bytes", "restore_ms", "same");
  double worst = 0;
  bool all_same = true;
  std::ofstream o(dir + "/checkpoint.csv");
  o << "res,tick,take_ms,write_ms,file_bytes,solver_state_bytes,restore_ms,same_final_hash,"
       "step_ms_mean\n";
  for (const Row& r : rows) {
    std::printf("%8llu %10.2f %10.2f %12zu %12zu %12.1f %6s\n",
                static_cast<unsigned long long>(r.tick), r.take_ms, r.write_ms, r.bytes,
                r.solver_bytes, r.restore_ms, r.same ? "yes" : "NO");
    o << res << "," << r.tick << "," << r.take_ms << "," << r.write_ms << "," << r.bytes << ","
      << r.solver_bytes << "," << r.restore_ms << "," << (r.same ? 1 : 0) << "," << tick_ms << "\n";
    worst = std::max(worst, r.take_ms);
    all_same = all_same && r.same;
  }
  std::printf(
      "sim thread: at most %.2f ms per checkpoint = %.4f ms per tick over the default "
      "%d-tick interval (%.3f %% of a %.2f ms step)\n",
      worst, worst / kDefaultIntervalTicks, kDefaultIntervalTicks,
      100.0 * worst / kDefaultIntervalTicks / tick_ms, tick_ms);
  std::printf("wrote %s/checkpoint.csv\n", dir.c_str());
  return o && all_same ? 0 : 1;
}
