// The project's OBJ importer, through the mesh loader (load_mesh_from_memory with "obj").
#include "sim/io/obj_importer.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "sim/io/mesh_io.hpp"

namespace drape::sim {
namespace {

Result<TriMesh> load_obj(const std::string& text) {
  return load_mesh_from_memory(text.data(), text.size(), "obj", "test.obj");
}

// The error of loading `text`, which must fail and contain `part` (printed).
void expect_obj_error(const std::string& text, const std::string& part) {
  auto m = load_obj(text);
  ASSERT_FALSE(m.ok()) << "loaded: " << text;
  std::printf("%s\n", m.error().c_str());
  EXPECT_NE(m.error().find("test.obj"), std::string::npos) << m.error();
  EXPECT_NE(m.error().find(part), std::string::npos) << m.error();
}

TEST(ObjImporter, QuadWithAllCornerFormsAndNegativeIndices) {
  const std::string obj =
      "# a unit quad\r\no quad\nmtllib none.mtl\nv 0 0 0\nv 1 0 0\nv +1 1 0 1\nv 0 1 0 0.5 0.5 "
      "0.5\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\ng side\ns off\nusemtl cloth\n"
      "f 1/1/1 2/2/1 -2/-2/-1 4/4\n";
  auto m = load_obj(obj);
  ASSERT_TRUE(m.ok()) << m.error();
  EXPECT_EQ(m->triangles.size(), 2u);
  EXPECT_EQ(m->vertices.size(), 4u);  // the corners merged back into the file's four vertices
  ASSERT_EQ(m->uv.size(), 4u);
  for (size_t i = 0; i < 4; ++i)  // each vertex keeps its texture coordinate (here its x, y)
    EXPECT_TRUE(m->uv[i].isApprox(m->vertices[i].head<2>())) << i;
}

TEST(ObjImporter, PointsAndLinesSkippedTrianglesKept) {
  auto m = load_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\np 1\nl 1 2\nf 1\nf 1 2\nf 1 2 3\n");
  ASSERT_TRUE(m.ok()) << m.error();
  EXPECT_EQ(m->triangles.size(), 1u);
  EXPECT_TRUE(m->uv.empty());
}

TEST(ObjImporter, ErrorsNameTheLine) {
  expect_obj_error("v 0 0 0\nv 1 zero 0\n", "OBJ line 2: \"zero\" is not a number");
  expect_obj_error("v 0 0\n", "OBJ line 1: \"v\" takes 3 to 7 numbers, not 2");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "OBJ line 4: \"0\" is not an index");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n", "OBJ line 4: a negative index");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", "has over 3 parts");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "out of range");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2 3\n", "out of range");  // no vt
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\n", "OBJ: no faces");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1e99 0 0\nf 1 2 3\n", "out of range");
}

// A mesh the loader rejects after the importer still gets the loader's checks (non-finite).
TEST(ObjImporter, LoaderChecksStillApply) {
  expect_obj_error("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "non-finite");
}

TEST(ObjImporter, FactoryMakesAnObjImporter) {
  auto imp = make_obj_importer();
  ASSERT_NE(imp, nullptr);
  ASSERT_NE(imp->GetInfo(), nullptr);
  EXPECT_STREQ(imp->GetInfo()->mFileExtensions, "obj");
}

}  // namespace
}  // namespace drape::sim
