// The project's PLY importer, through the mesh loader (load_mesh_from_memory with "ply").
#include "sim/io/ply_importer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "sim/io/mesh_io.hpp"

namespace drape::sim {
namespace {

// A property of a test file: a scalar, or a list when `count_type` is set.
struct Prop {
  std::string type, name, count_type;
};

// An element of a test file: rows[entry][property] holds a scalar's one value or a list's items.
struct Elem {
  std::string name;
  std::vector<Prop> props;
  std::vector<std::vector<std::vector<double>>> rows;
};

// One value in the binary encoding of `type` (any PLY name), little or big endian.
void put(std::string& out, const std::string& type, double v, bool big) {
  char b[8];
  size_t n = 0;
  auto store = [&](auto x) {
    n = sizeof(x);
    std::memcpy(b, &x, n);
  };
  if (type == "char" || type == "int8") store(static_cast<int8_t>(v));
  if (type == "uchar" || type == "uint8") store(static_cast<uint8_t>(v));
  if (type == "short" || type == "int16") store(static_cast<int16_t>(v));
  if (type == "ushort" || type == "uint16") store(static_cast<uint16_t>(v));
  if (type == "int" || type == "int32") store(static_cast<int32_t>(v));
  if (type == "uint" || type == "uint32") store(static_cast<uint32_t>(v));
  if (type == "float" || type == "float32") store(static_cast<float>(v));
  if (type == "double" || type == "float64") store(v);
  ASSERT_GT(n, 0u) << type;
  if (big != (std::endian::native == std::endian::big)) std::reverse(b, b + n);
  out.append(b, n);
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.9g", v);
  return buf;
}

std::string header(const std::string& format, const std::vector<Elem>& elems) {
  std::string h = "ply\nformat " + format + " 1.0\ncomment written by the test\nobj_info none\n";
  for (const Elem& e : elems) {
    h += "element " + e.name + " " + std::to_string(e.rows.size()) + "\n";
    for (const Prop& p : e.props)
      h += p.count_type.empty()
               ? "property " + p.type + " " + p.name + "\n"
               : "property list " + p.count_type + " " + p.type + " " + p.name + "\n";
  }
  return h + "end_header\n";
}

// A PLY file of `elems` in `format` (ascii, binary_little_endian or binary_big_endian).
std::string write_ply(const std::string& format, const std::vector<Elem>& elems) {
  std::string out = header(format, elems);
  const bool ascii = format == "ascii", big = format == "binary_big_endian";
  for (const Elem& e : elems)
    for (const auto& row : e.rows) {
      for (size_t p = 0; p < e.props.size(); ++p) {
        const Prop& prop = e.props[p];
        if (!prop.count_type.empty()) {
          if (ascii)
            out += std::to_string(row[p].size()) + " ";
          else
            put(out, prop.count_type, static_cast<double>(row[p].size()), big);
        }
        for (double v : row[p]) {
          if (ascii)
            out += number(v) + " ";
          else
            put(out, prop.type, v, big);
        }
      }
      if (ascii) out += "\n";
    }
  return out;
}

Elem cube_vertices(const std::string& type = "float") {
  Elem e{"vertex", {{type, "x", ""}, {type, "y", ""}, {type, "z", ""}}, {}};
  for (int i = 0; i < 8; ++i)
    e.rows.push_back({{double(i & 1)}, {double(i >> 1 & 1)}, {double(i >> 2)}});
  return e;
}

// The cube's six quads (outward, counter-clockwise).
Elem cube_faces(const std::string& count_type = "uchar", const std::string& index_type = "int") {
  Elem e{"face", {{index_type, "vertex_indices", count_type}}, {}};
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads)
    e.rows.push_back({{double(q[0]), double(q[1]), double(q[2]), double(q[3])}});
  return e;
}

Result<TriMesh> load_ply(const std::string& bytes) {
  return load_mesh_from_memory(bytes.data(), bytes.size(), "ply", "test.ply");
}

// Loading `bytes` fails with an error naming the file and containing `part` (printed).
void expect_ply_error(const std::string& bytes, const std::string& part) {
  auto m = load_ply(bytes);
  ASSERT_FALSE(m.ok()) << "loaded: " << bytes.substr(0, 200);
  std::printf("%s\n", m.error().c_str());
  EXPECT_NE(m.error().find("test.ply"), std::string::npos) << m.error();
  EXPECT_NE(m.error().find(part), std::string::npos) << m.error();
}

// The cube as loaded from `bytes`: 8 vertices at the unit cube's corners, 12 triangles.
void expect_cube(const std::string& bytes, const std::string& what) {
  auto m = load_ply(bytes);
  ASSERT_TRUE(m.ok()) << what << ": " << m.error();
  EXPECT_EQ(m->vertices.size(), 8u) << what;
  EXPECT_EQ(m->triangles.size(), 12u) << what;
  for (const Vec3& v : m->vertices)
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(v[c] == 0.0 || v[c] == 1.0) << what;
}

const char* const kFormats[] = {"ascii", "binary_little_endian", "binary_big_endian"};

TEST(PlyImporter, CubeReadsTheSameInEachFormat) {
  const std::vector<Elem> cube = {cube_vertices(), cube_faces()};
  auto first = load_ply(write_ply("ascii", cube));
  ASSERT_TRUE(first.ok()) << first.error();
  for (const char* f : kFormats) {
    const std::string bytes = write_ply(f, cube);
    expect_cube(bytes, f);
    auto m = load_ply(bytes);
    ASSERT_TRUE(m.ok()) << m.error();
    EXPECT_EQ(m->vertices, first->vertices) << f;
    EXPECT_EQ(m->triangles, first->triangles) << f;
  }
  // From disk too (load_mesh, by the extension).
  const auto path = std::filesystem::path(DRAPE_BINARY_DIR) / "test_tmp" / "ply_cube.ply";
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << write_ply("binary_big_endian", cube);
  auto d = load_mesh(path.string());
  ASSERT_TRUE(d.ok()) << d.error();
  EXPECT_EQ(d->triangles.size(), 12u);
}

// Quads and larger polygons come out as triangles (n - 2 each); points and lines are dropped.
TEST(PlyImporter, PolygonsTriangulatedPointsAndLinesDropped) {
  Elem v{"vertex", {{"float", "x", ""}, {"float", "y", ""}, {"float", "z", ""}}, {}};
  for (int i = 0; i < 5; ++i)
    v.rows.push_back({{std::cos(i * 1.2566)}, {std::sin(i * 1.2566)}, {0}});
  Elem f{"face", {{"uint", "vertex_index", "ushort"}}, {}};
  f.rows = {{{0, 1, 2, 3, 4}}, {{0, 1, 2, 3}}, {{0, 1, 2}}, {{0, 1}}, {{3}}};
  for (const char* fmt : kFormats) {
    auto m = load_ply(write_ply(fmt, {v, f}));
    ASSERT_TRUE(m.ok()) << fmt << ": " << m.error();
    EXPECT_EQ(m->triangles.size(), 3u + 2u + 1u) << fmt;
    EXPECT_EQ(m->vertices.size(), 5u) << fmt;
  }
}

// Coordinates, list counts and indices in every scalar type and alias, in each format.
TEST(PlyImporter, EveryScalarTypeForCoordinatesCountsAndIndices) {
  const char* const types[] = {"char",  "uchar",  "short",   "ushort", "int",   "uint",
                               "float", "double", "int8",    "uint8",  "int16", "uint16",
                               "int32", "uint32", "float32", "float64"};
  for (const char* fmt : kFormats)
    for (const char* t : types) {
      expect_cube(write_ply(fmt, {cube_vertices(t), cube_faces()}), std::string(fmt) + " x " + t);
      expect_cube(write_ply(fmt, {cube_vertices(), cube_faces(t, "int")}),
                  std::string(fmt) + " count " + t);
      expect_cube(write_ply(fmt, {cube_vertices(), cube_faces("uchar", t)}),
                  std::string(fmt) + " index " + t);
    }
}

// Normals and texture coordinates under each of the three naming conventions.
TEST(PlyImporter, TextureCoordinatesUnderEachName) {
  const std::pair<const char*, const char*> names[] = {
      {"s", "t"}, {"u", "v"}, {"texture_u", "texture_v"}};
  for (const auto& [u, w] : names)
    for (const char* fmt : kFormats) {
      Elem v = cube_vertices();
      v.props.push_back({"float", "nx", ""});
      v.props.push_back({"float", "ny", ""});
      v.props.push_back({"float", "nz", ""});
      v.props.push_back({"float", u, ""});
      v.props.push_back({"double", w, ""});
      for (auto& row : v.rows) {
        row.push_back({0}), row.push_back({0}), row.push_back({1});
        row.push_back({0.25 + row[0][0] * 0.5}), row.push_back({0.125 + row[1][0] * 0.5});
      }
      auto m = load_ply(write_ply(fmt, {v, cube_faces()}));
      ASSERT_TRUE(m.ok()) << m.error();
      ASSERT_EQ(m->uv.size(), m->vertices.size()) << u << " " << fmt;
      for (size_t i = 0; i < m->uv.size(); ++i) {
        EXPECT_FLOAT_EQ(m->uv[i].x(), 0.25 + m->vertices[i].x() * 0.5) << u;
        EXPECT_FLOAT_EQ(m->uv[i].y(), 0.125 + m->vertices[i].y() * 0.5) << u;
      }
    }
}

// Elements and properties the reader does not use are skipped, scalars and lists, before and
// after the ones it uses.
TEST(PlyImporter, OtherElementsAndPropertiesSkipped) {
  Elem before{
      "material", {{"uchar", "red", ""}, {"double", "shine", ""}}, {{{200}, {0.5}}, {{10}, {2}}}};
  Elem v = cube_vertices("double");
  v.props.insert(v.props.begin(), {"int", "tags", "uchar"});
  v.props.push_back({"float", "confidence", ""});
  for (auto& row : v.rows) {
    row.insert(row.begin(), std::vector<double>{7, 8, 9});
    row.push_back({0.9});
  }
  Elem f = cube_faces("uint8", "uint32");
  f.props.push_back({"uchar", "flags", ""});
  f.props.push_back({"float", "texcoord", "uchar"});
  for (auto& row : f.rows) row.push_back({1}), row.push_back({0, 0, 1, 0, 1, 1, 0, 1});
  Elem edge{"edge", {{"int", "vertex1", ""}, {"int", "vertex2", ""}}, {{{0}, {1}}, {{1}, {3}}}};
  const Elem marker{"marker", {}, std::vector<std::vector<std::vector<double>>>(5)};  // no bytes
  for (const char* fmt : kFormats) expect_cube(write_ply(fmt, {before, marker, v, f, edge}), fmt);
}

// Body errors name the element, the entry and the property.
TEST(PlyImporter, MalformedBodiesRejectedWithTheirPlace) {
  const std::string ascii = header("ascii", {cube_vertices(), cube_faces()});
  std::string verts;
  for (int i = 0; i < 8; ++i)
    verts += number(i & 1) + " " + number(i >> 1 & 1) + " " + number(i >> 2) + "\n";
  const std::string faces = "4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";
  expect_cube(ascii + verts + faces, "the plain ascii cube");
  expect_ply_error(ascii + verts.substr(0, verts.size() - 2),
                   "element \"vertex\" entry 7 of 8, property \"z\": the file ends here");
  expect_ply_error(ascii + verts + faces.substr(0, faces.size() - 6),
                   "element \"face\" entry 5 of 6, property \"vertex_indices\": a list of 4 "
                   "items, more than the file's 3 bytes left hold");
  expect_ply_error(ascii + verts + faces + "7\n",
                   "PLY body: more data than the header declares (\"7\" and after)");
  std::string bad = ascii + verts + faces;
  bad.replace(bad.find("4 0 1 5 4"), 9, "4 0 1 5 8");
  expect_ply_error(bad,
                   "entry 2 of 6, property \"vertex_indices\": vertex index 8 (item 3) is not "
                   "one of the 8 vertices");
  bad.replace(bad.find("4 0 1 5 8"), 9, "4 0 -1 5 4");
  expect_ply_error(bad, "vertex index -1 (item 1)");
  bad.replace(bad.find("4 0 -1 5 4"), 10, "4 0 1.5 5 4");
  expect_ply_error(bad, "vertex index 1.5 (item 1)");
  bad = ascii + verts + faces;
  bad.replace(bad.find("1 1 1"), 5, "1 zz 1");
  expect_ply_error(bad, "element \"vertex\" entry 7 of 8, property \"y\": \"zz\" is not a number");
  bad.replace(bad.find("1 zz 1"), 6, "1 nan 1");
  expect_ply_error(bad, "\"nan\" is not a number");
  expect_ply_error(ascii + verts + "0\n" + faces.substr(faces.find('\n') + 1),
                   "entry 0 of 6, property \"vertex_indices\": a face of no corners");
  expect_ply_error(ascii + verts + "2.5 0 1\n" + faces.substr(faces.find('\n') + 1),
                   "list count 2.5 is not a count");
  expect_ply_error(ascii + verts + "99999 0 1 2\n" + faces.substr(faces.find('\n') + 1),
                   "a list of 99999 items, more than the file's");
}

TEST(PlyImporter, MalformedBinaryBodiesRejectedBeforeAnyAllocation) {
  const std::vector<Elem> cube = {cube_vertices(), cube_faces("uint", "int")};
  const std::string le = write_ply("binary_little_endian", cube);
  expect_cube(le, "the plain binary cube");
  const size_t first_face = header("binary_little_endian", cube).size() + 8 * 12;
  // Cut inside the last vertex, its entries longer than their smallest size (a list each).
  Elem tagged = cube_vertices();
  tagged.props.insert(tagged.props.begin(), {"float", "tags", "uchar"});
  for (auto& row : tagged.rows) row.insert(row.begin(), std::vector<double>{1, 2, 3});
  const std::string cut = write_ply("binary_little_endian", {tagged, cube_faces()});
  expect_ply_error(
      cut.substr(0, header("binary_little_endian", {tagged, cube_faces()}).size() + 8 * 25 - 2),
      "element \"vertex\" entry 7 of 8, property \"z\": the file ends inside it");
  expect_ply_error(le.substr(0, le.size() - 2),
                   "entry 5 of 6, property \"vertex_indices\": a list of 4 items, more than the "
                   "file's 14 bytes left hold");
  expect_ply_error(le + '\n', "PLY body: 1 bytes more than the header declares");
  // A list count of four billion in a file of a few hundred bytes.
  std::string huge = le;
  huge.replace(first_face, 4, std::string("\x00\x28\x6b\xee", 4));  // 4 000 000 000
  expect_ply_error(huge,
                   "entry 0 of 6, property \"vertex_indices\": a list of 4000000000 items, "
                   "more than the file's");
  // An element count within the file's size, but not at its entries' smallest size.
  std::string many = le;
  many.replace(many.find("element vertex 8"), 16, "element vertex 99");
  expect_ply_error(many, "PLY body: element \"vertex\" declares 99 entries of at least 12 bytes");
  std::string big_index = write_ply("binary_big_endian", cube);
  const size_t first_be = header("binary_big_endian", cube).size() + 8 * 12;
  big_index.replace(first_be + 4, 4, std::string("\x00\x00\x01\x00", 4));  // 256
  expect_ply_error(big_index, "vertex index 256 (item 0) is not one of the 8 vertices");
}

TEST(PlyImporter, MalformedHeadersRejectedWithTheirLine) {
  const std::string body = write_ply("ascii", {cube_vertices(), cube_faces()})
                               .substr(header("ascii", {cube_vertices(), cube_faces()}).size());
  const std::string v = "element vertex 8\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string f = "element face 6\nproperty list uchar int vertex_indices\n";
  const std::string fmt = "ply\nformat ascii 1.0\n";
  const struct {
    std::string ply;
    const char* error;
  } cases[] = {
      {"ply\nformat ascii 1.0\n" + v + f, "PLY header has no end_header line"},
      {"ply\nformat ascii 1.0\n" + v + f + body, "PLY header: unknown line \"0 0 0\""},
      {"plY\nformat ascii 1.0\n" + v + f + "end_header\n" + body, "the first line is not \"ply\""},
      {fmt + "format ascii 1.0\n" + v + f + "end_header\n" + body, "is a second format line"},
      {"ply\n" + v + f + "end_header\n" + body, "no format line before end_header"},
      {"ply\nformat binary 1.0\n" + v + f + "end_header\n" + body,
       "is not \"format ascii|binary_* 1.0\""},
      {fmt + "property float w\n" + v + f + "end_header\n" + body, "comes before any element"},
      {fmt + v + "property float x\n" + f + "end_header\n" + body,
       "declares a second property \"x\""},
      {fmt + v + v + f + "end_header\n" + body, "declares a second element \"vertex\""},
      {fmt + "element vertex 8\nproperty float x\nproperty float y\n" + f + "end_header\n" + body,
       "element \"vertex\" lacks a scalar property x, y or z"},
      {fmt + v + "element face 6\nproperty list uchar int corners\nend_header\n" + body,
       "element \"face\" has no list property vertex_indices or vertex_index"},
      {fmt + v + "element face 6\nproperty int vertex_indices\nend_header\n" + body,
       "has no list property"},
      {fmt + v + "end_header\n" + body.substr(0, body.find("4 ")), "PLY: no faces"},
      {fmt + v + f + "element vertex_normals 900000\nproperty float nx\nend_header\n" + body,
       "declares more entries than the file has bytes"},
      {fmt + v + f + "\t \nend_header\n" + body, "is a line of blanks"},
      {fmt + v + f + "property list uchar half w\nend_header\n" + body,
       "is not \"property TYPE NAME\""},
  };
  for (const auto& c : cases) expect_ply_error(c.ply, c.error);
}

// Every seed of the fuzz target: the cylinder loads as before, each regression input is refused.
TEST(PlyImporter, FuzzSeedsReadOrRejectedAsBefore) {
  const auto dir = std::filesystem::path(DRAPE_SOURCE_DIR) / "fuzz" / "corpus" / "mesh_ply";
  size_t seeds = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string name = entry.path().filename().string();
    auto m = load_mesh_from_memory(bytes.data(), bytes.size(), "ply", name);
    ++seeds;
    if (name == "cyl.ply") {
      ASSERT_TRUE(m.ok()) << m.error();
      EXPECT_EQ(m->vertices.size(), 50u);
      EXPECT_EQ(m->triangles.size(), 96u);
      continue;
    }
    EXPECT_EQ(name.rfind("regress_ply_", 0), 0u) << name;
    ASSERT_FALSE(m.ok()) << name;
    std::printf("%s\n", m.error().c_str());
  }
  EXPECT_GE(seeds, 13u);
}

TEST(PlyImporter, FactoryMakesAPlyImporter) {
  auto imp = make_ply_importer();
  ASSERT_NE(imp, nullptr);
  ASSERT_NE(imp->GetInfo(), nullptr);
  EXPECT_STREQ(imp->GetInfo()->mFileExtensions, "ply");
}

}  // namespace
}  // namespace drape::sim
