// Blocks beyond the tight skirt: slash and spread on a hand-made block (geometry exactly known),
// and the flared skirt design end to end with its fit checks and its files read back by real
// readers (ezdxf, pdfinfo, rsvg-convert).
#include "sim/draping/blocks.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "sim/draping/pattern_pipeline.hpp"
#include "sim/form/dress_form.hpp"

using namespace drape::sim;

namespace {

// A rectangle 0.25 x 0.6 m (centre at x = 0, hem at y = 0, waist at y = 0.6) with one dart
// whose legs run from the tip (0.1, 0.45) to (0.09, 0.6) and (0.11, 0.6), labelled as the
// extraction labels them, counter-clockwise: hem, side, waist, leg2, leg1, waist, centre.
PatternPiece one_dart_block() {
  PatternPiece p;
  p.name = "Test";
  p.labels = {"hem", "side", "waist", "dart1_leg2", "dart1_leg1", "centre_front"};
  const std::vector<std::pair<Vec2, int>> pts = {
      {{0.0, 0.0}, 0},  {{0.125, 0.0}, 0}, {{0.25, 0.0}, 1}, {{0.25, 0.6}, 2}, {{0.11, 0.6}, 3},
      {{0.1, 0.45}, 4}, {{0.09, 0.6}, 2},  {{0.0, 0.6}, 5},  {{0.0, 0.3}, 5},
  };
  for (const auto& [q, l] : pts) {
    p.outline.push_back(q);
    p.seg_label.push_back(l);
  }
  p.hip_line = {{0.0, 0.3}, {0.125, 0.3}, {0.25, 0.3}};
  p.darts.push_back({5, 6, 4, 0.02});
  return p;
}

}  // namespace

TEST(Blocks, SlashAndSpreadClosesTheDartAndOpensTheHem) {
  const PatternPiece block = one_dart_block();
  auto sp = slash_and_spread(block, 0.002);
  ASSERT_TRUE(sp.ok()) << sp.error();
  ASSERT_EQ(sp->steps.size(), 1u);
  // The dart's angle: the two legs seen from the tip.
  const Vec2 l1 = Vec2(0.09, 0.6) - Vec2(0.1, 0.45), l2 = Vec2(0.11, 0.6) - Vec2(0.1, 0.45);
  const double dart = std::acos(l1.normalized().dot(l2.normalized()));
  EXPECT_NEAR(std::abs(sp->steps[0].angle), dart, 1e-12);
  // The slash runs down leg 2's line (from (0.11, 0.6) through the tip) to the hem at
  // distance rho from the tip; the hem opens by the chord 2 rho sin(angle / 2).
  const Vec2 d = (Vec2(0.1, 0.45) - Vec2(0.11, 0.6)).normalized();
  const double rho = 0.45 / -d.y();
  EXPECT_NEAR(sp->steps[0].hem_gap, 2 * rho * std::sin(dart / 2), 1e-12);
  // Nothing of the dart is left; the waist is one seam whose length is the block's waist.
  const PatternPiece& p = sp->piece;
  EXPECT_TRUE(p.seam_points("dart1_leg1").empty());
  EXPECT_TRUE(p.seam_points("dart1_leg2").empty());
  EXPECT_NEAR(p.seam_length("waist"), 0.09 + 0.14, 1e-9);
  // Area: the block's plus the wedge under the tip (a circular sector, hem drawn as an arc).
  const double sector = 0.5 * rho * rho * dart;
  EXPECT_NEAR(p.area(), block.area() + sector, 0.01 * sector);
  EXPECT_GT(p.area(), 0);  // counter-clockwise
  // The hem: the block's hem plus the arc.
  EXPECT_NEAR(sp->hem_length, 0.25 + rho * dart, 1e-4);
  // The hip line keeps its length on the cloth (the slash opening excluded).
  EXPECT_NEAR(sp->hip_width, 0.25, 1e-12);
  EXPECT_NEAR(sp->steps[0].hip_gap, 2 * (0.45 - 0.3) / -d.y() * std::sin(dart / 2), 1e-12);
  // A point of the side part goes back to where it was in the block, carrying the wedge's cloth
  // along its row; a wedge point goes onto the slash; the centre part stays.
  double extra = -1;
  const Vec2 tip(0.1, 0.45);
  const Vec2 far =
      tip + Eigen::Rotation2Dd(sp->steps[0].angle).toRotationMatrix() * (Vec2(0.25, 0.0) - tip);
  EXPECT_LT((unspread_arc(*sp, far, &extra) - Vec2(0.25, 0.0)).norm(), 1e-12);
  EXPECT_NEAR(extra, (Vec2(0.25, 0.0) - tip).dot(d) * dart, 1e-12);
  EXPECT_NEAR(spread_arc_at_row(*sp, 0.0), rho * dart, 1e-12);
  const Vec2 mid = tip + Eigen::Rotation2Dd(sp->steps[0].angle / 2).toRotationMatrix() * d * 0.2;
  EXPECT_LT((unspread_arc(*sp, mid, &extra) - (tip + 0.2 * d)).norm(), 1e-12);
  EXPECT_NEAR(extra, 0.2 * dart / 2, 1e-12);
  const Vec2 centre_side(0.05, 0.1);
  EXPECT_LT((unspread_arc(*sp, centre_side, &extra) - centre_side).norm(), 1e-15);
  EXPECT_EQ(extra, 0.0);
}

