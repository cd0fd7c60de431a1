// The pattern of a session's cloth: a panel cut along a curved stroke gives two pieces whose
// cut edge is the smoothed stroke (fair), not the grid's zigzag of split edges; notches where a
// reference line crosses the edge; the files written and readable.
#include "sim/draping/session_pattern.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sim/draping/session_lines.hpp"
#include "sim/ops/cut.hpp"

using namespace drape::sim;

namespace {

// A 0.4 m square panel (41 x 41 nodes, 10 mm), flat: x = u, y = v, z = 0.
Cloth flat_panel() {
  PanelSpec spec;
  spec.width = spec.height = 0.4;
  spec.nx = spec.ny = 41;
  spec.spacing = 0.01;
  Cloth c = make_panel(spec, FabricParams{});
  place_spread(c, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
  return c;
}

// A gentle S-curve across the panel, edge to edge (material space), every 5 mm.
std::vector<Vec2> s_curve() {
  std::vector<Vec2> s;
  for (int k = 0; k <= 80; ++k) {
    const double u = 0.4 * k / 80.0;
    s.emplace_back(u, 0.2 + 0.03 * std::sin(u / 0.4 * 2 * 3.141592653589793) + 0.1 * (u - 0.2));
  }
  return s;
}

struct CutPanel {
  Cloth cloth;
  CutResult cut;
};

CutPanel cut_panel() {
  CutPanel c{flat_panel(), {}};
  c.cut = cut_along_material(c.cloth, s_curve());
  EXPECT_TRUE(c.cut.ok) << c.cut.reason;
  EXPECT_EQ(c.cut.components_after, 2);
  return c;
}

std::string read_all(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace

TEST(SessionPattern, CutEdgeFollowsTheSmoothedStroke) {
  const CutPanel c = cut_panel();
  SessionPatternOptions opt;
  opt.waist_y = 0.33;  // crosses the upper piece's two side edges
  auto pieces = extract_session_pieces(c.cloth, {c.cut.smooth_stroke_uv}, opt);
  ASSERT_TRUE(pieces.ok()) << pieces.error();
  ASSERT_EQ(pieces->size(), 2u);
  double area = 0;
  for (const PatternPiece& pc : *pieces) {
    area += pc.area();
    const double fair = seam_fairness(pc, kSessionCutLabel);
    std::printf(
        "%s: %zu points, area %.2f cm^2, cut edge %.1f mm, fairness %.3f deg/mm, %zu "
        "notches\n",
        pc.name.c_str(), pc.outline.size(), pc.area() * 1e4,
        pc.seam_length(kSessionCutLabel) * 1000, fair, pc.notches.size());
    EXPECT_GT(pc.seam_length(kSessionCutLabel), 0.38);  // the cut runs across the panel
    EXPECT_LT(fair, 1.0);                               // smooth: the stroke, not the grid
    // Every point of the cut edge lies on the smoothed stroke.
    const int li = pc.label_index(kSessionCutLabel);
    for (size_t i = 0; i < pc.outline.size(); ++i) {
      if (pc.seg_label[i] != li) continue;
      double d = 1e9;
      const auto& s = c.cut.smooth_stroke_uv;
      for (size_t k = 0; k + 1 < s.size(); ++k) {
        const Vec2 e = s[k + 1] - s[k];
        const double t = std::clamp((pc.outline[i] - s[k]).dot(e) / e.squaredNorm(), 0.0, 1.0);
        d = std::min(d, (pc.outline[i] - s[k] - t * e).norm());
      }
      EXPECT_LT(d, 1e-9) << pc.name << " point " << i;
    }
  }
  EXPECT_NEAR(area, 0.16, 0.16 * 1e-3);  // the two pieces tile the panel
  int notches = 0;
  for (const PatternPiece& pc : *pieces) notches += static_cast<int>(pc.notches.size());
  EXPECT_EQ(notches, 2);
}

TEST(SessionPattern, WithoutTheStrokeTheCutEdgeIsTheGridZigzag) {
  const CutPanel c = cut_panel();
  auto smooth = extract_session_pieces(c.cloth, {c.cut.smooth_stroke_uv});
  auto grid = extract_session_pieces(c.cloth, {});
  ASSERT_TRUE(smooth.ok() && grid.ok());
  // Without strokes the split edges are "edge": their points off the panel's own border (the
  // cut's zigzag of grid edges), in order.
  std::vector<Vec2> zigzag;
  for (const Vec2& m : (*grid)[0].outline)
    if (m.x() > 0.005 && m.x() < 0.395 && m.y() > 0.005 && m.y() < 0.395) zigzag.push_back(m);
  ASSERT_GT(zigzag.size(), 30u);
  const double zig = polyline_fairness(zigzag);
  const double fair = seam_fairness((*smooth)[0], kSessionCutLabel);
  std::printf("cut edge: grid zigzag %.2f deg/mm, from the smoothed stroke %.3f deg/mm\n", zig,
              fair);
  EXPECT_GT(zig, 3.0);
  EXPECT_LT(fair, zig / 5);
}

TEST(SessionPattern, WritesTheFilesAndTheReport) {
  const CutPanel c = cut_panel();
  auto pieces = extract_session_pieces(c.cloth, {c.cut.smooth_stroke_uv});
  ASSERT_TRUE(pieces.ok()) << pieces.error();
  const std::string dir = std::string(DRAPE_BINARY_DIR) + "/test_out/session_pattern";
  std::filesystem::remove_all(dir);
  auto rep = write_session_pattern(dir, *pieces, 0.01, "session");
  ASSERT_TRUE(rep.ok()) << rep.error();
  for (const char* f :
       {"pattern.svg", "pattern.dxf", "pattern_a4.pdf", "pattern_letter.pdf", "report.json"})
    EXPECT_GT(std::filesystem::file_size(dir + "/" + f), 100u) << f;
  const std::string dxf = read_all(dir + "/pattern.dxf");
  EXPECT_NE(dxf.find("Piece Name: Piece 1"), std::string::npos);
  EXPECT_NE(dxf.find("Piece Name: Piece 2"), std::string::npos);
  EXPECT_EQ(read_all(dir + "/pattern_a4.pdf").rfind("%PDF", 0), 0u);
  const auto j = nlohmann::json::parse(read_all(dir + "/report.json"));
  ASSERT_EQ(j["pieces"].size(), 2u);
  EXPECT_LT(j["pieces"][0]["fairness_deg_per_mm"]["cut"].get<double>(), 1.0);
}

TEST(SessionPattern, BadClothIsAnError) {
  Cloth c = flat_panel();
  c.state.x.pop_back();
  auto r = extract_session_pieces(c, {});
  ASSERT_FALSE(r.ok());
  std::printf("%s\n", r.error().c_str());
  EXPECT_NE(r.error().find("positions"), std::string::npos);
  Cloth empty;
  auto e = extract_session_pieces(empty, {});
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().find("no triangles"), std::string::npos);
  // Unwritable directory: the error names it.
  auto p = extract_session_pieces(flat_panel(), {});
  ASSERT_TRUE(p.ok());
  auto w = write_session_pattern("/proc/no/such/dir", *p, 0.01, "s");
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().find("/proc/no/such/dir"), std::string::npos);
}

// The widths along the reference lines: a panel cut top to bottom along a slanted stroke that
// runs between the grid's columns; the left piece's width at height y is the stroke's u there
// (the panel's edge is at u = 0), read to the smoothed stroke, not to the zigzag of split edges.
TEST(SessionPattern, ReferenceLineWidthsEndOnTheSmoothedCut) {
  Cloth c = flat_panel();
  std::vector<Vec2> stroke;
  const auto u_at = [](double v) { return 0.2537 + 0.05 * (v - 0.2); };
  for (int k = 0; k <= 80; ++k) stroke.emplace_back(u_at(0.4 * k / 80.0), 0.4 * k / 80.0);
  const CutResult cut = cut_along_material(c, stroke);
  ASSERT_TRUE(cut.ok) << cut.reason;
  SessionPatternOptions opt;
  opt.hip_y = 0.1234;
  opt.waist_y = 0.3117;
  auto pieces = extract_session_pieces(c, {cut.smooth_stroke_uv}, opt);
  ASSERT_TRUE(pieces.ok()) << pieces.error();
  ASSERT_EQ(pieces->size(), 2u);
  const PatternPiece& left =
      pieces->at(0).area() < pieces->at(1).area() ? pieces->at(1) : pieces->at(0);
  const double hip = left.hip_width(), waist = polyline_length(left.waist_line);
  std::printf("left piece: hip width %.3f mm (stroke %.3f), waist width %.3f mm (stroke %.3f)\n",
              hip * 1e3, u_at(opt.hip_y) * 1e3, waist * 1e3, u_at(opt.waist_y) * 1e3);
  EXPECT_NEAR(hip, u_at(opt.hip_y), 2e-4);
  EXPECT_NEAR(waist, u_at(opt.waist_y), 2e-4);
  // A line the piece does not cross: no width.
  opt.hip_y = 0.5;
  auto off = extract_session_pieces(c, {cut.smooth_stroke_uv}, opt);
  ASSERT_TRUE(off.ok()) << off.error();
  for (const PatternPiece& pc : *off) EXPECT_TRUE(pc.hip_line.empty());
}
