// Pattern export read back by real readers: DXF with ezdxf (blocks, layers, units, closed
// boundaries), SVG with rsvg-convert, PDF with pdfinfo (page size) and pdftoppm (the 10 cm
// square measured in rendered pixels).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "sim/draping/pattern_pipeline.hpp"
#include "sim/form/dress_form.hpp"

using namespace drape::sim;

namespace {

std::string run(const std::string& cmd, int* rc) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) {
    *rc = -1;
    return out;
  }
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  *rc = pclose(p);
  return out;
}

struct Fixture : ::testing::Test {
  static void SetUpTestSuite() {
    auto m = measurements_for_size("9AR");
    ASSERT_TRUE(m.ok());
    auto form = DressForm::from_measurements(*m);
    ASSERT_TRUE(form.ok());
    auto d = load_design(std::string(DRAPE_SOURCE_DIR) + "/assets/designs/tight-skirt.json");
    ASSERT_TRUE(d.ok()) << d.error();
    PipelineOptions opt;
    opt.spacing = 0.01;
    auto r = run_pattern_pipeline(*d, *form, FabricParams{}, opt);
    ASSERT_TRUE(r.ok()) << r.error();
    pieces() = r->pieces;
    std::filesystem::create_directories(dir());
  }
  static std::vector<PatternPiece>& pieces() {
    static std::vector<PatternPiece> p;
    return p;
  }
  static std::string dir() { return std::string(DRAPE_BINARY_DIR) + "/test_out/pattern_export"; }
};

}  // namespace

TEST_F(Fixture, DxfReadByEzdxf) {
  ExportOptions o;
  o.style = "tight-skirt";
  const std::string path = dir() + "/p.dxf";
  ASSERT_EQ(write_dxf(path, pieces(), o), "");
  const std::string py = dir() + "/check_dxf.py";
  std::ofstream(py) << R"(import sys, ezdxf
doc = ezdxf.readfile(sys.argv[1])
msp = doc.modelspace()
inserts = [e for e in msp if e.dxftype() == 'INSERT']
texts = [e.dxf.text for e in msp if e.dxftype() == 'TEXT']
assert 'Units: METRIC' in texts, texts
assert doc.header.get('$INSUNITS', 0) == 4
print('inserts', len(inserts))
for ins in inserts:
    blk = doc.blocks[ins.dxf.name]
    layers = {}
    for e in blk:
        layers.setdefault(e.dxf.layer, []).append(e.dxftype())
    bounds = [e for e in blk if e.dxftype() == 'POLYLINE' and e.dxf.layer == '1']
    assert len(bounds) == 1 and bounds[0].is_closed, ins.dxf.name
    pts = [v.dxf.location for v in bounds[0].vertices]
    area = 0.5 * abs(sum(pts[i][0] * pts[(i + 1) % len(pts)][1] - pts[(i + 1) % len(pts)][0] * pts[i][1] for i in range(len(pts))))
    t = [e.dxf.text for e in blk if e.dxftype() == 'TEXT' and e.dxf.layer == '1']
    assert any(s.startswith('Piece Name: ') for s in t) and any(s.startswith('Size: ') for s in t) and any(s.startswith('Quantity: ') for s in t), t
    assert 'LINE' in layers.get('7', []), 'grain'
    assert layers.get('4', []).count('LINE') >= 4, 'notches'
    assert layers.get('8', []).count('LINE') == 4, 'dart legs'
    print(ins.dxf.name, 'boundary points', len(pts), 'area_mm2 %.0f' % area, 'layers', sorted(layers))
)";
  int rc = 0;
  const std::string out = run("/usr/bin/python3 " + py + " " + path + " 2>&1", &rc);
  std::printf("%s", out.c_str());
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("inserts 2"), std::string::npos);
  // The boundary area (mm^2) matches the cut line we computed.
  for (const PatternPiece& p : pieces()) {
    const auto cut = cut_line(p, o.seam_allowance);
    double a = 0;
    for (size_t i = 0; i < cut.size(); ++i)
      a += cut[i].x() * cut[(i + 1) % cut.size()].y() - cut[(i + 1) % cut.size()].x() * cut[i].y();
    char want[64];
    std::snprintf(want, sizeof want, "area_mm2 %.0f", 0.5 * std::abs(a) * 1e6);
    EXPECT_NE(out.find(p.name + " boundary"), std::string::npos);
    EXPECT_NE(out.find(want), std::string::npos) << want;
  }
}

TEST_F(Fixture, SvgReadByRsvg) {
  ExportOptions o;
  const std::string path = dir() + "/p.svg", png = dir() + "/p.png";
  ASSERT_EQ(write_svg(path, pieces(), o), "");
  int rc = 0;
  const std::string out =
      run("rsvg-convert --dpi-x 25.4 --dpi-y 25.4 -o " + png + " " + path + " 2>&1", &rc);
  ASSERT_EQ(rc, 0) << out;
  // PNG header: width and height at 1 px/mm equal the SVG's size in mm.
  std::ifstream f(png, std::ios::binary);
  unsigned char h[24];
  f.read(reinterpret_cast<char*>(h), 24);
  const int w = (h[16] << 24) | (h[17] << 16) | (h[18] << 8) | h[19];
  const int hh = (h[20] << 24) | (h[21] << 16) | (h[22] << 8) | h[23];
  std::ifstream s(path);
  std::stringstream ss;
  ss << s.rdbuf();
  const std::string svg = ss.str();
  const double wmm = std::stod(svg.substr(svg.find("width=\"") + 7));
  const double hmm = std::stod(svg.substr(svg.find("height=\"") + 8));
  std::printf("svg %.1f x %.1f mm -> png %d x %d px at 1 px/mm\n", wmm, hmm, w, hh);
  EXPECT_NEAR(w, wmm, 1.0);
  EXPECT_NEAR(hh, hmm, 1.0);
  EXPECT_NE(svg.find("Front"), std::string::npos);
  EXPECT_NE(svg.find("class=\"grain\""), std::string::npos);
  EXPECT_NE(svg.find("class=\"notch\""), std::string::npos);
}

