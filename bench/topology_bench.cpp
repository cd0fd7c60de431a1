// Costs that come with the topology and the scene's layers rather than with a step (nothing is
// computed that a scene doesn't need), on the settled form drape (XPBD 10x1, one thread, 120
// frames) at 32^2, 64^2 and 128^2, each side by side in one run:
//  * rebuilding the cloth energy after a cut, with the bending vertex matrix P (VBD, Newton,
//    Verlet need it) and rows only (what XPBD builds), best of 3;
//  * the first XPBD step after a slit is cut (re-cook + one frame) against a plain frame;
//  * one self-collision detection with and without the per-entry bounding-sphere test (same
//    pairs), best of 10.
// Writes out/bench/topology.csv (one row per resolution) and prints the table.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bench/best_time.hpp"
#include "sim/energy/energy.hpp"
#include "sim/energy/self_collision.hpp"
#include "sim/ops/cut.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"
#include "sim/testbeds/testbed.hpp"

using namespace drape::sim;

namespace {

using drape::bench::best_ms;

struct Row {
  int res = 0;
  double build_p = 0, build_rows = 0, frame = 0, frame_after_cut = 0, self_on = 0, self_off = 0;
  int pairs_on = 0, pairs_off = 0;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Costs that come with the topology and the scene's layers (out/bench/topology.csv)."};
  CLI11_PARSE(app, argc, argv);
  std::filesystem::create_directories("out/bench");
  std::vector<Row> rows;
  for (int res : {32, 64, 128}) {
    Row r;
    r.res = res;
    Testbed sc = make_scene("form", res);
    XpbdOptions o;
    o.threads = 1;
    XpbdSolver s(o);
    for (int f = 0; f < 120; ++f) s.step(sc.cloth, sc.objects, 1.0 / 90);
    SelfCollision self;
    r.self_on = best_ms(10, [&] {
      r.pairs_on = self.detect(sc.cloth, sc.cloth.state.x, sc.objects.offset, 0.005);
    });
    self.set_sphere_test(false);
    r.self_off = best_ms(10, [&] {
      r.pairs_off = self.detect(sc.cloth, sc.cloth.state.x, sc.objects.offset, 0.005);
    });
    r.frame = best_ms(3, [&] { s.step(sc.cloth, sc.objects, 1.0 / 90); });
    // A 30 cm slit up the front (material space), then the step that re-cooks.
    const CutResult cut = cut_along_material(sc.cloth, {Vec2(0.2, 0.0), Vec2(0.22, 0.3)});
    if (!cut.ok) std::printf("(res %d: the slit was not cut: %s)\n", res, cut.reason.c_str());
    EnergyOptions with_p, rows_only;
    rows_only.bending_matrix = false;
    r.build_p = best_ms(3, [&] {
      ClothEnergy e;
      e.build(sc.cloth, with_p);
    });
    r.build_rows = best_ms(3, [&] {
      ClothEnergy e;
      e.build(sc.cloth, rows_only);
    });
    r.frame_after_cut = best_ms(1, [&] { s.step(sc.cloth, sc.objects, 1.0 / 90); });
    rows.push_back(r);
  }
  std::ofstream csv("out/bench/topology.csv");
  csv << "resolution,energy_build_with_P_ms,energy_build_rows_ms,xpbd_frame_ms,"
         "xpbd_frame_after_cut_ms,self_detect_sphere_ms,self_detect_plain_ms,self_pairs\n";
  std::printf("%5s | %12s %10s %6s | %8s %10s | %14s %12s %6s %6s\n", "res", "build with P",
              "rows only", "ratio", "frame", "after cut", "self (sphere)", "self (plain)", "ratio",
              "pairs");
  for (const Row& r : rows) {
    std::printf(
        "%5d | %9.1f ms %7.1f ms %5.2fx | %5.1f ms %7.1f ms | %11.2f ms %9.2f ms %5.2fx %6d%s\n",
        r.res, r.build_p, r.build_rows, r.build_p / r.build_rows, r.frame, r.frame_after_cut,
        r.self_on, r.self_off, r.self_off / r.self_on, r.pairs_on,
        r.pairs_on == r.pairs_off ? "" : " (MISMATCH)");
    csv << r.res << ',' << r.build_p << ',' << r.build_rows << ',' << r.frame << ','
        << r.frame_after_cut << ',' << r.self_on << ',' << r.self_off << ',' << r.pairs_on << '\n';
  }
  std::printf("wrote out/bench/topology.csv\n");
  bool same = true;
  for (const Row& r : rows) same = same && r.pairs_on == r.pairs_off;
  return same ? 0 : 1;
}
