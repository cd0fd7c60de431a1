// Dress form from mesh files: known shapes written as OBJ / PLY / STL / glTF in several units
// and up axes, read back through assimp and resampled by ray casting; girths vs the analytic
// ellipse perimeter (Ramanujan II). Bad input gives a clear error naming the file.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "sim/form/dress_form.hpp"
#include "sim/io/mesh_io.hpp"

namespace drape::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
using Units = MeshImportOptions::Units;
using Up = MeshImportOptions::UpAxis;

double ramanujan2(double a, double b) {
  const double h = (a - b) * (a - b) / ((a + b) * (a + b));
  return kPi * (a + b) * (1 + 3 * h / (10 + std::sqrt(4 - 3 * h)));
}

std::filesystem::path tmp_dir() {
  const auto dir = std::filesystem::path(DRAPE_BINARY_DIR) / "test_tmp" / "form_mesh";
  std::filesystem::create_directories(dir);
  return dir;
}

// Shapes in stage convention (y up, metres), semi-axes a along x, b along z.
TriMesh elliptic_cylinder(double a, double b, double y0, double y1, int nseg, int nrings) {
  TriMesh m;
  for (int i = 0; i <= nrings; ++i) {
    const double y = y0 + (y1 - y0) * i / nrings;
    for (int k = 0; k < nseg; ++k) {
      const double t = 2 * kPi * k / nseg;
      m.vertices.emplace_back(a * std::sin(t), y, b * std::cos(t));
    }
  }
  for (int i = 0; i < nrings; ++i)
    for (int k = 0; k < nseg; ++k) {
      const int p = i * nseg + k, q = i * nseg + (k + 1) % nseg;
      m.triangles.push_back({p, q, q + nseg});
      m.triangles.push_back({p, q + nseg, p + nseg});
    }
  const int bc = static_cast<int>(m.vertices.size());
  m.vertices.emplace_back(0, y0, 0);
  m.vertices.emplace_back(0, y1, 0);
  for (int k = 0; k < nseg; ++k) {
    m.triangles.push_back({bc, (k + 1) % nseg, k});
    m.triangles.push_back({bc + 1, nrings * nseg + k, nrings * nseg + (k + 1) % nseg});
  }
  return m;
}

TriMesh ellipsoid(double a, double c, double b, double yc, int nseg, int nstack) {
  TriMesh m;  // semi-axes a (x), c (y, vertical), b (z)
  m.vertices.emplace_back(0, yc - c, 0);
  for (int i = 1; i < nstack; ++i) {
    const double phi = -kPi / 2 + kPi * i / nstack;
    for (int k = 0; k < nseg; ++k) {
      const double t = 2 * kPi * k / nseg;
      m.vertices.emplace_back(a * std::cos(phi) * std::sin(t), yc + c * std::sin(phi),
                              b * std::cos(phi) * std::cos(t));
    }
  }
  m.vertices.emplace_back(0, yc + c, 0);
  const int top = static_cast<int>(m.vertices.size()) - 1;
  auto id = [&](int i, int k) { return 1 + (i - 1) * nseg + (k % nseg); };
  for (int k = 0; k < nseg; ++k) m.triangles.push_back({0, id(1, k + 1), id(1, k)});
  for (int i = 1; i + 1 < nstack; ++i)
    for (int k = 0; k < nseg; ++k) {
      m.triangles.push_back({id(i, k), id(i, k + 1), id(i + 1, k + 1)});
      m.triangles.push_back({id(i, k), id(i + 1, k + 1), id(i + 1, k)});
    }
  for (int k = 0; k < nseg; ++k)
    m.triangles.push_back({top, id(nstack - 1, k), id(nstack - 1, k + 1)});
  return m;
}