TEST(Blocks, SlashThatMissesTheHemIsNamed) {
  PatternPiece block = one_dart_block();
  block.seg_label[0] = block.seg_label[1] = 1;  // no hem: the slash meets nothing
  block.labels[0] = "unused";
  block.labels.push_back("hem");
  auto sp = slash_and_spread(block);
  ASSERT_FALSE(sp.ok());
  std::printf("%s\n", sp.error().c_str());
  EXPECT_NE(sp.error().find("piece 'Test': dart1: "), std::string::npos);
}

namespace {

std::string shell(const std::string& cmd, int* rc) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return *rc = -1, out;
  char buf[4096];
  for (size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  *rc = pclose(p);
  return out;
}

// Runs a design of assets/designs/ on the 9AR form, writing its files under test_out/.
PipelineResult run_design(const std::string& name, const std::string& out_dir) {
  auto m = measurements_for_size("9AR");
  EXPECT_TRUE(m.ok());
  auto form = DressForm::from_measurements(*m);
  EXPECT_TRUE(form.ok());
  auto d = load_design(std::string(DRAPE_SOURCE_DIR) + "/assets/designs/" + name + ".json");
  EXPECT_TRUE(d.ok()) << d.error();
  PipelineOptions opt;
  opt.out_dir = out_dir;
  auto r = run_pattern_pipeline(*d, *form, FabricParams{}, opt);
  EXPECT_TRUE(r.ok()) << r.error();
  return r.ok() ? std::move(*r) : PipelineResult{};
}

// The exported files read back: DXF by ezdxf (one block per piece, closed boundary, `legs`
// dart-leg lines on layer 8), both PDFs by pdfinfo, the SVG by rsvg-convert (to a PNG).
void check_files(const std::string& dir, size_t pieces, int legs) {
  const std::string py = dir + "/check_dxf.py";
  std::ofstream(py)
      << "import sys, ezdxf\n"
         "doc = ezdxf.readfile(sys.argv[1])\n"
         "ins = [e for e in doc.modelspace() if e.dxftype() == 'INSERT']\n"
         "print('inserts', len(ins))\n"
         "for i in ins:\n"
         "    b = doc.blocks[i.dxf.name]\n"
         "    bd = [e for e in b if e.dxftype() == 'POLYLINE' and e.dxf.layer == '1']\n"
         "    assert len(bd) == 1 and bd[0].is_closed, i.dxf.name\n"
         "    print(i.dxf.name, 'dart legs', sum(1 for e in b if e.dxftype() == "
         "'LINE' and e.dxf.layer == '8'))\n";
  int rc = 0;
  std::string out = shell("/usr/bin/python3 " + py + " " + dir + "/pattern.dxf 2>&1", &rc);
  std::printf("%s", out.c_str());
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("inserts " + std::to_string(pieces)), std::string::npos) << out;
  size_t blocks_with_legs = 0;
  for (size_t at = 0;
       (at = out.find("dart legs " + std::to_string(legs) + "\n", at)) != std::string::npos; ++at)
    ++blocks_with_legs;
  EXPECT_EQ(blocks_with_legs, pieces) << out;
  for (const char* pdf : {"pattern_a4.pdf", "pattern_letter.pdf"}) {
    out = shell("pdfinfo " + dir + "/" + pdf + " 2>&1", &rc);
    EXPECT_EQ(rc, 0) << out;
    EXPECT_NE(out.find("Pages:"), std::string::npos) << out;
  }
  out = shell("rsvg-convert --dpi-x 25.4 --dpi-y 25.4 -o " + dir + "/pattern.png " + dir +
                  "/pattern.svg 2>&1",
              &rc);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_TRUE(std::ifstream(dir + "/pattern.png").good());
}

}  // namespace