TEST_F(Fixture, PdfPageSizeAndScaleSquare) {
  for (const Paper& paper : {Paper::a4(), Paper::letter()}) {
    ExportOptions o;
    const std::string path = dir() + "/p_" + paper.name + ".pdf";
    PdfLayout lay;
    ASSERT_EQ(write_pdf(path, pieces(), o, paper, &lay), "");
    int rc = 0;
    const std::string info = run("pdfinfo " + path + " 2>&1", &rc);
    ASSERT_EQ(rc, 0) << info;
    const size_t at = info.find("Page size:");
    ASSERT_NE(at, std::string::npos);
    double wpt = 0, hpt = 0;
    std::sscanf(info.c_str() + at, "Page size: %lf x %lf", &wpt, &hpt);
    const int pages = std::stoi(info.substr(info.find("Pages:") + 6));
    std::printf("%s: %d pages (%d x %d tiles + cover), %.2f x %.2f pt\n", paper.name.c_str(), pages,
                lay.rows, lay.cols, wpt, hpt);
    EXPECT_EQ(pages, lay.pages);
    EXPECT_GE(lay.pages, 3);
    EXPECT_NEAR(wpt, paper.width_mm * 72 / 25.4, 0.5);
    EXPECT_NEAR(hpt, paper.height_mm * 72 / 25.4, 0.5);
    // Render the cover at 150 dpi and measure the black square.
    const int dpi = 150;
    const std::string ppm = dir() + "/cover_" + paper.name;
    const std::string o2 = run("pdftoppm -r " + std::to_string(dpi) +
                                   " -f 1 -l 1 -gray -singlefile " + path + " " + ppm + " 2>&1",
                               &rc);
    ASSERT_EQ(rc, 0) << o2;
    std::ifstream f(ppm + ".pgm", std::ios::binary);
    ASSERT_TRUE(f.good());
    std::string magic;
    int W, H, maxv;
    f >> magic >> W >> H >> maxv;
    f.get();
    std::vector<unsigned char> img(static_cast<size_t>(W) * H);
    f.read(reinterpret_cast<char*>(img.data()), img.size());
    // Row and column through the square's centre: count dark pixels (coverage-weighted).
    const double px_per_mm = dpi / 25.4;
    const int cy = static_cast<int>((kScaleSquareY + kScaleSquareSize / 2) * px_per_mm);
    const int cx = static_cast<int>((kScaleSquareX + kScaleSquareSize / 2) * px_per_mm);
    double wdark = 0, hdark = 0;
    for (int x = 0; x < W; ++x) wdark += 1.0 - img[static_cast<size_t>(cy) * W + x] / 255.0;
    for (int y = static_cast<int>(kScaleSquareY * px_per_mm) - 20;
         y < static_cast<int>((kScaleSquareY + kScaleSquareSize) * px_per_mm) + 20; ++y)
      hdark += 1.0 - img[static_cast<size_t>(y) * W + cx] / 255.0;
    const double wmm = wdark / px_per_mm, hmm = hdark / px_per_mm;
    std::printf("  scale square at %d dpi: %.2f x %.2f mm\n", dpi, wmm, hmm);
    EXPECT_NEAR(wmm, 100.0, 0.5);
    EXPECT_NEAR(hmm, 100.0, 0.5);
  }
}

TEST_F(Fixture, SeamAllowanceAndBadPath) {
  const PatternPiece& p = pieces().front();
  const auto seam = cut_line(p, 0.0), cut = cut_line(p, 0.01);
  const auto area = [](const std::vector<Vec2>& q) {
    double a = 0;
    for (size_t i = 0; i < q.size(); ++i)
      a += q[i].x() * q[(i + 1) % q.size()].y() - q[(i + 1) % q.size()].x() * q[i].y();
    return 0.5 * a;
  };
  double perim = 0;
  for (size_t i = 0; i < seam.size(); ++i) perim += (seam[(i + 1) % seam.size()] - seam[i]).norm();
  // Offsetting by d grows a convex-ish outline's area by about perimeter * d.
  EXPECT_NEAR(area(cut) - area(seam), perim * 0.01, 0.1 * perim * 0.01);
  ExportOptions o;
  EXPECT_NE(write_svg("/nonexistent_dir/x.svg", pieces(), o).find("/nonexistent_dir/x.svg"),
            std::string::npos);
  EXPECT_NE(write_dxf("/nonexistent_dir/x.dxf", pieces(), o).find("x.dxf"), std::string::npos);
}
