// The live session's scene: fabric, form and start state (see desk_scene.hpp).
#include "xr_app/app/desk_scene.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "sim/core/cloth.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/io/mesh_io.hpp"

namespace drape::app {

namespace {

constexpr double kPanel = 0.5;  // m, the panel's side

sim::Result<sim::FabricParams> desk_fabric(const XrAppOptions& o) {
  if (o.fabrics_path.empty()) {
    if (o.fabric == sim::FabricParams{}.name) return sim::FabricParams{};
    return sim::make_error("--fabric", "no fabrics file to find '" + o.fabric + "' in");
  }
  auto f = sim::load_fabric(o.fabrics_path, o.fabric);
  if (!f) return sim::make_error("--fabric " + o.fabric, f.error());
  return f;
}

// Whether every vertex lies outside the form's contact shell (with 2 mm to spare).
bool clear_of_form(const sim::Testbed& s) {
  for (const sim::Vec3& x : s.cloth.state.x)
    if (s.objects.form->signed_distance(x) < s.objects.offset + 0.002) return false;
  return true;
}

void pin_row(sim::Cloth& c, int res, int row) {
  for (int i = 0; i < res; ++i) c.state.flags[row * res + i] |= sim::kFlagPinned;
}

// The start state: the panel placed with its top edge (v = height, the last row) across the
// chest line at `line` (its left end), 1 cm in front of the form; moved forward 1 cm at a time
// (or tilted, when hanging) until it is clear of the form.
void place_start(sim::Testbed& s, const std::string& start, int res, const sim::Vec3& line) {
  sim::Cloth& c = s.cloth;
  const sim::Vec3 fwd = sim::Vec3::UnitZ(), x = sim::Vec3::UnitX();
  for (int step = 0; step <= 90; ++step) {
    if (start == "spread") {
      sim::place_spread(c, line + (0.01 * step + kPanel) * fwd, x, -fwd);
    } else if (start == "rolled") {
      sim::place_rolled(c, line + 0.01 * step * fwd, x, sim::Vec3::UnitY(), 0.02);
    } else {  // pinned-top: hanging down, tilted forward by the least whole degree that clears
      const double a = step * M_PI / 180;
      const sim::Vec3 down(0, -std::cos(a), std::sin(a));
      sim::place_spread(c, line + kPanel * down, x, -down);
    }
    if (clear_of_form(s)) break;
  }
  pin_row(c, res, res - 1);
  if (start == "spread") {  // the two free corners too: held open
    c.state.flags[0] |= sim::kFlagPinned;
    c.state.flags[res - 1] |= sim::kFlagPinned;
  } else if (start == "rolled") {
    pin_row(c, res, 0);  // the roll's core: it stays rolled until released
  }
}

}  // namespace

sim::Result<sim::DressForm> desk_form(const XrAppOptions& o) {
  if (!o.form_mesh.empty()) {
    auto f = sim::form_from_mesh_file(o.form_mesh);
    if (!f) return sim::make_error("--mesh " + o.form_mesh, f.error());
    return f;
  }
  const bool file = !o.form_measurements.empty();
  auto m = file ? sim::load_measurements(o.form_measurements)
                : sim::measurements_for_size(o.form_size, o.forms_dir);
  const std::string what = "--form " + (file ? o.form_measurements : o.form_size);
  if (!m) return sim::make_error(what, m.error());
  auto f = sim::DressForm::from_measurements(*m);
  if (!f) return sim::make_error(what, f.error());
  return f;
}

const char* desk_start_names() {
  return "spread|rolled|pinned-top";
}

bool is_desk_start(const std::string& name) {
  return name == "spread" || name == "rolled" || name == "pinned-top";
}

sim::Result<sim::Testbed> make_desk_scene(const XrAppOptions& opt) {
  if (!is_desk_start(opt.start))
    return sim::make_error("--start", "'" + opt.start + "' is none of " + desk_start_names());
  auto fabric = desk_fabric(opt);
  if (!fabric) return sim::Error{fabric.error()};
  auto form = desk_form(opt);
  if (!form) return sim::Error{form.error()};
  sim::Testbed s;
  s.name = "desk";
  s.objects.form = std::make_shared<const sim::DressForm>(std::move(*form));
  s.objects.floor = true;
  s.objects.friction = sim::kFormFriction;  // muslin does not slide on a dress form's cover
  const sim::DressForm& f = *s.objects.form;
  // The chest line: 12 cm above the bust line, below the top of the form.
  const double top = std::min(f.landmarks().bust_y + 0.12, f.max_y() - 0.02);
  const sim::Vec2 centre = f.centre_at(top);
  const double zf = f.surface_at(top, 0.0).z();
  sim::PanelSpec p;
  p.width = p.height = kPanel;
  p.nx = p.ny = opt.cloth_res;
  s.cloth = sim::make_panel(p, *fabric);
  place_start(s, opt.start, opt.cloth_res, sim::Vec3(centre.x() - kPanel / 2, top, zf + 0.01));
  s.cloth.relump_masses();
  s.duration = 1.5;
  return s;
}

}  // namespace drape::app