// Stage frame (y up, m) -> file frame: units and up axis.
TriMesh to_file_frame(TriMesh m, double per_metre, Up up) {
  for (Vec3& v : m.vertices) {
    Vec3 p = v * per_metre;
    switch (up) {
      case Up::kZ:
        v = Vec3(p.x(), -p.z(), p.y());
        break;  // file z = stage y
      case Up::kX:
        v = Vec3(p.y(), -p.x(), p.z());
        break;  // file x = stage y
      case Up::kNegY:
        v = Vec3(p.x(), -p.y(), -p.z());
        break;
      case Up::kNegZ:
        v = Vec3(p.x(), p.z(), -p.y());
        break;
      default:
        v = p;
        break;
    }
  }
  return m;
}

void write_obj(const std::string& path, const TriMesh& m) {
  std::ofstream f(path);
  f.precision(10);
  for (const Vec3& v : m.vertices) f << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (const auto& t : m.triangles)
    f << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
}

void write_ply_ascii(const std::string& path, const TriMesh& m) {
  std::ofstream f(path);
  f.precision(10);
  f << "ply\nformat ascii 1.0\nelement vertex " << m.vertices.size()
    << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << m.triangles.size()
    << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3& v : m.vertices) f << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (const auto& t : m.triangles) f << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
}

void write_stl_binary(const std::string& path, const TriMesh& m) {
  std::ofstream f(path, std::ios::binary);
  char header[80] = {};
  std::snprintf(header, sizeof header, "drape test solid");
  f.write(header, 80);
  const uint32_t n = static_cast<uint32_t>(m.triangles.size());
  f.write(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : m.triangles) {
    const Vec3 nn = (m.vertices[t[1]] - m.vertices[t[0]])
                        .cross(m.vertices[t[2]] - m.vertices[t[0]])
                        .normalized();
    float buf[12];
    for (int c = 0; c < 3; ++c) buf[c] = static_cast<float>(nn[c]);
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) buf[3 + 3 * k + c] = static_cast<float>(m.vertices[t[k]][c]);
    f.write(reinterpret_cast<const char*>(buf), sizeof buf);
    const uint16_t attr = 0;
    f.write(reinterpret_cast<const char*>(&attr), 2);
  }
}

std::string write_as(const std::string& name, const TriMesh& m) {
  const std::string path = (tmp_dir() / name).string();
  const std::string ext = std::filesystem::path(name).extension().string();
  if (ext == ".obj")
    write_obj(path, m);
  else if (ext == ".ply")
    write_ply_ascii(path, m);
  else if (ext == ".stl")
    write_stl_binary(path, m);
  else
    EXPECT_EQ(write_meshes(path, {m}), "");
  return path;
}

struct Case {
  const char* file;
  double per_metre;  // file units per metre
  Up up;
  Units units;  // kAuto: detect
  Up up_flag;   // kAuto: detect
};

