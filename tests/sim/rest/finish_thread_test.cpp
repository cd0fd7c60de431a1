// The static finish on a thread of its own (sim/rest/finish_thread.hpp): the job's result is the
// finisher's, the caller's cloth is not touched while it runs, a cancelled job stops early and
// its result is not used, and the XPBD solver drops the result for a piece that woke
// meanwhile. Run in the TSan build (the file name carries "thread").
#include "sim/rest/finish_thread.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <thread>

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include "sim/ops/cut.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"
#include "tests/sim/solvers/solver_checks.hpp"

using namespace drape::sim;
using namespace drape::sim::test;

namespace {
SceneObjects nothing() {
  SceneObjects none;
  none.floor = false;
  return none;
}

// The XPBD tests' set-up: a 12 x 12 hanging sheet and a solver with sleeping whose first finish
// runs `cycles` cycles without converging (move tolerance 0), stepped until the sheet sleeps
// and its finish has started on the thread.
struct SleepingSheet {
  Testbed sc = make_hanging_sheet(12);
  std::unique_ptr<XpbdSolver> s;
  int frames = 0;  // until the finish started
  explicit SleepingSheet(int cycles) {
    XpbdOptions o;
    o.freeze = true;
    // The job at the caller's priority: these tests wait for it to end, and at nice 10 it got
    // ~10 % of a core beside the sanitizer build's other tests (one did not end in 74 s in CI).
    o.finish_nice = 0;
    o.finisher.cycles = cycles;
    o.finisher.move_tolerance = 0;
    s = std::make_unique<XpbdSolver>(o);
    for (; frames < 3000 && !s->finishing(); ++frames) s->step(sc.cloth, sc.objects, 1.0 / 90);
  }
  // Later jobs converge as usual, in at most `cycles` cycles.
  void later_jobs(int cycles) {
    s->options().finisher.cycles = cycles;
    s->options().finisher.move_tolerance = 1e-5;
  }
};
}  // namespace

TEST(FinishThread, AJobEndsInTheFinishersStateAndLeavesTheCallersClothAlone) {
  Cloth c = hanging_from_an_edge(17, 0.2);
  const std::vector<int> g = free_group(c);
  const SceneObjects none = nothing();
  FinisherOptions fo;
  fo.cycles = 8;
  Cloth direct = c;
  EquilibriumFinisher fin(fo);
  const FinisherStats want = fin.run(direct, none, g, EnergyOptions{}, nullptr);

  const uint64_t before = state_hash(c);
  FinishThread job;
  EXPECT_FALSE(job.busy());
  job.start(c, none, g, EnergyOptions{}, fo);
  EXPECT_TRUE(job.busy());
  EXPECT_THROW(job.start(c, none, g, EnergyOptions{}, fo), std::logic_error);
  const FinisherStats got = job.collect();
  EXPECT_FALSE(job.busy());
  EXPECT_TRUE(job.completed());
  EXPECT_EQ(state_hash(c), before) << "the caller's cloth";
  EXPECT_EQ(got.cycles, want.cycles);
  double rms = 0, mx = 0;
  position_error(job.cloth().state.x, direct.state.x, rms, mx);
  std::printf("job: %d cycles, moved up to %.3f mm, %.3g m from the finisher run here\n",
              got.cycles, got.max_move * 1e3, mx);
  EXPECT_EQ(mx, 0.0);
  EXPECT_GT(got.max_move, 1e-3);
#if defined(__linux__)
  // The job ran at a lower priority (nice + 10); this thread's own is unchanged.
  errno = 0;
  const int mine = getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)));
  ASSERT_EQ(errno, 0);
  std::printf("nice: this thread %d, the job %d\n", mine, job.job_nice());
  EXPECT_EQ(job.job_nice(), std::min(19, mine + 10));
#endif
}

TEST(FinishThread, ACancelledJobStopsEarlyAndIsNotCompleted) {
  Cloth c = hanging_from_an_edge(25, 0.2);
  FinisherOptions fo;
  fo.cycles = 100000;     // far more than it would run
  fo.move_tolerance = 0;  // never converged
  FinishThread job;
  job.start(c, nothing(), free_group(c), EnergyOptions{}, fo);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  job.cancel();
  const FinisherStats st = job.collect();
  std::printf("cancelled after %d cycles\n", st.cycles);
  EXPECT_TRUE(job.ended());
  EXPECT_FALSE(job.completed());
  EXPECT_LT(st.cycles, fo.cycles);
  // A new job may start once the last was collected.
  fo.cycles = 2;
  job.start(c, nothing(), free_group(c), EnergyOptions{}, fo);
  EXPECT_EQ(job.collect().cycles, 2);
  EXPECT_TRUE(job.completed());
}

