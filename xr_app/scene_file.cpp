// Scene files and the default scene of `drape render` (xr_app/scene_file.hpp).
#include "xr_app/scene_file.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sim/core/cloth.hpp"
#include "sim/core/fabric.hpp"
#include "sim/core/scene_objects.hpp"
#include "sim/draping/mapping.hpp"
#include "sim/draping/panel.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/io/mesh_io.hpp"
#include "sim/runtime/world.hpp"
#include "sim/solvers/solver_factory.hpp"
#include "xr_app/paths.hpp"

namespace drape::app {
using namespace drape::render;
namespace {

using json = nlohmann::json;
constexpr float kDeg = 3.14159265358979323846f / 180.0f;

// Parse errors carry the field path; thrown inside the parser only, caught at its boundary.
struct FieldError {
  std::string field, what;
};

[[noreturn]] void bad(const std::string& field, const std::string& what) {
  throw FieldError{field, what};
}

double number(const json& j, const std::string& field) {
  if (!j.is_number()) bad(field, "expected a number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) bad(field, "not finite");
  return v;
}

double positive(const json& j, const std::string& field) {
  const double v = number(j, field);
  if (v <= 0) bad(field, "must be > 0");
  return v;
}

Eigen::Vector3d vec3(const json& j, const std::string& field) {
  if (!j.is_array() || j.size() != 3) bad(field, "expected [x, y, z]");
  return {number(j[0], field + "[0]"), number(j[1], field + "[1]"), number(j[2], field + "[2]")};
}

Eigen::Vector2d vec2(const json& j, const std::string& field) {
  if (!j.is_array() || j.size() != 2) bad(field, "expected [u, v]");
  return {number(j[0], field + "[0]"), number(j[1], field + "[1]")};
}

const json& array_field(const json& obj, const char* key, const std::string& field) {
  const json& a = obj.at(key);
  if (!a.is_array()) bad(field, "expected an array");
  return a;
}

bool boolean(const json& j, const std::string& field) {
  if (!j.is_boolean()) bad(field, "expected true or false");
  return j.get<bool>();
}

std::string text(const json& j, const std::string& field) {
  if (!j.is_string()) bad(field, "expected a string");
  return j.get<std::string>();
}

std::string resolve(const std::string& base, const std::string& p) {
  const std::filesystem::path path(p);
  return path.is_absolute() ? p : (std::filesystem::path(base) / path).string();
}

void parse_form(const json& f, const std::string& base, sim::SceneSnapshot& snap) {
  sim::Result<sim::DressForm> form = sim::Error{""};
  if (f.contains("size")) {
    auto m = sim::measurements_for_size(text(f["size"], "form.size"), asset("forms"));
    if (!m) bad("form.size", m.error());
    form = sim::DressForm::from_measurements(*m);
  } else if (f.contains("measurements")) {
    auto m = sim::load_measurements(resolve(base, text(f["measurements"], "form.measurements")));
    if (!m) bad("form.measurements", m.error());
    form = sim::DressForm::from_measurements(*m);
  } else if (f.contains("mesh")) {
    form = sim::form_from_mesh_file(resolve(base, text(f["mesh"], "form.mesh")));
  } else {
    bad("form", "expected \"size\", \"measurements\" or \"mesh\"");
  }
  if (!form) bad("form", form.error());
  snap.form = std::make_shared<const sim::DressForm>(std::move(*form));
}

// A flat panel of the grid kind (material (u, v) from the bottom-left corner) placed in 3D.
sim::Cloth panel_cloth(const json& p, const std::string& field) {
  sim::PanelSpec spec;
  if (p.contains("width")) spec.width = positive(p["width"], field + ".width");
  if (p.contains("height")) spec.height = positive(p["height"], field + ".height");
  if (p.contains("spacing")) spec.spacing = positive(p["spacing"], field + ".spacing");
  if (p.contains("nx")) spec.nx = static_cast<int>(positive(p["nx"], field + ".nx"));
  if (p.contains("ny")) spec.ny = static_cast<int>(positive(p["ny"], field + ".ny"));
  if (spec.nx > 1024 || spec.ny > 1024) bad(field, "grid larger than 1024 x 1024");
  if (spec.nx == 0 && (spec.width / spec.spacing > 1024 || spec.height / spec.spacing > 1024))
    bad(field + ".spacing", "grid larger than 1024 x 1024");
  sim::Cloth c = sim::make_panel(spec, sim::FabricParams{});
  const sim::Vec3 origin = p.contains("origin") ? vec3(p["origin"], field + ".origin")
                                                : sim::Vec3(-0.5 * spec.width, 1.0, 0.3);
  const sim::Vec3 au =
      p.contains("axis_u") ? vec3(p["axis_u"], field + ".axis_u") : sim::Vec3::UnitX();
  const sim::Vec3 av =
      p.contains("axis_v") ? vec3(p["axis_v"], field + ".axis_v") : sim::Vec3::UnitY();
  if (au.norm() < 1e-9 || av.norm() < 1e-9 || au.cross(av).norm() < 1e-9 * au.norm() * av.norm())
    bad(field, "axis_u and axis_v must be non-zero and not parallel");
  sim::place_spread(c, origin, au, av);
  return c;
}

void cloth_to_snapshot(const sim::Cloth& c, sim::SceneSnapshot& snap) {
  sim::World w;
  w.cloth = c;
  w.scene.form = snap.form;
  auto form = snap.form;
  sim::fill_snapshot(w, snap);
  snap.form = form;
}

// Geometric draping (method 2.4, sim/draping/mapping.hpp): four quarter panels of muslin, one waist
// dart each, mapped onto the form along the grain (centre front/back to the side lines), `ease`
// metres of ease round the body. The panels are merged into one cloth mesh with their flat (u, v).
void mapped_cloth(const json& m, sim::SceneSnapshot& snap) {
  if (!snap.form) bad("cloth.mapped", "needs a form");
  const sim::DressForm& form = *snap.form;
  const sim::FormLandmarks& lm = form.landmarks();
  const double ease = m.contains("ease") ? number(m["ease"], "cloth.mapped.ease") : 0.02;
  if (ease < 0 || ease > 0.2) bad("cloth.mapped.ease", "expected 0 .. 0.2 m");
  const sim::MappingSurface surf(form, ease);
  const double hip = surf.girth(lm.hip_y), waist = surf.girth(lm.waist_y);
  sim::PanelDesign pd;
  pd.width = hip / 4;
  pd.height = m.contains("height") ? positive(m["height"], "cloth.mapped.height") : 0.62;
  pd.spacing = m.contains("spacing") ? positive(m["spacing"], "cloth.mapped.spacing") : 0.008;
  if (pd.spacing < 0.002) bad("cloth.mapped.spacing", "at least 0.002 m");
  pd.top_above_waist = m.contains("top_above_waist")
                           ? number(m["top_above_waist"], "cloth.mapped.top_above_waist")
                           : 0.03;
  pd.slits.push_back({0.45 * pd.width, 0.14, std::max(0.0, (hip - waist) / 4 - 0.004)});
  const double top_y = lm.waist_y + pd.top_above_waist;
  if (std::string e = sim::validate_panel(pd, "cloth.mapped", &form, ease, top_y); !e.empty())
    bad("cloth.mapped", e);
  const struct {
    double centre, side;
  } pieces[] = {{lm.centre_front_theta, lm.right_side_theta},
                {lm.centre_front_theta, lm.left_side_theta},
                {lm.centre_back_theta, lm.right_side_theta},
                {lm.centre_back_theta, lm.left_side_theta}};
  constexpr double kPi = 3.14159265358979323846;
  for (const auto& pc : pieces) {
    auto panel = sim::build_panel(pd, sim::FabricParams{}, "cloth.mapped");
    if (!panel) bad("cloth.mapped", panel.error());
    const double delta = std::fmod(pc.side - pc.centre + 3 * kPi, 2 * kPi) - kPi;
    const int dir = delta < 0 ? -1 : 1;
    const sim::PieceMapping pm =
        sim::make_piece_mapping(*panel, surf, pc.centre, dir, pc.side, lm.waist_y);
    sim::map_panel(*panel, surf, pm);
    sim::SceneSnapshot part;
    part.form = snap.form;
    cloth_to_snapshot(panel->cloth, part);
    const auto base = static_cast<uint32_t>(snap.positions.size());
    snap.positions.insert(snap.positions.end(), part.positions.begin(), part.positions.end());
    snap.normals.insert(snap.normals.end(), part.normals.begin(), part.normals.end());
    snap.material.insert(snap.material.end(), part.material.begin(), part.material.end());
    snap.flags.insert(snap.flags.end(), part.flags.begin(), part.flags.end());
    snap.strain.insert(snap.strain.end(), part.strain.begin(), part.strain.end());
    for (uint32_t i : part.indices) snap.indices.push_back(base + i);
  }
}

void parse_cloth(const json& c, const std::string& base, sim::SceneSnapshot& snap) {
  if (c.contains("mapped")) {
    mapped_cloth(c["mapped"], snap);
    return;
  }
  if (c.contains("panel")) {
    sim::Cloth cloth = panel_cloth(c["panel"], "cloth.panel");
    if (c.contains("drape")) {
      const json& d = c["drape"];
      const double seconds =
          d.contains("seconds") ? positive(d["seconds"], "cloth.drape.seconds") : 2.0;
      if (seconds > 60) bad("cloth.drape.seconds", "at most 60 s");
      const std::string solver =
          d.contains("solver") ? text(d["solver"], "cloth.drape.solver") : "xpbd";
      if (d.contains("fabric")) {
        auto fab = sim::load_fabric(asset("fabrics.json").string(),
                                    text(d["fabric"], "cloth.drape.fabric"));
        if (!fab) bad("cloth.drape.fabric", fab.error());
        cloth.fabric = *fab;
        cloth.relump_masses();
      }
      auto s = sim::make_solver(solver);
      if (!s) bad("cloth.drape.solver", s.error());
      sim::SceneObjects objs;
      objs.form = snap.form;
      // Muslin on the form's linen cover does not slide (Coulomb friction, every solver).
      objs.friction = d.contains("friction") ? number(d["friction"], "cloth.drape.friction")
                                             : sim::kFormFriction;
      if (objs.friction < 0 || objs.friction > 2) bad("cloth.drape.friction", "outside [0, 2]");
      for (const auto& p : snap.plates) objs.plates.push_back(p);
      for (const auto& b : snap.boxes) objs.boxes.push_back(b);
      for (const auto& sp : snap.spheres) objs.spheres.push_back(sp);
      const double dt = 1.0 / 90.0;
      for (int i = 0; i < static_cast<int>(std::ceil(seconds / dt)); ++i) {
        const auto st = (*s)->step(cloth, objs, dt);
        if (st.diverged) bad("cloth.drape", "the solver diverged at t = " + std::to_string(i * dt));
      }
    }
    cloth_to_snapshot(cloth, snap);
    return;
  }
  if (c.contains("mesh")) {
    const std::string path = resolve(base, text(c["mesh"], "cloth.mesh"));
    auto m = sim::load_mesh(path);
    if (!m) bad("cloth.mesh", m.error());
    for (const auto& v : m->vertices) snap.positions.emplace_back(v.cast<float>());
    for (const auto& t : m->triangles)
      for (int k = 0; k < 3; ++k) snap.indices.push_back(static_cast<uint32_t>(t[k]));
    for (const auto& uv : m->uv) snap.material.emplace_back(uv.cast<float>());
    return;
  }
  const json& pos = array_field(c, "positions", "cloth.positions");
  for (size_t i = 0; i < pos.size(); ++i)
    snap.positions.emplace_back(
        vec3(pos[i], "cloth.positions[" + std::to_string(i) + "]").cast<float>());
  const json& idx = array_field(c, "indices", "cloth.indices");
  if (idx.size() % 3) bad("cloth.indices", "length must be a multiple of 3");
  for (size_t i = 0; i < idx.size(); ++i) {
    const std::string f = "cloth.indices[" + std::to_string(i) + "]";
    if (!idx[i].is_number_integer() || idx[i].get<int64_t>() < 0 ||
        idx[i].get<uint64_t>() >= snap.positions.size())
      bad(f, "expected a vertex index in [0, " + std::to_string(snap.positions.size()) + ")");
    snap.indices.push_back(idx[i].get<uint32_t>());
  }
  if (c.contains("material")) {
    const json& m = array_field(c, "material", "cloth.material");
    if (m.size() != snap.positions.size()) bad("cloth.material", "one [u, v] per position");
    for (size_t i = 0; i < m.size(); ++i)
      snap.material.emplace_back(
          vec2(m[i], "cloth.material[" + std::to_string(i) + "]").cast<float>());
  }
  if (c.contains("strain")) {
    const json& s = array_field(c, "strain", "cloth.strain");
    if (s.size() != snap.positions.size()) bad("cloth.strain", "one value per position");
    for (size_t i = 0; i < s.size(); ++i)
      snap.strain.push_back(
          static_cast<float>(number(s[i], "cloth.strain[" + std::to_string(i) + "]")));
  }
}

void parse_camera(const json& c, CameraSpec& cam) {
  if (c.contains("eye")) cam.eye = vec3(c["eye"], "camera.eye").cast<float>();
  if (c.contains("target")) cam.target = vec3(c["target"], "camera.target").cast<float>();
  if (c.contains("fov_y_deg")) {
    cam.fov_y_deg = static_cast<float>(positive(c["fov_y_deg"], "camera.fov_y_deg"));
    if (cam.fov_y_deg >= 179) bad("camera.fov_y_deg", "must be < 179");
  }
  if ((cam.eye - cam.target).norm() < 1e-6f) bad("camera", "eye and target coincide");
  if (c.contains("xr")) {
    const json& x = c["xr"];
    Fov f;
    const json& fov = x.at("fov");
    f.angle_left = static_cast<float>(number(fov.at("angleLeft"), "camera.xr.fov.angleLeft"));
    f.angle_right = static_cast<float>(number(fov.at("angleRight"), "camera.xr.fov.angleRight"));
    f.angle_up = static_cast<float>(number(fov.at("angleUp"), "camera.xr.fov.angleUp"));
    f.angle_down = static_cast<float>(number(fov.at("angleDown"), "camera.xr.fov.angleDown"));
    if (!(f.angle_left < f.angle_right && f.angle_down < f.angle_up) ||
        std::abs(f.angle_left) >= 1.57f || std::abs(f.angle_right) >= 1.57f ||
        std::abs(f.angle_up) >= 1.57f || std::abs(f.angle_down) >= 1.57f)
      bad("camera.xr.fov", "angles must satisfy left < right, down < up, |angle| < pi/2");
    cam.xr_fov = f;
    if (x.contains("position"))
      cam.xr_pose.position = vec3(x["position"], "camera.xr.position").cast<float>();
    if (x.contains("orientation")) {
      const json& q = x["orientation"];
      if (!q.is_array() || q.size() != 4) bad("camera.xr.orientation", "expected [x, y, z, w]");
      Eigen::Quaternionf qq(static_cast<float>(number(q[3], "camera.xr.orientation[3]")),
                            static_cast<float>(number(q[0], "camera.xr.orientation[0]")),
                            static_cast<float>(number(q[1], "camera.xr.orientation[1]")),
                            static_cast<float>(number(q[2], "camera.xr.orientation[2]")));
      if (qq.norm() < 1e-6f) bad("camera.xr.orientation", "zero quaternion");
      cam.xr_pose.orientation = qq.normalized();
    }
  }
}

void parse_options(const json& o, SceneDescription& d) {
  DrawOptions& opt = d.options;
  if (o.contains("colour_map")) {
    const std::string m = text(o["colour_map"], "options.colour_map");
    if (m == "none")
      opt.colour_map = ColourMap::kNone;
    else if (m == "strain")
      opt.colour_map = ColourMap::kStrain;
    else if (m == "ease")
      opt.colour_map = ColourMap::kEase;
    else
      bad("options.colour_map", "expected \"none\", \"strain\" or \"ease\"");
  }
  if (o.contains("strain_range"))
    opt.strain_range = static_cast<float>(positive(o["strain_range"], "options.strain_range"));
  if (o.contains("ease_range"))
    opt.ease_range = static_cast<float>(positive(o["ease_range"], "options.ease_range"));
  if (o.contains("grain")) opt.grain = boolean(o["grain"], "options.grain");
  if (o.contains("grain_spacing"))
    opt.grain_spacing = static_cast<float>(positive(o["grain_spacing"], "options.grain_spacing"));
  if (o.contains("floor")) opt.floor_grid = boolean(o["floor"], "options.floor");
  if (o.contains("pattern_panel"))
    opt.pattern_panel = boolean(o["pattern_panel"], "options.pattern_panel");
  if (o.contains("panel_centre"))
    opt.panel_centre = vec3(o["panel_centre"], "options.panel_centre").cast<float>();
  if (o.contains("samples")) {
    d.samples = static_cast<int>(positive(o["samples"], "options.samples"));
    if (d.samples > 8) bad("options.samples", "at most 8");
  }
}

void parse_document(const json& doc, const std::string& base, SceneDescription& d) {
  if (!doc.is_object()) bad("(top level)", "expected a JSON object");
  sim::SceneSnapshot& s = d.snapshot;
  if (doc.contains("form") && !doc["form"].is_null()) parse_form(doc["form"], base, s);
  if (doc.contains("plates"))
    for (size_t i = 0; const auto& p : array_field(doc, "plates", "plates")) {
      const std::string f = "plates[" + std::to_string(i++) + "]";
      sim::Plate pl;
      if (p.contains("centre")) pl.centre = vec3(p["centre"], f + ".centre");
      if (p.contains("half_x")) pl.half_x = positive(p["half_x"], f + ".half_x");
      if (p.contains("half_z")) pl.half_z = positive(p["half_z"], f + ".half_z");
      if (p.contains("thickness")) pl.thickness = positive(p["thickness"], f + ".thickness");
      s.plates.push_back(pl);
    }
  if (doc.contains("boxes"))
    for (size_t i = 0; const auto& b : array_field(doc, "boxes", "boxes")) {
      const std::string f = "boxes[" + std::to_string(i++) + "]";
      sim::Box bx;
      if (b.contains("centre")) bx.centre = vec3(b["centre"], f + ".centre");
      if (b.contains("half")) bx.half = vec3(b["half"], f + ".half");
      if (bx.half.minCoeff() <= 0) bad(f + ".half", "must be > 0");
      s.boxes.push_back(bx);
    }
  if (doc.contains("spheres"))
    for (size_t i = 0; const auto& b : array_field(doc, "spheres", "spheres")) {
      const std::string f = "spheres[" + std::to_string(i++) + "]";
      sim::Sphere sp;
      if (b.contains("centre")) sp.centre = vec3(b["centre"], f + ".centre");
      if (b.contains("radius")) sp.radius = positive(b["radius"], f + ".radius");
      s.spheres.push_back(sp);
    }
  if (doc.contains("cloth")) parse_cloth(doc["cloth"], base, s);
  if (doc.contains("hands"))
    for (size_t i = 0; const auto& h : array_field(doc, "hands", "hands")) {
      const std::string f = "hands[" + std::to_string(i++) + "]";
      sim::HandProxy hp;
      hp.tracked = true;
      if (h.contains("id")) hp.id = static_cast<int>(number(h["id"], f + ".id")) == 1 ? 1 : 0;
      if (h.contains("position")) hp.position = vec3(h["position"], f + ".position");
      hp.tip = h.contains("tip") ? vec3(h["tip"], f + ".tip") : hp.position;
      if (h.contains("radius")) hp.radius = positive(h["radius"], f + ".radius");
      s.hands.push_back(hp);
    }
  if (doc.contains("pins"))
    for (size_t i = 0; const auto& p : array_field(doc, "pins", "pins"))
      s.pins.emplace_back(vec3(p, "pins[" + std::to_string(i++) + "]").cast<float>());
  if (doc.contains("cut_strokes"))
    for (size_t i = 0; const auto& st : array_field(doc, "cut_strokes", "cut_strokes")) {
      const std::string f = "cut_strokes[" + std::to_string(i++) + "]";
      if (!st.is_array()) bad(f, "expected an array of [x, y, z]");
      auto& out = s.cut_strokes.emplace_back();
      for (size_t k = 0; k < st.size(); ++k)
        out.emplace_back(vec3(st[k], f + "[" + std::to_string(k) + "]").cast<float>());
    }
  if (doc.contains("pattern_outlines"))
    for (size_t i = 0; const auto& o : array_field(doc, "pattern_outlines", "pattern_outlines")) {
      const std::string f = "pattern_outlines[" + std::to_string(i++) + "]";
      if (!o.is_array()) bad(f, "expected an array of [u, v]");
      auto& out = s.pattern_outlines.emplace_back();
      for (size_t k = 0; k < o.size(); ++k)
        out.emplace_back(vec2(o[k], f + "[" + std::to_string(k) + "]").cast<float>());
    }
  if (doc.contains("candidates"))
    for (size_t i = 0; const auto& c : array_field(doc, "candidates", "candidates")) {
      const std::string f = "candidates[" + std::to_string(i++) + "]";
      const int hand = c.contains("hand") ? static_cast<int>(number(c["hand"], f + ".hand")) : 0;
      if (hand != 0 && hand != 1) bad(f + ".hand", "expected 0 (left) or 1 (right)");
      if (c.contains("vertex")) {
        const double v = number(c["vertex"], f + ".vertex");
        if (v < 0 || v >= static_cast<double>(s.positions.size()))
          bad(f + ".vertex", "not a cloth vertex index");
        s.candidate_vertex[hand] = static_cast<int32_t>(v);
      } else if (c.contains("point")) {
        s.candidate_point[hand] = vec3(c["point"], f + ".point").cast<float>();
        s.candidate_is_form[hand] = true;
      } else {
        bad(f, "expected \"vertex\" or \"point\"");
      }
    }
  if (doc.contains("camera")) parse_camera(doc["camera"], d.camera);
  if (doc.contains("options")) parse_options(doc["options"], d);
}

}  // namespace

View CameraSpec::view(int width, int height) const {
  const float aspect = static_cast<float>(width) / static_cast<float>(std::max(height, 1));
  if (xr_fov) return make_view(xr_pose, *xr_fov);
  return look_at(eye, target, fov_y_deg * kDeg, aspect);
}

sim::Result<SceneDescription> parse_scene(const std::string& json_text, const std::string& source,
                                          const std::string& base_dir) {
  SceneDescription d;
  try {
    const json doc = json::parse(json_text);
    parse_document(doc, base_dir, d);
  } catch (const FieldError& e) {
    return sim::make_error(source, e.field + ": " + e.what);
  } catch (const json::parse_error& e) {
    return sim::make_error(source, std::string("invalid JSON: ") + e.what());
  } catch (const json::exception& e) {
    return sim::make_error(source, std::string("missing or mistyped field: ") + e.what());
  }
  d.summary = std::to_string(d.snapshot.positions.size()) + " cloth vertices, " +
              std::to_string(d.snapshot.indices.size() / 3) + " triangles" +
              (d.snapshot.form ? ", form" : "");
  return d;
}

sim::Result<SceneDescription> load_scene(const std::string& path) {
  std::ifstream in(path);
  if (!in) return sim::make_error(path, "cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_scene(ss.str(), path, std::filesystem::path(path).parent_path().string());
}

sim::Result<SceneDescription> default_scene(double sim_seconds, const std::string& solver,
                                            int grid) {
  if (solver == "mapping") {
    // Geometric draping: four quarter panels mapped onto the form (a fitted skirt block with a
    // waist dart each), the straight grain vertical on centre front and back.
    json doc = {{"form", {{"size", "9AR"}}},
                {"cloth", {{"mapped", {{"ease", 0.02}, {"height", 0.62}, {"spacing", 0.008}}}}},
                {"options", {{"samples", 4}}}};
    return parse_scene(doc.dump(), "default scene");
  }
  // A square of muslin held flat above the shoulders and dropped: it falls over the form and
  // hangs in folds, the straight grain (v) running from front to back over the shoulders.
  json doc = {{"form", {{"size", "9AR"}}},
              {"cloth",
               {{"panel",
                 {{"width", 1.0},
                  {"height", 1.0},
                  {"nx", grid},
                  {"ny", grid},
                  {"origin", {-0.5, 1.40, 0.5}},
                  {"axis_u", {1, 0, 0}},
                  {"axis_v", {0, 0, -1}}}},
                {"drape", {{"seconds", sim_seconds}, {"solver", solver}, {"fabric", "muslin"}}}}},
              {"options", {{"samples", 4}}}};
  return parse_scene(doc.dump(), "default scene");
}

}  // namespace drape::app