TEST(FormMesh, EllipticCylinderAllFormatsUnitsAxes) {
  const double a = 0.16, b = 0.12;  // width/depth 1.33
  const TriMesh shape = elliptic_cylinder(a, b, 0.0, 0.8, 256, 8);
  const double expect = ramanujan2(a, b);
  const Case cases[] = {
      {"cyl_m_y.obj", 1.0, Up::kY, Units::kAuto, Up::kAuto},
      {"cyl_cm_z.obj", 100.0, Up::kZ, Units::kAuto, Up::kAuto},
      {"cyl_mm_z.ply", 1000.0, Up::kZ, Units::kAuto, Up::kAuto},
      {"cyl_in_y.stl", 1 / 0.0254, Up::kY, Units::kAuto, Up::kAuto},
      {"cyl_m_x.gltf", 1.0, Up::kX, Units::kAuto, Up::kAuto},
      {"cyl_cm_negz.glb", 100.0, Up::kNegZ, Units::kCentimetres, Up::kNegZ},
      {"cyl_mm_negy.stl", 1000.0, Up::kNegY, Units::kMillimetres, Up::kNegY},
      {"cyl_m_z_flags.ply", 1.0, Up::kZ, Units::kMetres, Up::kZ},
  };
  for (const Case& c : cases) {
    const std::string path = write_as(c.file, to_file_frame(shape, c.per_metre, c.up));
    MeshImportOptions opt;
    opt.units = c.units;
    opt.up = c.up_flag;
    opt.section_spacing = 0.01;
    opt.bottom_y = 0.5;
    MeshImportInfo info;
    auto mesh = load_mesh(path);
    ASSERT_TRUE(mesh.ok()) << mesh.error();
    auto f = DressForm::from_triangles(*mesh, opt, path, &info);
    ASSERT_TRUE(f.ok()) << c.file << ": " << f.error();
    EXPECT_NEAR(info.scale * c.per_metre, 1.0, 1e-9) << c.file;
    EXPECT_NEAR(f->min_y(), 0.505, 1e-6) << c.file;
    double worst = 0;
    for (double y : {0.6, 0.9, 1.2}) {
      const double g = f->girth_at(y);
      worst = std::max(worst, std::abs(g / expect - 1));
    }
    std::printf(
        "%-20s units %-2s up %-2s: girth %.2f mm vs %.2f mm (worst rel err %.4f %%), "
        "r(front) %.4f r(side) %.4f\n",
        c.file, info.units.c_str(), info.up.c_str(), f->girth_at(0.9) * 1e3, expect * 1e3,
        worst * 100, f->radius_at(0.9, 0), f->radius_at(0.9, kPi / 2));
    EXPECT_LT(worst, 0.005) << c.file;
    // The depth axis ends up along z (front-back), the width along x.
    EXPECT_NEAR(f->radius_at(0.9, 0), b, 0.002) << c.file;
    EXPECT_NEAR(f->radius_at(0.9, kPi / 2), a, 0.002) << c.file;
    // Sections are centred on the axis.
    EXPECT_LT(f->centre_at(0.9).norm(), 1e-3) << c.file;
  }
}

TEST(FormMesh, EllipsoidGirthAtHeights) {
  const double a = 0.17, b = 0.125, c = 0.36;
  const TriMesh shape = ellipsoid(a, c, b, 0.0, 256, 160);
  const Case cases[] = {
      {"ell_m_y.obj", 1.0, Up::kY, Units::kAuto, Up::kAuto},
      {"ell_mm_z.stl", 1000.0, Up::kZ, Units::kAuto, Up::kAuto},
      {"ell_cm_x.ply", 100.0, Up::kX, Units::kAuto, Up::kAuto},
      {"ell_in_z.glb", 1 / 0.0254, Up::kZ, Units::kInches, Up::kZ},
  };
  for (const Case& cs : cases) {
    const std::string path = write_as(cs.file, to_file_frame(shape, cs.per_metre, cs.up));
    MeshImportOptions opt;
    opt.units = cs.units;
    opt.up = cs.up_flag;
    opt.section_spacing = 0.005;
    MeshImportInfo info;
    auto mesh = load_mesh(path);
    ASSERT_TRUE(mesh.ok()) << mesh.error();
    auto f = DressForm::from_triangles(*mesh, opt, path, &info);
    ASSERT_TRUE(f.ok()) << cs.file << ": " << f.error();
    // Centred at the origin in the file: below the floor, so the bottom goes to 0.60 m.
    EXPECT_NEAR(info.lift, 0.60 + c, 1e-5) << cs.file;
    const double yc = 0.60 + c;
    double worst = 0;
    for (double s : {-0.6, -0.3, 0.0, 0.3, 0.6}) {
      const double k = std::sqrt(1 - s * s);
      const double expect = ramanujan2(a * k, b * k);
      const double g = f->girth_at(yc + s * c);
      worst = std::max(worst, std::abs(g / expect - 1));
      if (s == 0.0)
        std::printf("%-14s units %-2s up %-2s: equator girth %.2f mm vs %.2f mm\n", cs.file,
                    info.units.c_str(), info.up.c_str(), g * 1e3, expect * 1e3);
    }
    std::printf("%-14s worst relative girth error over 5 heights: %.4f %%\n", cs.file, worst * 100);
    EXPECT_LT(worst, 0.005) << cs.file;
  }
}

