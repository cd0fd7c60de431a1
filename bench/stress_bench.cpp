// ./drape bench stress: the stress cases at benchmark size for every solver; writes
// out/bench/stress.csv (case,solver,steps,failures). Usage: stress_bench [--scale N] (default
// 3; 2 is the quicker run: 100 cuts on 48^2, 120 steps per case).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

int main(int argc, char** argv) {
  int scale = 3;
  std::string only_case, only_solver;  // --case NAME / --solver NAME: run a subset
  for (int i = 1; i + 1 < argc; ++i) {
    if (!std::strcmp(argv[i], "--scale")) scale = std::max(1, std::atoi(argv[i + 1]));
    if (!std::strcmp(argv[i], "--case")) only_case = argv[i + 1];
    if (!std::strcmp(argv[i], "--solver")) only_solver = argv[i + 1];
  }
  std::filesystem::create_directories("out/bench");
  std::ofstream csv("out/bench/stress.csv");
  csv << "case,solver,steps,failures\n";
  std::printf("%-16s %-8s %6s %8s %9s %8s\n", "case", "solver", "steps", "failures", "rollbacks",
              "vertices");
  for (const auto& c : stress_case_names())
    for (const char* s : {"vbd", "xpbd", "newton", "verlet"}) {
      if ((!only_case.empty() && c != only_case) || (!only_solver.empty() && only_solver != s))
        continue;
      StressResult r = run_stress_case(c, s, scale);
      std::printf("%-16s %-8s %6d %8d %9d %8d %s\n", c.c_str(), s, r.steps, r.failures, r.rollbacks,
                  r.vertices, r.note.c_str());
      std::fflush(stdout);
      csv << c << "," << s << "," << r.steps << "," << r.failures << std::endl;
    }
  std::printf("wrote out/bench/stress.csv\n");
  return 0;
}
