// `drape form`: build a dress form (standard size, measurement JSON or mesh) and report its
// girths and landmarks, or export it as a mesh.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include "sim/form/dress_form.hpp"
#include "sim/form/vit_measurements.hpp"
#include "sim/io/mesh_io.hpp"
#include "xr_app/command.hpp"
#include "xr_app/paths.hpp"

namespace {

using drape::sim::DressForm;
using drape::sim::MeshImportOptions;

bool parse_units(const std::string& s, MeshImportOptions::Units& u) {
  using U = MeshImportOptions::Units;
  if (s == "m")
    u = U::kMetres;
  else if (s == "cm")
    u = U::kCentimetres;
  else if (s == "mm")
    u = U::kMillimetres;
  else if (s == "in")
    u = U::kInches;
  else if (s == "auto")
    u = U::kAuto;
  else
    return false;
  return true;
}

bool parse_up(const std::string& s, MeshImportOptions::UpAxis& u) {
  using U = MeshImportOptions::UpAxis;
  if (s == "y" || s == "+y")
    u = U::kY;
  else if (s == "z" || s == "+z")
    u = U::kZ;
  else if (s == "x" || s == "+x")
    u = U::kX;
  else if (s == "-y")
    u = U::kNegY;
  else if (s == "-z")
    u = U::kNegZ;
  else if (s == "-x")
    u = U::kNegX;
  else if (s == "auto")
    u = U::kAuto;
  else
    return false;
  return true;
}

bool parse_front(const std::string& s, drape::sim::Vec3& f) {
  if (s == "z" || s == "+z")
    f = {0, 0, 1};
  else if (s == "-z")
    f = {0, 0, -1};
  else if (s == "x" || s == "+x")
    f = {1, 0, 0};
  else if (s == "-x")
    f = {-1, 0, 0};
  else
    return false;
  return true;
}

int run(int argc, char** argv) {
  std::string size, measurements, mesh, vit, export_path, units, up, front;
  bool report = false;
  double spacing = 0.0025;
  MeshImportOptions opt;
  CLI::App cli{
      "Builds the dress form (default: the 9AR form) and prints its girths at bust, waist and\n"
      "hip in mm and the landmark heights (--report, the default), or writes it as a mesh.",
      "drape form"};
  cli.option_defaults()->always_capture_default();
  auto* o_size =
      cli.add_option("--size", size, "standard size: 7AR, 9AR, 11AR or 13AR (default 9AR)")
          ->type_name("SIZE");
  auto* o_meas =
      cli.add_option("--measurements", measurements, "measurements JSON (docs/dress-form.md)")
          ->type_name("FILE.json");
  auto* o_mesh = cli.add_option("--mesh", mesh, "a scanned or modelled form (glTF, OBJ, ...)")
                     ->type_name("FILE");
  auto* o_vit = cli.add_option("--vit", vit,
                               "Seamly2D/Valentina individual measurements (docs/dress-form.md)")
                    ->type_name("FILE.vit");
  o_size->excludes(o_meas)->excludes(o_mesh)->excludes(o_vit);
  o_meas->excludes(o_mesh)->excludes(o_vit);
  o_mesh->excludes(o_vit);
  cli.add_option("--units", units, "--mesh: the file's units (default: detected)")
      ->check(CLI::IsMember({"m", "cm", "mm", "in", "auto"}));
  cli.add_option("--up", up, "--mesh: the file's up axis (default: detected)")
      ->check(CLI::IsMember({"y", "+y", "z", "+z", "x", "+x", "-y", "-z", "-x", "auto"}));
  cli.add_option("--front", front, "--mesh: the centre front axis (default: detected)")
      ->check(CLI::IsMember({"z", "+z", "-z", "x", "+x", "-x"}));
  cli.add_option("--spacing", spacing, "section spacing in metres")
      ->check(CLI::Range(0.0005, 0.05));
  cli.add_flag("--report", report, "print girths and landmarks (the default without --export)");
  cli.add_option("--export", export_path, "write the form as a mesh")
      ->type_name("FILE.gltf|.glb|.obj");
  if (int rc = drape::app::parse_command_line(cli, argc, argv); rc >= 0) return rc;
  if (!units.empty()) parse_units(units, opt.units);
  if (!up.empty()) parse_up(up, opt.up);
  if (!front.empty()) {
    parse_front(front, opt.front_axis);
    opt.front_auto = false;
  }
  if (size.empty() && measurements.empty() && mesh.empty() && vit.empty()) size = "9AR";
  if (export_path.empty()) report = true;

  drape::sim::Result<DressForm> form = drape::sim::Error{"no form"};
  drape::sim::MeshImportInfo info;
  std::string what;
  if (!mesh.empty()) {
    opt.section_spacing = spacing;
    auto m = drape::sim::load_mesh(mesh);
    if (!m) {
      std::fprintf(stderr, "drape form: %s\n", m.error().c_str());
      return 1;
    }
    form = DressForm::from_triangles(*m, opt, mesh, &info);
    what = "mesh " + mesh;
  } else {
    auto meas = !vit.empty() ? drape::sim::load_vit(vit)
                : measurements.empty()
                    ? drape::sim::measurements_for_size(size, drape::app::asset("forms"))
                    : drape::sim::load_measurements(measurements);
    if (!meas) {
      std::fprintf(stderr, "drape form: %s\n", meas.error().c_str());
      return 1;
    }
    form = DressForm::from_measurements(*meas, spacing);
    what = !vit.empty()           ? "individual measurements " + vit
           : measurements.empty() ? "size " + size
                                  : "measurements " + measurements;
    if (form && report) {
      std::printf("requested: bust %.1f mm, waist %.1f mm, hip %.1f mm\n", meas->bust_girth * 1000,
                  meas->waist_girth * 1000, meas->hip_girth * 1000);
    }
  }
  if (!form) {
    std::fprintf(stderr, "drape form: %s\n", form.error().c_str());
    return 1;
  }
  const DressForm& f = *form;
  const auto& lm = f.landmarks();
  if (report) {
    std::printf("dress form from %s: %d sections x %d angles, spacing %.2f mm, y %.4f .. %.4f m\n",
                what.c_str(), f.num_sections(), DressForm::kAngles, f.section_spacing() * 1000,
                f.min_y(), f.max_y());
    if (!mesh.empty()) {
      std::printf(
          "import: units %s%s (x%g), up axis %s%s, centre front %s (rotated %.1f deg), "
          "lifted %.4f m, %d triangles, %d rays filled\n",
          info.units.c_str(), info.units_detected ? " (detected)" : "", info.scale, info.up.c_str(),
          info.up_detected ? " (detected)" : "",
          info.front_detected ? "detected" : "from --front / +z",
          info.front_angle * 180.0 / 3.14159265358979323846, info.lift, info.triangles,
          info.filled_rays);
    }
    std::printf("%-6s %10s %12s\n", "line", "height m", "girth mm");
    std::printf("%-6s %10.4f %12.1f\n", "bust", lm.bust_y, f.girth_at(lm.bust_y) * 1000);
    std::printf("%-6s %10.4f %12.1f\n", "waist", lm.waist_y, f.girth_at(lm.waist_y) * 1000);
    std::printf("%-6s %10.4f %12.1f\n", "hip", lm.hip_y, f.girth_at(lm.hip_y) * 1000);
    std::printf(
        "neck %.4f m, bottom %.4f m, top %.4f m; side lines at theta %.1f / %.1f deg "
        "(centre front theta 0 faces +z, theta runs toward the form's left, +x)\n",
        lm.neck_y, lm.bottom_y, lm.top_y, lm.left_side_theta * 180 / 3.14159265358979323846,
        lm.right_side_theta * 180 / 3.14159265358979323846);
  }
  if (!export_path.empty()) {
    const std::string err = drape::sim::write_meshes(export_path, {f.to_mesh()});
    if (!err.empty()) {
      std::fprintf(stderr, "drape form: %s\n", err.c_str());
      return 1;
    }
    std::printf("wrote %s\n", export_path.c_str());
  }
  return 0;
}

int form_main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drape form: error: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "drape form: unknown error\n");
  }
  return 1;
}

}  // namespace

DRAPE_COMMAND(form, "dress form: girths report (--size/--measurements/--mesh), --export",
              form_main);