TEST(FormMesh, ParametricFormRoundTripDetectsFrontAndUp) {
  // The 9AR form exported, rotated 70 deg about the vertical, turned z-up in cm: the import
  // must detect units, up axis and centre front (bust forward, seat back) and give back the
  // same girths and the same front/back radii.
  auto src = DressForm::from_measurements(FormMeasurements{}, 0.005);
  ASSERT_TRUE(src.ok());
  TriMesh m = src->to_mesh();
  const double ang = 70 * kPi / 180;
  for (Vec3& v : m.vertices) {
    const double x = std::cos(ang) * v.x() + std::sin(ang) * v.z();
    const double z = -std::sin(ang) * v.x() + std::cos(ang) * v.z();
    v = Vec3(x, v.y(), z);
  }
  const std::string path = write_as("form9ar_cm_z.ply", to_file_frame(m, 100.0, Up::kZ));
  MeshImportInfo info;
  MeshImportOptions opt;
  opt.section_spacing = 0.005;
  auto mesh = load_mesh(path);
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  auto f = DressForm::from_triangles(*mesh, opt, path, &info);
  ASSERT_TRUE(f.ok()) << f.error();
  EXPECT_EQ(info.units, "cm");
  EXPECT_EQ(info.up, "+z");
  EXPECT_TRUE(info.front_detected);
  const auto& lm = src->landmarks();
  for (double y : {lm.hip_y, lm.waist_y, lm.bust_y}) {
    const double g0 = src->girth_at(y), g1 = f->girth_at(y);
    std::printf(
        "y %.3f: source %.2f mm, imported %.2f mm (%.3f %%); r(front) %.4f / %.4f "
        "r(back) %.4f / %.4f\n",
        y, g0 * 1e3, g1 * 1e3, 100 * (g1 / g0 - 1), src->radius_at(y, 0), f->radius_at(y, 0),
        src->radius_at(y, kPi), f->radius_at(y, kPi));
    EXPECT_NEAR(g1 / g0, 1.0, 0.005);
  }
  // Front really at +z: the bust is ahead of the section centre more than the back is behind.
  const double zf = f->surface_at(lm.bust_y, 0).z(), zb = f->surface_at(lm.bust_y, kPi).z();
  const double zf0 = src->surface_at(lm.bust_y, 0).z(), zb0 = src->surface_at(lm.bust_y, kPi).z();
  EXPECT_NEAR(zf - zb, zf0 - zb0, 0.004);
  EXPECT_NEAR(f->radius_at(lm.bust_y, kPi / 2), src->radius_at(lm.bust_y, kPi / 2), 0.003);
  // Detected landmarks near the parametric ones.
  std::printf("detected: hip %.3f waist %.3f bust %.3f (parametric %.3f %.3f %.3f)\n",
              f->landmarks().hip_y, f->landmarks().waist_y, f->landmarks().bust_y, lm.hip_y,
              lm.waist_y, lm.bust_y);
  EXPECT_NEAR(f->landmarks().waist_y, lm.waist_y, 0.03);
  EXPECT_NEAR(f->landmarks().bust_y, lm.bust_y, 0.04);
  // The bodice's armpit and shoulder heights, in the parametric form's proportions between the
  // detected bust and the top (the neck).
  EXPECT_NEAR(f->landmarks().armpit_y, lm.armpit_y, 0.04);
  EXPECT_NEAR(f->landmarks().shoulder_y, lm.shoulder_y, 0.03);
  EXPECT_GT(f->landmarks().shoulder_y, f->landmarks().armpit_y);
  // Above the floor in the file (z from 60 cm): height kept.
  EXPECT_NEAR(info.lift, 0.0, 1e-12);
  EXPECT_NEAR(f->min_y(), src->min_y() + 0.0025, 1e-4);
}

