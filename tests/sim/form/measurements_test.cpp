// Measurement JSON: the standard sizes and bad input (errors name the file and field).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "sim/form/dress_form.hpp"

namespace drape::sim {
namespace {

std::string tmp_file(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::path(DRAPE_BINARY_DIR) / "test_tmp" / "measurements";
  std::filesystem::create_directories(dir);
  const auto p = dir / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

const char* kGood = R"({"size": "X", "bust_girth": 0.83, "waist_girth": 0.64, "hip_girth": 0.91,
  "height": 1.58, "bust_height": 1.15, "waist_height": 0.97, "hip_height": 0.78,
  "neck_height": 1.34, "bottom_height": 0.60})";

TEST(Measurements, StandardSizesMatchReadme) {
  // JIS L 4005 bust / hip and the usual form waist (cm).
  struct Row {
    const char* size;
    double bust, waist, hip;
  };
  for (const Row& r : {Row{"7AR", 80, 61, 87}, Row{"9AR", 83, 64, 91}, Row{"11AR", 86, 67, 93},
                       Row{"13AR", 89, 70, 95}}) {
    const std::string path = std::string(DRAPE_SOURCE_DIR) + "/assets/forms/" + r.size + ".json";
    auto f = load_measurements(path);
    ASSERT_TRUE(f.ok()) << f.error();
    EXPECT_EQ(f->size, r.size);
    EXPECT_NEAR(f->bust_girth, r.bust / 100, 1e-12);
    EXPECT_NEAR(f->waist_girth, r.waist / 100, 1e-12);
    EXPECT_NEAR(f->hip_girth, r.hip / 100, 1e-12);
    EXPECT_NEAR(f->height, 1.58, 1e-12);
    // measurements_for_size (the file in the forms directory, or the built-in copy without
    // one) gives the same.
    for (const std::string& dir :
         {std::string(DRAPE_SOURCE_DIR) + "/assets/forms", std::string()}) {
      auto s = measurements_for_size(r.size, dir);
      ASSERT_TRUE(s.ok()) << s.error();
      using M = FormMeasurements;
      for (double M::*field :
           {&M::bust_girth, &M::waist_girth, &M::hip_girth, &M::height, &M::bust_height,
            &M::waist_height, &M::hip_height, &M::neck_height, &M::bottom_height, &M::bust_aspect,
            &M::waist_aspect, &M::hip_aspect})
        EXPECT_EQ((*s).*field, (*f).*field) << dir;
    }
  }
  auto bad = measurements_for_size("99XL");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().find("99XL"), std::string::npos);
}

TEST(Measurements, GoodFileParses) {
  auto m = load_measurements(tmp_file("good.json", kGood));
  ASSERT_TRUE(m.ok()) << m.error();
  EXPECT_EQ(m->size, "X");
  EXPECT_DOUBLE_EQ(m->hip_height, 0.78);
  EXPECT_DOUBLE_EQ(m->hip_aspect, 1.4);  // optional field: default
}

void expect_error(const std::string& name, const std::string& text, const std::string& field) {
  const std::string path = tmp_file(name, text);
  auto m = load_measurements(path);
  ASSERT_FALSE(m.ok()) << name;
  std::printf("%s -> %s\n", name.c_str(), m.error().c_str());
  EXPECT_NE(m.error().find(path), std::string::npos) << m.error();
  if (!field.empty()) {
    EXPECT_NE(m.error().find(field), std::string::npos) << m.error();
  }
}

std::string replace(std::string s, const std::string& a, const std::string& b) {
  const auto p = s.find(a);
  EXPECT_NE(p, std::string::npos) << a;
  return s.replace(p, a.size(), b);
}

TEST(Measurements, BadFieldsNamed) {
  const std::string g = kGood;
  expect_error("missing.json", replace(g, R"("waist_girth": 0.64,)", ""), "waist_girth");
  expect_error("string.json", replace(g, "0.91", R"("91cm")"), "hip_girth");
  expect_error("null.json", replace(g, "0.91", "null"), "hip_girth");
  expect_error("negative.json", replace(g, "1.15", "-1.15"), "bust_height");
  expect_error("nan.json", replace(g, "0.83", "NaN"), "");  // not JSON at all
  expect_error("inf.json", replace(g, "0.83", "1e999"), "1e999");
  expect_error("cm.json", replace(g, "0.83", "83"), "bust_girth");  // centimetres, not metres
  expect_error("order.json", replace(g, R"("waist_height": 0.97)", R"("waist_height": 1.20)"),
               "bust_height");
  expect_error("order2.json", replace(g, R"("hip_height": 0.78)", R"("hip_height": 0.99)"),
               "waist_height");
  expect_error("neck.json", replace(g, "1.34", "1.10"), "neck_height");
  expect_error("aspect.json", replace(g, "}", R"(, "hip_aspect": "wide"})"), "hip_aspect");
  expect_error("size.json", replace(g, R"("X")", "7"), "size");
  expect_error("typo.json", replace(g, "}", R"(, "hip_aspekt": 1.4})"), "hip_aspekt");
  expect_error("array.json", "[1, 2, 3]", "");
  expect_error("truncated.json", g.substr(0, g.size() / 2), "");
  expect_error("empty.json", "", "empty");
  auto missing = load_measurements("/nonexistent/dir/form.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("/nonexistent/dir/form.json"), std::string::npos);
}

TEST(Measurements, FromMeasurementsRejectsBadStruct) {
  FormMeasurements m;
  m.waist_girth = -0.6;
  auto f = DressForm::from_measurements(m);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.error().find("waist_girth"), std::string::npos) << f.error();
  FormMeasurements ok;
  EXPECT_FALSE(DressForm::from_measurements(ok, 0.0).ok());
  EXPECT_FALSE(DressForm::from_measurements(ok, std::nan("")).ok());
}

}  // namespace
}  // namespace drape::sim
