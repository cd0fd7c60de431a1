// Tests of sim/core/fabric.cpp: the presets in assets/ and every kind of bad input.
#include "sim/core/fabric.hpp"

#include <gtest/gtest.h>

#include <fstream>

using namespace drape::sim;

static const std::string kAssets = std::string(DRAPE_SOURCE_DIR) + "/assets/fabrics.json";

TEST(Fabric, LoadsAssetPresets) {
  auto all = load_fabric_presets(kAssets);
  ASSERT_TRUE(all) << all.error();
  EXPECT_EQ(all->size(), 9u);  // four literature mid-points, five calibrated (docs/fabrics.md)
  auto m = load_fabric(kAssets, "muslin");
  ASSERT_TRUE(m) << m.error();
  EXPECT_EQ(m->name, "muslin");
  EXPECT_DOUBLE_EQ(m->areal_density, 0.13);
  EXPECT_DOUBLE_EQ(m->stretch_warp, 8000);
  EXPECT_DOUBLE_EQ(m->stretch_weft, 5000);
  EXPECT_DOUBLE_EQ(m->shear, 60);
  EXPECT_DOUBLE_EQ(m->bending_warp, 8.0e-6);
  EXPECT_DOUBLE_EQ(m->rayleigh_damping, 0.0);
  auto d = load_fabric(kAssets, "denim");
  ASSERT_TRUE(d);
  EXPECT_DOUBLE_EQ(d->areal_density, 0.40);
  auto w = load_fabric(kAssets, "wool_red");  // a preset calibrated by `./drape bench fabrics`
  ASSERT_TRUE(w) << w.error();
  EXPECT_DOUBLE_EQ(w->areal_density, 0.274);
  EXPECT_GT(w->bending_warp, w->bending_weft);
}

static std::string preset(const std::string& shear) {
  return R"({"_units": "x", "muslin": {"areal_density": 0.13, "thickness": 0.0003,
    "stretch_warp": 8000, "stretch_weft": 5000, "shear": )" +
         shear + R"(, "bending_warp": 8e-6, "bending_weft": 5e-6}})";
}

TEST(Fabric, ErrorsNameFileAndField) {
  auto neg = parse_fabric_presets(preset("-3"), "assets/fabrics.json");
  ASSERT_FALSE(neg);
  EXPECT_EQ(neg.error(), "assets/fabrics.json: muslin.shear: must be > 0, got -3");
  auto zero = parse_fabric_presets(preset("0"), "f.json");
  ASSERT_FALSE(zero);
  EXPECT_EQ(zero.error(), "f.json: muslin.shear: must be > 0, got 0");
  auto str = parse_fabric_presets(preset("\"NaN\""), "f.json");
  ASSERT_FALSE(str);
  EXPECT_EQ(str.error(), "f.json: muslin.shear: must be a number, got \"NaN\"");
  auto inf = parse_fabric_presets(preset("1e999"), "f.json");
  ASSERT_FALSE(inf);
  // nlohmann rejects out-of-range numbers while parsing: the message names the file and value.
  EXPECT_EQ(inf.error().rfind("f.json: ", 0), 0u) << inf.error();
  EXPECT_NE(inf.error().find("1e999"), std::string::npos) << inf.error();
  auto nan = parse_fabric_presets(preset("NaN"), "f.json");  // not JSON at all
  ASSERT_FALSE(nan);
  EXPECT_NE(nan.error().find("f.json: invalid JSON"), std::string::npos) << nan.error();
  auto missing = parse_fabric_presets(R"({"muslin": {"areal_density": 0.13}})", "f.json");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error(), "f.json: muslin.thickness: missing");
  auto neg_damp = parse_fabric_presets(
      preset("60").replace(preset("60").size() - 2, 0, R"(, "damping": -1)"), "f.json");
  ASSERT_FALSE(neg_damp);
  EXPECT_EQ(neg_damp.error(), "f.json: muslin.damping: must be >= 0, got -1");
  for (const std::string& s : {std::string(""), std::string("{"), std::string("[1,2]"),
                               std::string("{\"_units\": \"x\"}"), std::string("{\"a\": 3}")}) {
    auto r = parse_fabric_presets(s, "f.json");
    ASSERT_FALSE(r) << s;
    EXPECT_EQ(r.error().rfind("f.json: ", 0), 0u) << r.error();
    std::printf("%-16s -> %s\n", s.c_str(), r.error().c_str());
  }
}

TEST(Fabric, FileErrors) {
  auto none = load_fabric_presets("/nonexistent/fabrics.json");
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error(), "/nonexistent/fabrics.json: cannot open file");
  const std::string path = std::string(DRAPE_BINARY_DIR) + "/fabric_test_truncated.json";
  {
    std::ofstream out(path);
    out << preset("60").substr(0, 60);
  }
  auto trunc = load_fabric_presets(path);
  ASSERT_FALSE(trunc);
  EXPECT_EQ(trunc.error().rfind(path + ": invalid JSON", 0), 0u) << trunc.error();
  auto unknown = load_fabric(kAssets, "velvet");
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().find("no preset 'velvet'"), std::string::npos);
}