TEST(FormMesh, LargeMeshConvertsQuickly) {
  const TriMesh shape = ellipsoid(0.17, 0.37, 0.13, 0.97, 320, 160);  // ~100k triangles
  ASSERT_GT(shape.triangles.size(), 100000u);
  const auto t0 = std::chrono::steady_clock::now();
  auto f = DressForm::from_triangles(shape, MeshImportOptions{}, "large");
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(f.ok()) << f.error();
  std::printf("%zu triangles -> %d sections x 256 rays in %.1f ms\n", shape.triangles.size(),
              f->num_sections(), ms);
  EXPECT_NEAR(f->girth_at(0.97), ramanujan2(0.17, 0.13), 0.005 * ramanujan2(0.17, 0.13));
}

void expect_form_error(const std::string& path, const char* what) {
  auto f = form_from_mesh_file(path);
  ASSERT_FALSE(f.ok()) << what;
  std::printf("%s -> %s\n", what, f.error().c_str());
  EXPECT_NE(f.error().find(path), std::string::npos) << f.error();
}

TEST(FormMesh, BadInput) {
  auto write = [](const std::string& name, const std::string& text) {
    const std::string p = (tmp_dir() / name).string();
    std::ofstream(p, std::ios::binary) << text;
    return p;
  };
  expect_form_error(write("empty.stl", ""), "empty file");
  expect_form_error(write("words.obj", "Dear reader,\nthis is a letter, not a mesh.\n"),
                    "text, not a mesh");
  expect_form_error((tmp_dir() / "missing.ply").string(), "missing file");
  // Truncated binary STL and PLY.
  const TriMesh cyl = elliptic_cylinder(0.15, 0.11, 0, 0.8, 64, 4);
  const std::string stl = write_as("full.stl", cyl);
  {
    std::ifstream in(stl, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    expect_form_error(write("truncated.stl", bytes.substr(0, bytes.size() / 3)), "truncated stl");
  }
  const std::string glb = write_as("full.glb", cyl);
  {
    std::ifstream in(glb, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    expect_form_error(write("truncated.glb", bytes.substr(0, bytes.size() - 100)), "truncated glb");
  }
  // A flat plane (vertical and horizontal): rays miss.
  TriMesh plane;
  plane.vertices = {Vec3(-0.3, 0, 0), Vec3(0.3, 0, 0), Vec3(0.3, 1.0, 0), Vec3(-0.3, 1.0, 0)};
  plane.triangles = {{0, 1, 2}, {0, 2, 3}};
  expect_form_error(write_as("vplane.obj", plane), "vertical plane");
  TriMesh hplane;
  hplane.vertices = {Vec3(-0.5, 0.8, -0.5), Vec3(0.5, 0.8, -0.5), Vec3(0.5, 0.8, 0.5),
                     Vec3(-0.5, 0.8, 0.5)};
  hplane.triangles = {{0, 1, 2}, {0, 2, 3}};
  expect_form_error(write_as("hplane.obj", hplane), "horizontal plane");
  // An open half cylinder: rays toward the open side miss.
  TriMesh half = elliptic_cylinder(0.15, 0.11, 0, 0.8, 64, 4);
  std::vector<std::array<int32_t, 3>> kept;
  for (const auto& t : half.triangles) {
    bool front = true;
    for (int32_t i : t) front = front && half.vertices[i].z() > -1e-9 && t[0] < 5 * 64;
    if (front) kept.push_back(t);
  }
  half.triangles = kept;
  expect_form_error(write_as("half.obj", half), "open half cylinder");
  // A tiny object in metres cannot be a torso: units undetectable.
  expect_form_error(write_as("tiny.obj", elliptic_cylinder(0.01, 0.01, 0, 0.05, 16, 1)),
                    "undetectable units");
}

}  // namespace
}  // namespace drape::sim
