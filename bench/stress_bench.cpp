// ./drape bench stress: the stress cases at benchmark size for every solver; writes
// out/bench/stress.csv (case,solver,steps,failures). Usage: stress_bench [--scale N] (default
// 3; 2 is the quicker run: 100 cuts on 48^2, 120 steps per case) [--case NAME] [--solver NAME].
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

int main(int argc, char** argv) {
  int scale = 3;
  std::string only_case, only_solver;  // a subset
  const std::vector<std::string> solvers{"vbd", "xpbd", "newton", "verlet"};
  CLI::App app{"The stress cases at benchmark size for every solver (out/bench/stress.csv)."};
  app.add_option("--scale", scale, "size of the cases (2: the quicker run, 100 cuts on 48^2)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  app.add_option("--case", only_case, "only this case")->check(CLI::IsMember(stress_case_names()));
  app.add_option("--solver", only_solver, "only this solver")->check(CLI::IsMember(solvers));
  CLI11_PARSE(app, argc, argv);
  std::filesystem::create_directories("out/bench");
  std::ofstream csv("out/bench/stress.csv");
  csv << "case,solver,steps,failures,rollbacks,vertices,max_kinetic_j_per_kg,energy_growth_j_per_"
         "kg,"
         "max_penetration_mm\n";
  std::printf("%-16s %-8s %6s %8s %9s %8s %12s %12s %10s\n", "case", "solver", "steps", "failures",
              "rollbacks", "vertices", "max_ke_J/kg", "growth_J/kg", "penetr_mm");
  for (const auto& c : stress_case_names())
    for (const std::string& s : solvers) {
      if ((!only_case.empty() && c != only_case) || (!only_solver.empty() && only_solver != s))
        continue;
      StressResult r = run_stress_case(c, s, scale);
      std::printf("%-16s %-8s %6d %8d %9d %8d %12.4f %12.5f %10.3f %s\n", c.c_str(), s.c_str(),
                  r.steps, r.failures, r.rollbacks, r.vertices, r.max_kinetic, r.energy_growth,
                  r.max_penetration * 1e3, r.note.c_str());
      std::fflush(stdout);
      csv << c << "," << s << "," << r.steps << "," << r.failures << "," << r.rollbacks << ","
          << r.vertices << "," << r.max_kinetic << "," << r.energy_growth << ","
          << r.max_penetration * 1e3 << std::endl;
    }
  std::printf("wrote out/bench/stress.csv\n");
  return 0;
}
