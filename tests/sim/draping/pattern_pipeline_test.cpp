// End-to-end tight skirt (the pipeline's acceptance bounds): outline before relaxation equals the
// flat panel region, hip/waist widths against the form's girths, piece area against draped area,
// sewn garment girth at the hip, and bad design input named by field.
#include "sim/draping/pattern_pipeline.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "sim/form/dress_form.hpp"

using namespace drape::sim;

namespace {

const std::string kDesign = std::string(DRAPE_SOURCE_DIR) + "/assets/designs/tight-skirt.json";

DressForm form9() {
  auto m = measurements_for_size("9AR");
  EXPECT_TRUE(m.ok());
  auto f = DressForm::from_measurements(*m);
  EXPECT_TRUE(f.ok()) << f.error();
  return std::move(*f);
}

void check_must_show(double ease_m) {
  const DressForm form = form9();
  auto d = load_design(kDesign);
  ASSERT_TRUE(d.ok()) << d.error();
  PipelineOptions opt;
  opt.ease = ease_m;
  opt.spacing = 0.01;
  auto r = run_pattern_pipeline(*d, form, FabricParams{}, opt);
  ASSERT_TRUE(r.ok()) << r.error();
  const PipelineReport& rep = r->report;
  std::printf(
      "ease %.1f mm: outline error before relax %.5f mm, hip error %+.3f mm, waist error "
      "%+.3f mm, area error %.3f %%, garment hip girth error %+.3f %% (%s), %.0f ms\n",
      ease_m * 1000, rep.outline_error_before_relax_mm, rep.hip_width_error_mm,
      rep.waist_width_error_mm, rep.area_error_pct, rep.garment_hip_girth_error_pct,
      rep.relax_backend.c_str(), rep.pipeline_ms);
  // The acceptance bounds (measured: outline 0.0000 mm, hip +0.000, waist -1.2 mm, area 0.74 %,
  // garment hip girth -0.03 %; ease 40 mm in docs/results.md).
  EXPECT_LT(rep.outline_error_before_relax_mm, 1e-3);
  EXPECT_NEAR(rep.hip_width_error_mm, 0.0, 2.0);
  EXPECT_NEAR(rep.waist_width_error_mm, 0.0, 2.0);
  EXPECT_LT(rep.area_error_pct, 1.0);
  EXPECT_LT(std::abs(rep.garment_hip_girth_error_pct), 1.0);
  ASSERT_EQ(r->pieces.size(), 2u);
  // Fair side seams: the largest turn per mm along each seam (seam_fairness). The front side
  // seam once had a bump ~10 cm below the waist (6.7 deg/mm; the side line held at the nearest
  // grid node, which jumps a column where the line crosses one); held between the nodes
  // (relax.cpp, side_line_ties) it is 2.2 deg/mm, with ease 40 mm 1.7 (what is left: the
  // zone shift of eq. 2-10 starting at the dart tips' height, docs/draping.md).
  for (const auto& p : rep.pieces)
    for (const auto& [label, f] : p.fairness_deg_per_mm) {
      std::printf("  %s %s: fairness %.2f deg/mm\n", p.name.c_str(), label.c_str(), f);
      if (label == "side" || label == "hem" || label == "waist" || label.rfind("centre", 0) == 0) {
        EXPECT_LT(f, 3.0) << p.name << " " << label;
      }
    }
  for (const auto& p : rep.pieces) {
    ASSERT_EQ(p.dart_intake_mm.size(), 2u);
    for (size_t k = 0; k < 2; ++k) {
      std::printf("  %s dart %zu: intake %.2f mm (wanted %.2f)\n", p.name.c_str(), k + 1,
                  p.dart_intake_mm[k], p.dart_intake_wanted_mm[k]);
      // The mapping gives the wanted intake exactly (sim_pattern_extract_test); after relaxation
      // the waist row slides up the form and the back dart 2 opens by ~3 mm (GAP, docs/draping.md).
      EXPECT_NEAR(p.dart_intake_mm[k], p.dart_intake_wanted_mm[k], 3.5);
    }
  }
}

}  // namespace

TEST(PatternPipeline, TightSkirtMustShow) {
  check_must_show(0.0);
}

TEST(PatternPipeline, TightSkirtWithEase) {
  check_must_show(0.04);
}