TEST(FinishThread, AGroupOfTheWrongSizeIsRefused) {
  Cloth c = hanging_from_an_edge(5);
  FinishThread job;
  EXPECT_THROW(job.start(c, nothing(), std::vector<int>(3, 0), EnergyOptions{}, FinisherOptions{}),
               std::invalid_argument);
  EXPECT_FALSE(job.busy());
}

// The XPBD solver's use of it: a sheet falls asleep, its finish starts on the thread; the sheet
// is woken (its pinned corner dragged) before the job ends: the job's result is dropped and the
// sheet is not moved by it; once it sleeps again a new job finishes it.
TEST(FinishThread, XpbdDropsTheResultOfAPieceThatWokeAndFinishesItWhenItSleepsAgain) {
  SleepingSheet sh(100000);  // the first job runs until it is cancelled
  auto& sc = sh.sc;
  auto& s = *sh.s;
  ASSERT_TRUE(s.finishing()) << "asleep and finishing after " << sh.frames << " frames";
  const double moved = drag_sheet_corner(sc, s, 30);
  EXPECT_GT(moved, 1e-3);
  sh.later_jobs(10);
  int f = 0;
  for (; f < 30000 && (s.finish_count() == 0); ++f) {
    s.step(sc.cloth, sc.objects, 1.0 / 90);
    if (s.finishing()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::printf("dropped %d, finished %d pieces, %d cycles in all, %d frames after the drag\n",
              s.finish_dropped(), s.finish_count(), s.finish_cycles(), f);
  EXPECT_EQ(s.finish_dropped(), 1);
  EXPECT_EQ(s.finish_count(), 1);
  int free_vertices = 0;
  for (int i = 0; i < sc.cloth.num_vertices(); ++i) free_vertices += sc.cloth.is_free(i);
  EXPECT_EQ(s.frozen_count(), free_vertices) << "asleep again";
}

// A cut while the job runs: the cloth is re-cooked (another topology version), the job's
// positions belong to the old mesh and are dropped; the sheet's vertices keep the positions
// the cut left them at until the solver moves them.
TEST(FinishThread, XpbdDropsTheResultWhenTheClothIsCutMeanwhile) {
  SleepingSheet sh(100000);  // runs until it is cancelled
  auto& sc = sh.sc;
  auto& s = *sh.s;
  ASSERT_TRUE(s.finishing());
  const double w = sc.cloth.topo.material.back().x();
  ASSERT_TRUE(cut_along_material(sc.cloth, {Vec2(-0.01, 0.1), Vec2(w + 0.01, 0.1)}).ok);
  const uint64_t version = sc.cloth.topology_version;
  s.step(sc.cloth, sc.objects, 1.0 / 90);  // re-cooks, cancels the job
  for (int f = 0; f < 5000 && s.finishing(); ++f) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    s.step(sc.cloth, sc.objects, 1.0 / 90);
  }
  EXPECT_FALSE(s.finishing());
  EXPECT_EQ(sc.cloth.topology_version, version);
  EXPECT_EQ(s.finish_dropped(), 1);
  EXPECT_EQ(s.finish_count(), 0);
  for (const Vec3& x : sc.cloth.state.x) ASSERT_TRUE(x.allFinite());
}

// Something changes the sleeping sheet without waking it while the job runs: a free vertex is
// pinned where it lies (a pin does not move it, so the piece sleeps on). The job ends by itself
// but its result is dropped (it moved that vertex), the pinned vertex stays put, and a new job
// finishes the sheet with the vertex pinned.
TEST(FinishThread, XpbdDropsTheResultWhenAVertexWasPinnedMeanwhile) {
  SleepingSheet sh(300);  // long enough to pin the vertex before the job ends
  auto& sc = sh.sc;
  auto& s = *sh.s;
  ASSERT_TRUE(s.finishing());
  const int v = sc.cloth.num_vertices() / 2 + 3;
  ASSERT_TRUE(sc.cloth.is_free(v));
  sc.cloth.state.flags[v] |= kFlagPinned;
  const Vec3 at = sc.cloth.state.x[v];
  sh.later_jobs(5);
  int frames = 0;
  for (; frames < 60000 && s.finish_count() == 0; ++frames) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    s.step(sc.cloth, sc.objects, 1.0 / 90);
    EXPECT_EQ(sc.cloth.state.x[v], at) << "the pinned vertex, frame " << frames;
    if (sc.cloth.state.x[v] != at) break;
  }
  std::printf("dropped %d, finished %d, %d cycles in all, %d frames\n", s.finish_dropped(),
              s.finish_count(), s.finish_cycles(), frames);
  EXPECT_EQ(s.finish_dropped(), 1);
  EXPECT_EQ(s.finish_count(), 1);
  EXPECT_GE(s.finish_cycles(), 300) << "the first job ran to its end";
}
