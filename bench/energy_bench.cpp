// ./drape bench energy: cost of the VBD hot path ClothEnergy::vertex_force_hessian per vertex
// update (ns, CPU time of one thread), per bending model, on a res x res muslin sheet in a
// curved, slightly rumpled state. Writes out/bench/energy.csv (model,res,ns_per_vertex,
// ns_bending_per_vertex). Usage: energy_bench [--res N] [--sweeps K].
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "sim/energy/energy.hpp"

using namespace drape::sim;

namespace {

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// ns per vertex_force_hessian call over `sweeps` passes of every vertex (best of 3 rounds).
double time_vertex_blocks(const ClothEnergy& e, const Cloth& c, int sweeps, double& sink) {
  const int n = c.num_vertices();
  double best = 1e300;
  for (int round = 0; round < 3; ++round) {
    const double t0 = cpu_seconds();
    for (int s = 0; s < sweeps; ++s)
      for (int i = 0; i < n; ++i) {
        Vec3 f;
        Mat3 H;
        e.vertex_force_hessian(i, c.state.x, c.state.mass[i], f, H);
        sink += f.x() + H(0, 0);
      }
    best = std::min(best, (cpu_seconds() - t0) / (static_cast<double>(sweeps) * n));
  }
  return best * 1e9;
}

}  // namespace

int main(int argc, char** argv) {
  int res = 128, sweeps = 5;
  CLI::App app{
      "CPU time of vertex_force_hessian per vertex update on a bent sheet, per bending model "
      "(out/bench/energy.csv)."};
  app.add_option("--res", res, "sheet resolution")
      ->check(CLI::Range(4, 4096))
      ->capture_default_str();
  app.add_option("--sweeps", sweeps, "sweeps over the vertices per timing")
      ->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  PanelSpec p;
  p.width = p.height = 0.5;
  p.nx = p.ny = res;
  Cloth c = make_panel(p, FabricParams{});
  // Rolled onto a cylinder of radius 0.3 m along the warp plus 0.2 mm noise: every hinge bent.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2e-4, 2e-4);
  for (int i = 0; i < c.num_vertices(); ++i) {
    const Vec2 m = c.topo.material[i];
    const double R = 0.3;
    c.state.x[i] = Vec3(m.x(), R * std::sin(m.y() / R), R * (1 - std::cos(m.y() / R))) +
                   Vec3(u(rng), u(rng), u(rng));
  }
  c.relump_masses();
  std::filesystem::create_directories("out/bench");
  std::ofstream csv("out/bench/energy.csv");
  csv << "model,res,ns_per_vertex,ns_bending_per_vertex\n";
  double sink = 0;
  EnergyOptions none;
  none.bending = false;
  ClothEnergy e0;
  e0.build(c, none);
  const double base = time_vertex_blocks(e0, c, sweeps, sink);
  std::printf("vertex_force_hessian on a %dx%d sheet, %d sweeps, CPU ns per vertex update\n", res,
              res, sweeps);
  std::printf("%-10s %10s %14s\n", "bending", "ns/vertex", "bending ns");
  std::printf("%-10s %10.1f %14s\n", "none", base, "-");
  csv << "none," << res << "," << base << ",0\n";
  const struct {
    const char* name;
    EnergyOptions::Bending model;
  } models[] = {{"tensor", EnergyOptions::Bending::kTensor},
                {"dihedral", EnergyOptions::Bending::kDihedral},
                {"linear", EnergyOptions::Bending::kLinear}};
  for (const auto& m : models) {
    EnergyOptions o;
    o.bending_model = m.model;
    ClothEnergy e;
    e.build(c, o);
    const double ns = time_vertex_blocks(e, c, sweeps, sink);
    std::printf("%-10s %10.1f %14.1f\n", m.name, ns, ns - base);
    csv << m.name << "," << res << "," << ns << "," << ns - base << "\n";
  }
  std::printf("wrote out/bench/energy.csv (checksum %.3e)\n", sink);
  return 0;
}
