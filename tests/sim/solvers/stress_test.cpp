// Short versions of the stress cases: 0 failures for the default solver (XPBD + watchdog) and
// for VBD.
#include <gtest/gtest.h>

#include <cstdio>

#include "sim/solvers/solver_factory.hpp"
#include "sim/solvers/watchdog.hpp"
#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

TEST(Stress, DefaultSolverAndVbdHaveNoFailures) {
  std::printf("%-8s %-16s %5s %8s %9s %8s %12s %12s %12s\n", "solver", "case", "steps", "failures",
              "rollbacks", "vertices", "max_ke_J/kg", "growth_J/kg", "penetr_mm");
  for (const char* solver : {"default", "vbd"})
    for (const auto& name : stress_case_names()) {
      StressResult r = run_stress_case(name, solver, 1);
      std::printf("%-8s %-16s %5d %8d %9d %8d %12.4f %12.5f %12.3f %s\n", solver, name.c_str(),
                  r.steps, r.failures, r.rollbacks, r.vertices, r.max_kinetic, r.energy_growth,
                  r.max_penetration * 1e3, r.note.c_str());
      EXPECT_GT(r.steps, 0) << solver << " " << name;
      EXPECT_EQ(r.failures, 0) << solver << " " << name;
      // A rollback is a step the watchdog had to restore and re-run: the cases stay clear of them.
      EXPECT_EQ(r.rollbacks, 0) << solver << " " << name;
      // Kinetic + gravitational energy between driven steps: it rises where strain comes back as
      // motion (the dragged corner let go) and where XPBD's settling lifts a sheet that its
      // under-resolved stiffness let sag (up to 0.8 J/kg, an 8 cm rise of the centre of mass);
      // an instability grows it without bound. The dragged cloth can give back at most about
      // what the drag put in (its peak kinetic energy).
      const double bound = name == "jerk" ? r.max_kinetic : 2.0;
      EXPECT_LT(r.energy_growth, bound) << solver << " " << name;
      // No vertex deeper than 5 mm below the surface of the floor, the form or the plate.
      EXPECT_LT(r.max_penetration, 5e-3) << solver << " " << name;
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