TEST(PatternPipeline, WritesReportAndFiles) {
  const DressForm form = form9();
  auto d = load_design(kDesign);
  ASSERT_TRUE(d.ok()) << d.error();
  PipelineOptions opt;
  opt.spacing = 0.02;  // the coarse mesh runs end to end too (extraction, remesh, sew)
  opt.out_dir = std::string(DRAPE_BINARY_DIR) + "/test_out/pattern_pipeline";
  auto r = run_pattern_pipeline(*d, form, FabricParams{}, opt);
  ASSERT_TRUE(r.ok()) << r.error();
  // Every outline is a simple polygon (remeshing needs one): no two non-adjacent segments cross.
  for (const PatternPiece& pc : r->pieces) {
    const auto& o = pc.outline;
    const int n = static_cast<int>(o.size());
    int crossings = 0;
    for (int i = 0; i < n; ++i)
      for (int j = i + 2; j < n; ++j) {
        if ((j + 1) % n == i) continue;
        const Vec2 a = o[i], b = o[(i + 1) % n], c = o[j], d = o[(j + 1) % n];
        const auto side = [](const Vec2& p, const Vec2& q, const Vec2& x) {
          return (q.x() - p.x()) * (x.y() - p.y()) - (q.y() - p.y()) * (x.x() - p.x());
        };
        if (side(a, b, c) * side(a, b, d) < 0 && side(c, d, a) * side(c, d, b) < 0) ++crossings;
      }
    std::printf("%s: %d outline points, %d loops cut, %d crossings\n", pc.name.c_str(), n,
                pc.loops_removed, crossings);
    EXPECT_EQ(crossings, 0) << pc.name;
  }
  std::ifstream f(opt.out_dir + "/report.json");
  ASSERT_TRUE(f.good());
  const auto j = nlohmann::json::parse(f);
  for (const char* k :
       {"hip_width_error_mm", "waist_width_error_mm", "area_error_pct",
        "garment_hip_girth_error_pct", "outline_error_before_relax_mm", "pipeline_ms"})
    EXPECT_TRUE(j.contains(k) && j[k].is_number()) << k;
  EXPECT_DOUBLE_EQ(j["hip_width_error_mm"].get<double>(), r->report.hip_width_error_mm);
  // The fairness of every seam line, per piece, as the report computed it.
  ASSERT_EQ(j["pieces"].size(), r->report.pieces.size());
  for (size_t i = 0; i < r->report.pieces.size(); ++i)
    for (const auto& [label, fair] : r->report.pieces[i].fairness_deg_per_mm)
      EXPECT_DOUBLE_EQ(j["pieces"][i]["fairness_deg_per_mm"][label].get<double>(), fair) << label;
  EXPECT_TRUE(j["pieces"][0]["fairness_deg_per_mm"].contains("side"));
  for (const char* file : {"pattern.svg", "pattern.dxf", "pattern_a4.pdf", "pattern_letter.pdf",
                           "draped_panels.gltf", "garment.gltf"})
    EXPECT_TRUE(std::ifstream(opt.out_dir + "/" + file).good()) << file;
}

TEST(PatternPipeline, BadDesignNamesTheField) {
  auto text = [] {
    std::ifstream f(kDesign);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  }();
  auto j = nlohmann::json::parse(text);
  {
    auto b = j;
    b["pieces"][1]["side_line"] = "rigth_side";
    auto d = parse_design(b.dump(), "bad.json");
    ASSERT_FALSE(d.ok());
    std::printf("%s\n", d.error().c_str());
    EXPECT_NE(d.error().find("bad.json: pieces[1].side_line: unknown line 'rigth_side'"),
              std::string::npos);
  }
  {
    auto b = j;
    b["pieces"][0]["darts"][1]["position"] = 0.09;  // one column from darts[0] at 0.08
    auto d = parse_design(b.dump(), "bad.json");
    ASSERT_FALSE(d.ok());
    std::printf("%s\n", d.error().c_str());
    EXPECT_NE(d.error().find("pieces[0].darts[1].position: overlapping slits"), std::string::npos);
  }
  {
    auto b = j;
    b["pieces"][0]["darts"][0]["depth"] = 0.9;
    auto d = parse_design(b.dump(), "bad.json");
    ASSERT_FALSE(d.ok());
    std::printf("%s\n", d.error().c_str());
    EXPECT_NE(d.error().find("pieces[0].darts[0].depth: slit off the panel"), std::string::npos);
  }
  {
    auto b = j;
    b["pieces"][0]["panel"]["width"] = 0.6;  // wider than half the hip girth
    auto d = parse_design(b.dump(), "bad.json");
    ASSERT_TRUE(d.ok()) << d.error();
    const DressForm form = form9();
    auto r = run_pattern_pipeline(*d, form, FabricParams{});
    ASSERT_FALSE(r.ok());
    std::printf("%s\n", r.error().c_str());
    EXPECT_NE(r.error().find("pieces[0].panel.width: panel larger than the form"),
              std::string::npos);
  }
  {
    auto d = parse_design("{\"pieces\": 3", "broken.json");
    ASSERT_FALSE(d.ok());
    EXPECT_NE(d.error().find("broken.json"), std::string::npos);
  }
  EXPECT_FALSE(load_design("/nonexistent/design.json").ok());
}