TEST(Blocks, FlaredSkirtMeetsItsFitChecks) {
  const std::string dir = std::string(DRAPE_BINARY_DIR) + "/test_out/flared_skirt";
  const PipelineResult r = run_design("flared-skirt", dir);
  const PipelineReport& rep = r.report;
  std::printf(
      "flared skirt: hip widths %+.3f mm, waist widths %+.3f mm, worst area %.3f %%, sewn waist "
      "girth %+.3f %%, sewn hip girth %+.3f %% of the pattern's %.1f mm, hem sweep %.1f mm\n",
      rep.hip_width_error_mm, rep.waist_width_error_mm, rep.area_error_pct,
      rep.garment_waist_girth_error_pct, rep.garment_hip_girth_vs_pattern_pct,
      rep.pattern_hip_girth_mm, rep.hem_sweep_mm);
  ASSERT_EQ(r.pieces.size(), 2u);
  EXPECT_EQ(rep.flare, "close_darts");
  // Widths against the form's arcs plus ease.
  EXPECT_NEAR(rep.hip_width_error_mm, 0.0, 2.0);
  EXPECT_NEAR(rep.waist_width_error_mm, 0.0, 2.0);
  // Piece areas against the draped (sewn, relaxed) areas, sewn girths.
  EXPECT_LT(rep.area_error_pct, 1.0);
  EXPECT_LT(std::abs(rep.garment_waist_girth_error_pct), 1.0);
  // The flare starts above the hip (the dart tips), so the skirt measures more than the form
  // there: the sewn hip girth is checked against the cut pattern's girth along the hip line.
  EXPECT_GT(rep.pattern_hip_girth_mm, rep.form_hip_girth_mm + rep.ease_mm + 20);
  EXPECT_LT(std::abs(rep.garment_hip_girth_vs_pattern_pct), 1.0);
  // Darts closed, hem opened: each piece's hem is longer than its hip line by the spread.
  double hem = 0;
  for (size_t i = 0; i < r.pieces.size(); ++i) {
    const PieceReport& p = rep.pieces[i];
    EXPECT_TRUE(r.pieces[i].darts.empty());
    ASSERT_EQ(p.spread_deg.size(), 2u);
    for (double a : p.spread_deg) EXPECT_GT(std::abs(a), 1.0) << p.name;
    EXPECT_GT(p.hem_mm, p.hip_width_mm + 20) << p.name;
    hem += 2 * p.hem_mm;
  }
  EXPECT_NEAR(rep.hem_sweep_mm, hem, 1e-9);
  std::ifstream f(dir + "/report.json");
  ASSERT_TRUE(f.good());
  const auto j = nlohmann::json::parse(f);
  EXPECT_DOUBLE_EQ(j["hem_sweep_mm"].get<double>(), rep.hem_sweep_mm);
  check_files(dir, 2, 0);
}

TEST(Blocks, UnknownFlareIsNamed) {
  std::ifstream f(std::string(DRAPE_SOURCE_DIR) + "/assets/designs/flared-skirt.json");
  auto j = nlohmann::json::parse(f);
  ASSERT_EQ(j["flare"], "close_darts");
  j["flare"] = "bell";
  auto d = parse_design(j.dump(), "bad.json");
  ASSERT_FALSE(d.ok());
  std::printf("%s\n", d.error().c_str());
  EXPECT_NE(d.error().find("bad.json.flare: unknown 'bell' (known: none, close_darts)"),
            std::string::npos);
  j["flare"] = 3;
  d = parse_design(j.dump(), "bad.json");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().find("bad.json.flare: must be a string"), std::string::npos) << d.error();
}
