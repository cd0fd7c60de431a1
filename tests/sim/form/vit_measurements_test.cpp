// Seamly2D / Valentina individual measurements (.vit): files written by hand to the schema
// (tests/sim/form/vit/), units, arcs instead of girths, and bad input named by file, line and
// measurement.
#include "sim/form/vit_measurements.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace drape::sim {
namespace {

const std::string kDir = std::string(DRAPE_SOURCE_DIR) + "/tests/sim/form/vit/";

// A minimal document around the given <m> lines.
std::string vit(const std::string& unit, const std::string& ms) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<vit>\n<version>0.3.3</version>\n"
         "<read-only>false</read-only>\n<unit>" +
         unit + "</unit>\n<pm_system>998</pm_system>\n<body-measurements>\n" + ms +
         "</body-measurements>\n</vit>\n";
}
const char* kAll =
    "<m name=\"height\" value=\"158\"/>\n<m name=\"height_neck_back\" value=\"134\"/>\n"
    "<m name=\"height_bust\" value=\"115\"/>\n<m name=\"height_waist_side\" value=\"97\"/>\n"
    "<m name=\"height_hip\" value=\"78\"/>\n<m name=\"bust_circ\" value=\"83\"/>\n"
    "<m name=\"waist_circ\" value=\"64\"/>\n<m name=\"hip_circ\" value=\"91\"/>\n";

TEST(VitMeasurements, NineArInCentimetresGivesTheNineArForm) {
  auto m = load_vit(kDir + "nine_ar_cm.vit");
  ASSERT_TRUE(m.ok()) << m.error();
  auto ref = measurements_for_size("9AR");
  ASSERT_TRUE(ref.ok());
  EXPECT_EQ(m->size, "Nine AR");
  EXPECT_NEAR(m->bust_girth, ref->bust_girth, 1e-12);
  EXPECT_NEAR(m->waist_girth, ref->waist_girth, 1e-12);
  EXPECT_NEAR(m->hip_girth, ref->hip_girth, 1e-12);
  EXPECT_NEAR(m->height, ref->height, 1e-12);
  EXPECT_NEAR(m->bust_height, ref->bust_height, 1e-12);
  EXPECT_NEAR(m->waist_height, ref->waist_height, 1e-12);
  EXPECT_NEAR(m->hip_height, ref->hip_height, 1e-12);
  EXPECT_NEAR(m->neck_height, ref->neck_height, 1e-12);
  EXPECT_NEAR(m->bottom_height, ref->bottom_height, 1e-12);
  // The form built from it measures what the file says.
  auto f = DressForm::from_measurements(*m);
  ASSERT_TRUE(f.ok()) << f.error();
  EXPECT_NEAR(f->girth_at(f->landmarks().bust_y), 0.83, 2e-3);
  EXPECT_NEAR(f->girth_at(f->landmarks().waist_y), 0.64, 2e-3);
  EXPECT_NEAR(f->girth_at(f->landmarks().hip_y), 0.91, 2e-3);
}

TEST(VitMeasurements, ArcsInInchesAreSummedAndConverted) {
  auto m = load_vit(kDir + "arcs_inch.vit");
  ASSERT_TRUE(m.ok()) << m.error();
  EXPECT_EQ(m->size, "arcs_inch");  // no customer name: the file's name
  EXPECT_NEAR(m->bust_girth, (18.5 + 16.5) * 0.0254, 1e-12);
  EXPECT_NEAR(m->waist_girth, (13.75 + 13.25) * 0.0254, 1e-12);
  EXPECT_NEAR(m->hip_girth, (18.5 + 19.5) * 0.0254, 1e-12);
  EXPECT_NEAR(m->waist_height, 39 * 0.0254, 1e-12);            // height_waist_front
  EXPECT_NEAR(m->neck_height, 53.5 * 0.0254, 1e-12);           // height_neck_side
  EXPECT_NEAR(m->bottom_height, 31.5 * 0.0254 - 0.18, 1e-12);  // no gluteal fold: hip - 18 cm
  EXPECT_TRUE(DressForm::from_measurements(*m).ok());
}

