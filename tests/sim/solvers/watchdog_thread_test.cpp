// The divergence watchdog's save and checks run in parts on the inner solver's pool
// (WatchdogSolver::by_parts): a bad vertex in any part is found, and the restore brings back
// every vertex of every part. (In the TSan build: "thread" in the name.)
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "sim/core/thread_pool.hpp"
#include "sim/solvers/watchdog.hpp"
#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

namespace {

// Spoils vertex `bad` on its first call (NaN position, or a speed of 1 km/s), moves every
// vertex otherwise; runs on a two-thread pool that the watchdog borrows.
struct Spoiler : Solver {
  int bad = 0, calls = 0;
  bool nan = true;
  ThreadPool threads{2};
  std::string name() const override { return "spoiler"; }
  ThreadPool* pool() override { return &threads; }
  StepStats step(Cloth& c, const SceneObjects&, double dt) override {
    for (size_t i = 0; i < c.state.x.size(); ++i) {
      c.state.v[i] = Vec3(0, -0.1, 0);
      c.state.x[i] += dt * c.state.v[i];
    }
    if (calls++ == 0) {
      if (nan)
        c.state.x[bad].x() = NAN;
      else
        c.state.v[bad] = Vec3(1000, 0, 0);
    }
    return {};
  }
};

}  // namespace

TEST(WatchdogThreads, ABadVertexInEitherPartIsRolledBack) {
  for (bool nan : {true, false})
    for (double where : {0.1, 0.9}) {
      Testbed sc = make_hanging_sheet(72);  // 5 184 vertices: two parts
      const int n = sc.cloth.num_vertices();
      ASSERT_GE(n, 4096);
      auto inner = std::make_unique<Spoiler>();
      inner->bad = static_cast<int>(where * n);
      inner->nan = nan;
      Spoiler& sp = *inner;
      WatchdogSolver w(std::move(inner));
      ASSERT_EQ(w.pool(), &sp.threads);
      const std::vector<Vec3> x0 = sc.cloth.state.x;
      StepStats st = w.step(sc.cloth, sc.objects, 1.0 / 90);
      EXPECT_TRUE(st.diverged) << "nan " << nan << " at " << where;
      EXPECT_EQ(st.retries, 1);
      EXPECT_TRUE(cloth_finite(sc.cloth));
      // The retry (two half steps from the restored state) moved every vertex by 1/90 s at
      // 0.1 m/s: the restore brought all of them back first.
      double worst = 0;
      for (int i = 0; i < n; ++i)
        worst = std::max(worst, std::abs((x0[i] - sc.cloth.state.x[i]).y() - 0.1 / 90));
      EXPECT_LT(worst, 1e-12);
      EXPECT_EQ(sp.calls, 3);
    }
}

TEST(WatchdogThreads, AHealthyStepPassesOnThePool) {
  Testbed sc = make_hanging_sheet(72);
  auto inner = std::make_unique<Spoiler>();
  inner->calls = 1;  // never spoils
  WatchdogSolver w(std::move(inner));
  for (int f = 0; f < 3; ++f) {
    StepStats st = w.step(sc.cloth, sc.objects, 1.0 / 90);
    EXPECT_FALSE(st.diverged);
    EXPECT_EQ(st.retries, 0);
  }
  EXPECT_EQ(w.total_rollbacks(), 0);
}
