// Geometric draping timing: mapping + pattern extraction of a 1 cm panel (target < 50 ms) and
// the whole tight-skirt pipeline (design -> pattern files). Prints a table and writes
// out/bench/pattern.csv (median of repeated runs).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "sim/draping/pattern_pipeline.hpp"
#include "sim/form/dress_form.hpp"

using namespace drape::sim;
using Clock = std::chrono::steady_clock;

namespace {

struct Setup {
  DressForm form;
  Design design;
};

Setup& setup() {
  static Setup s = [] {
    auto m = measurements_for_size("9AR");
    auto f = DressForm::from_measurements(*m);
    auto d = load_design(std::string(DRAPE_SOURCE_DIR) + "/assets/designs/tight-skirt.json");
    if (!f.ok() || !d.ok()) {
      std::fprintf(stderr, "pattern_bench: set-up failed: %s\n",
                   d.ok() ? f.error().c_str() : d.error().c_str());
      std::exit(1);
    }
    return Setup{std::move(*f), std::move(*d)};
  }();
  return s;
}

// Mapping + extraction of the front panel (two darts) at the given spacing.
double map_extract_ms(double spacing, int* vertices) {
  Setup& s = setup();
  PanelDesign pd = s.design.pieces[0].panel;
  pd.spacing = spacing;
  auto panel = build_panel(pd, FabricParams{});
  const auto& lm = s.form.landmarks();
  const MappingSurface surf(s.form);
  PieceLines lines;
  lines.waist_y = lm.waist_y;
  lines.hip_y = lm.hip_y;
  lines.hem_y = lm.waist_y - s.design.length_below_waist;
  const auto t0 = Clock::now();
  const PieceMapping pm =
      make_piece_mapping(*panel, surf, 0.0, -1, lm.right_side_theta, lm.waist_y);
  map_panel(*panel, surf, pm);
  auto piece = extract_piece(*panel, surf, pm, lines);
  benchmark::DoNotOptimize(piece);
  *vertices = panel->cloth.num_vertices();
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void BM_MapExtract1cm(benchmark::State& st) {
  int nv = 0;
  for (auto _ : st) benchmark::DoNotOptimize(map_extract_ms(0.01, &nv));
  st.counters["vertices"] = nv;
}
BENCHMARK(BM_MapExtract1cm)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  std::filesystem::create_directories("out/bench");
  std::ofstream csv("out/bench/pattern.csv");
  csv << "case,spacing_mm,vertices,median_ms,target_ms\n";
  std::printf("\n%-28s %10s %9s %11s %9s\n", "case", "spacing", "vertices", "median ms", "target");
  for (double sp : {0.02, 0.01, 0.005}) {
    std::vector<double> t;
    int nv = 0;
    for (int r = 0; r < 11; ++r) t.push_back(map_extract_ms(sp, &nv));
    const double m = median(t);
    std::printf("%-28s %8.0f mm %9d %11.2f %9s\n", "mapping + extraction", sp * 1000, nv, m,
                sp == 0.01 ? "< 50" : "-");
    csv << "map_extract," << sp * 1000 << "," << nv << "," << m << "," << (sp == 0.01 ? "50" : "")
        << "\n";
  }
  for (double sp : {0.02, 0.01}) {
    std::vector<double> t;
    PipelineReport rep;
    for (int r = 0; r < 3; ++r) {
      PipelineOptions opt;
      opt.spacing = sp;
      opt.out_dir = "out/bench/pattern_files";
      auto res = run_pattern_pipeline(setup().design, setup().form, FabricParams{}, opt);
      if (!res.ok()) {
        std::fprintf(stderr, "pipeline failed: %s\n", res.error().c_str());
        return 1;
      }
      t.push_back(res->report.pipeline_ms);
      rep = res->report;
    }
    const double m = median(t);
    std::printf(
        "%-28s %8.0f mm %9s %11.2f %9s   (map+extract %.1f, relax %.1f, remesh %.1f, sew %.1f, "
        "export %.1f)\n",
        "whole pipeline (with files)", sp * 1000, "-", m, "-", rep.mapping_extraction_ms,
        rep.relax_ms, rep.remesh_ms, rep.sew_ms, rep.export_ms);
    csv << "pipeline," << sp * 1000 << ",," << m << ",\n";
  }
  std::printf("wrote out/bench/pattern.csv\n");
  return 0;
}