TEST(VitMeasurements, MissingMeasurementsAreAllNamed) {
  auto m = load_vit(kDir + "missing.vit");
  ASSERT_FALSE(m.ok());
  std::printf("%s\n", m.error().c_str());
  const std::string& e = m.error();
  EXPECT_NE(e.find("missing.vit: the form needs measurements the file lacks"), std::string::npos);
  // waist_arc_f alone is not a girth: the back arc is missing too.
  for (const char* what : {"waist girth (waist_circ or waist_arc_f+waist_arc_b)",
                           "bust height (height_bust)", "hip height (height_hip)",
                           "neck height (height_neck_side or height_neck_back or "
                           "height_neck_front)"})
    EXPECT_NE(e.find(what), std::string::npos) << what;
  for (const char* given : {"bust girth", "hip girth (", "; height (", "waist height"})
    EXPECT_EQ(e.find(given), std::string::npos) << given;
}

TEST(VitMeasurements, MalformedXmlNamesFileAndLine) {
  auto m = load_vit(kDir + "malformed.vit");
  ASSERT_FALSE(m.ok());
  std::printf("%s\n", m.error().c_str());
  EXPECT_NE(m.error().find("malformed.vit:9: malformed XML: mismatched tag"), std::string::npos);
  auto t = parse_vit("<vit><unit>cm</unit>", "cut.vit");
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.error().find("cut.vit:1: malformed XML"), std::string::npos) << t.error();
  EXPECT_FALSE(parse_vit("", "empty.vit").ok());
  EXPECT_FALSE(load_vit(kDir + "no_such_file.vit").ok());
}

TEST(VitMeasurements, BadValuesAndDocumentsAreNamed) {
  ASSERT_TRUE(parse_vit(vit("cm", kAll), "ok.vit").ok());
  {  // a formula (Valentina allows them): refused, naming the measurement and its line
    std::string ms = kAll;
    ms.replace(ms.find("value=\"64\""), 10, "value=\"bust_circ - 19\"");
    auto m = parse_vit(vit("cm", ms), "formula.vit");
    ASSERT_FALSE(m.ok());
    std::printf("%s\n", m.error().c_str());
    EXPECT_NE(m.error().find("formula.vit:14: measurement 'waist_circ': value 'bust_circ - 19' "
                             "is not a number"),
              std::string::npos)
        << m.error();
  }
  {
    auto m = parse_vit(vit("furlong", kAll), "unit.vit");
    ASSERT_FALSE(m.ok());
    EXPECT_NE(m.error().find("unit.vit:5: <unit> 'furlong' unknown"), std::string::npos)
        << m.error();
  }
  {
    auto m = parse_vit(vit("cm", std::string(kAll) + "<m name=\"height\" value=\"160\"/>\n"),
                       "twice.vit");
    ASSERT_FALSE(m.ok());
    EXPECT_NE(m.error().find("twice.vit:16: measurement 'height' given twice (first on line 8)"),
              std::string::npos)
        << m.error();
  }
  {  // values read in the wrong unit fail the form's own range checks, named by field
    auto m = parse_vit(vit("mm", kAll), "mm.vit");
    ASSERT_FALSE(m.ok());
    std::printf("%s\n", m.error().c_str());
    EXPECT_NE(m.error().find("mm.vit"), std::string::npos);
    EXPECT_NE(m.error().find("bust_girth"), std::string::npos) << m.error();
  }
  {
    auto m = parse_vit("<vst><unit>cm</unit></vst>", "table.vst");
    ASSERT_FALSE(m.ok());
    EXPECT_NE(m.error().find("root element is <vst>"), std::string::npos) << m.error();
  }
}

}  // namespace
}  // namespace drape::sim
