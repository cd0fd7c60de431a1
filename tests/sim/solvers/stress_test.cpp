// Short versions of the stress cases: 0 failures for the default solver (XPBD + watchdog) and
// for VBD.
#include <gtest/gtest.h>

#include <cstdio>

#include "sim/solvers/solver_factory.hpp"
#include "sim/solvers/watchdog.hpp"
#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

TEST(Stress, DefaultSolverAndVbdHaveNoFailures) {
  for (const char* solver : {"default", "vbd"})
    for (const auto& name : stress_case_names()) {
      StressResult r = run_stress_case(name, solver, 1);
      std::printf("%-8s %-16s steps %4d failures %d rollbacks %d vertices %d %s\n", solver,
                  name.c_str(), r.steps, r.failures, r.rollbacks, r.vertices, r.note.c_str());
      EXPECT_GT(r.steps, 0) << solver << " " << name;
      EXPECT_EQ(r.failures, 0) << solver << " " << name;
    }
}

TEST(Stress, WatchdogRollsBackANonFiniteStep) {
  // A solver that poisons the state on its first call: the watchdog must restore and retry.
  struct Poison : Solver {
    int calls = 0;
    std::string name() const override { return "poison"; }
    StepStats step(Cloth& c, const SceneObjects&, double) override {
      if (calls++ == 0) c.state.x[0] = Vec3(NAN, NAN, NAN);
      return {};
    }
  };
  Testbed sc = make_hanging_sheet(6);
  const Vec3 x0 = sc.cloth.state.x[0];
  WatchdogSolver w(std::make_unique<Poison>());
  StepStats st = w.step(sc.cloth, sc.objects, 1.0 / 90);
  EXPECT_TRUE(st.diverged);
  EXPECT_GE(st.retries, 1);
  EXPECT_TRUE(cloth_finite(sc.cloth));
  EXPECT_EQ(sc.cloth.state.x[0], x0);
}

TEST(Stress, UnknownSolverAndCaseAreClearErrors) {
  auto s = make_solver("rk4");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("rk4"), std::string::npos);
  StressResult r = run_stress_case("nope", "vbd", 1);
  EXPECT_EQ(r.failures, 1);
  EXPECT_NE(r.note.find("nope"), std::string::npos);
}
