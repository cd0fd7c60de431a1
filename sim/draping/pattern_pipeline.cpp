// The geometric draping pipeline of method chapter 2 end to end (the draped block, and the
// blocks derived from it by slash and spread), with its measured report.
#include "sim/draping/pattern_pipeline.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sim/core/stopwatch.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/io/mesh_io.hpp"

namespace drape::sim {
namespace {
constexpr double kPi = 3.141592653589793;
using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

// Reads an optional number field; errors name source and field.
std::string get_num(const json& j, const char* key, const std::string& where, double* out) {
  if (!j.contains(key)) return "";
  if (!j[key].is_number() || !std::isfinite(j[key].get<double>()))
    return where + "." + key + ": must be a finite number";
  *out = j[key].get<double>();
  return "";
}
std::string get_str(const json& j, const char* key, const std::string& where, std::string* out) {
  if (!j.contains(key)) return "";
  if (!j[key].is_string()) return where + "." + key + ": must be a string";
  *out = j[key].get<std::string>();
  return "";
}

double line_theta(const std::string& name, const FormLandmarks& lm) {
  if (name == "centre_front") return lm.centre_front_theta;
  if (name == "centre_back") return lm.centre_back_theta;
  if (name == "left_side") return lm.left_side_theta;
  return lm.right_side_theta;
}

// The draped panel's position at a material point (the nearest node where the point falls
// just outside every flat triangle).
std::function<Vec3(const Vec2&)> block_position(const Panel& panel) {
  return [&panel](const Vec2& m) {
    const auto& px = panel.cloth.state.x;
    Vec3 b;
    const int t = panel.locate(m, &b);
    if (t >= 0) {
      const auto& tri = panel.cloth.topo.triangles[t];
      return Vec3(b[0] * px[tri[0]] + b[1] * px[tri[1]] + b[2] * px[tri[2]]);
    }
    const auto& mat = panel.cloth.topo.material;
    size_t best = 0;
    for (size_t v = 1; v < mat.size(); ++v)
      if ((mat[v] - m).squaredNorm() < (mat[best] - m).squaredNorm()) best = v;
    return px[best];
  };
}

// 3D area of the garment triangles of one piece copy (m^2): those whose three vertices belong to
// it (a mirrored copy shares its centre seam's vertices with the right one).
double garment_piece_area(const Garment& g, int piece) {
  double a = 0;
  for (const auto& t : g.triangles)
    if (g.vertex_piece[t[0]] == piece && g.vertex_piece[t[1]] == piece &&
        g.vertex_piece[t[2]] == piece)
      a += 0.5 * (g.x[t[1]] - g.x[t[0]]).cross(g.x[t[2]] - g.x[t[0]]).norm();
  return a;
}

// Length on the sewn garment of a line drawn on a pattern piece (flat points, right-half
// material coordinates): each segment subdivided every 2 mm, each point found in the piece
// copy's triangles by its material coordinates (x mirrored for the left copy) and taken to 3D.
// Across folds and pleats this follows the cloth, as a tape laid along the line would.
double garment_line_length(const Garment& g, int piece, const std::vector<Vec2>& line,
                           bool mirrored) {
  std::vector<const std::array<int32_t, 3>*> tris;
  for (const auto& t : g.triangles) {
    int own = 0;
    for (int k = 0; k < 3; ++k) own += g.vertex_piece[t[k]] == piece;
    if (own == 3 || (mirrored && own > 0)) tris.push_back(&t);
  }
  const auto at = [&](Vec2 m, Vec3* out) {
    if (mirrored) m.x() = -m.x();
    double best = -1e300;
    for (const auto* t : tris) {
      const Vec2 &a = g.material[(*t)[0]], &b = g.material[(*t)[1]], &c = g.material[(*t)[2]];
      const double den = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
      if (std::abs(den) < 1e-18) continue;
      const double u = ((m - a).x() * (c - a).y() - (m - a).y() * (c - a).x()) / den;
      const double v = ((b - a).x() * (m - a).y() - (b - a).y() * (m - a).x()) / den;
      const double w = std::min({1 - u - v, u, v});
      if (w > best) {  // inside (w >= 0) or, on the outline, the nearest triangle
        best = w;
        *out = (1 - u - v) * g.x[(*t)[0]] + u * g.x[(*t)[1]] + v * g.x[(*t)[2]];
      }
      if (w >= 0) return;
    }
  };
  double len = 0;
  Vec3 prev = Vec3::Zero();
  bool first = true;
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    const int n = std::max(1, static_cast<int>(std::ceil((line[i + 1] - line[i]).norm() / 0.002)));
    for (int k = first ? 0 : 1; k <= n; ++k) {
      Vec3 p = Vec3::Zero();
      at(line[i] + (line[i + 1] - line[i]) * (static_cast<double>(k) / n), &p);
      if (!first) len += (p - prev).norm();
      prev = p;
      first = false;
    }
  }
  return len;
}

// Where a spread piece's point starts the garment relaxation: the flare spread evenly round the
// form. The point goes back to the draped block (block_position of its unspread point, height
// y, arc s0 from the piece's centre line); at height y all wedges of all pieces (both halves) add
// dG of girth, so the section is scaled by k = (G + dG) / G about its centre and the point sits
// at arc (s0 + the wedges before it) / k of the unscaled section, keeping its offset from the
// surface.
std::function<Vec3(const Vec2&)> cone_placement(const PipelineResult& R, size_t i,
                                                const MappingSurface& surf) {
  const auto added_girth = [&R](double y) {
    double dg = 0;
    for (size_t k = 0; k < R.spread.size(); ++k)
      dg += 2 * spread_arc_at_row(R.spread[k], R.mappings[k].v_of_y(y));
    return dg;
  };
  // The flare slopes outward (its radius grows by dG / 2 pi), so a meridian of the cone is longer
  // than its height: heights below the waist are drawn up so that each millimetre of cloth down
  // the meridian drops cos(slope) (else the placed cloth is stretched by ~1.3 % down the grain).
  const double y_top = R.mappings[i].y_top, step = 0.001;
  std::vector<double> drop{0.0};  // drop[j]: placed depth of the height y_top - j * step
  for (double y = y_top; y > y_top - 1.5; y -= step) {
    const double slope = (added_girth(y - step) - added_girth(y)) / (2 * 3.141592653589793 * step);
    drop.push_back(drop.back() + step / std::sqrt(1 + slope * slope));
  }
  return [&R, i, &surf, added_girth, drop, y_top, step,
          block = block_position(R.panels[i])](const Vec2& m) {
    const SpreadPiece& sp = R.spread[i];
    const PieceMapping& pm = R.mappings[i];
    double extra = 0;
    const Vec3 p0 = block(unspread_arc(sp, m, &extra));
    const double f = std::clamp((y_top - p0.y()) / step, 0.0, drop.size() - 1.001);
    const size_t j = static_cast<size_t>(f);
    const double y = y_top - (drop[j] + (f - j) * (drop[j + 1] - drop[j]));
    const Vec2 c = surf.centre(p0.y());
    const double th0 = std::atan2(p0.x() - c.x(), p0.z() - c.y());
    const double off = std::hypot(p0.x() - c.x(), p0.z() - c.y()) - surf.radius(p0.y(), th0);
    const ArcTable T = ArcTable::build(surf, p0.y(), pm.theta_centre, pm.dir);
    const double g = surf.girth(p0.y()), k = (g + added_girth(p0.y())) / g;
    const double th = T.theta_at((T.arc_at(th0) + extra) / k);
    const double r = k * surf.radius(p0.y(), th) + off;
    const Vec2 cy = surf.centre(y);
    return Vec3(cy.x() + r * std::sin(th), y, cy.y() + r * std::cos(th));
  };
}

TriMesh panel_mesh(const Panel& p, const std::string& name) {
  TriMesh m;
  m.name = name;
  m.vertices = p.cloth.state.x;
  m.triangles = p.cloth.topo.triangles;
  m.uv = p.cloth.topo.material;
  return m;
}
}  // namespace

const std::vector<std::string>& known_lines() {
  static const std::vector<std::string> k{"centre_front", "centre_back", "left_side", "right_side",
                                          "waist",        "hip",         "hem"};
  return k;
}

Result<Design> parse_design(const std::string& text, const std::string& src) {
  json j;
  try {
    j = json::parse(text);
  } catch (const std::exception& e) {
    return Error{src + ": not valid JSON: " + e.what()};
  }
  if (!j.is_object()) return Error{src + ": the design must be a JSON object"};
  Design d;
  std::string err;
  const auto check = [&](std::string e) {
    if (err.empty() && !e.empty()) err = std::move(e);
  };
  check(get_str(j, "name", src, &d.name));
  check(get_str(j, "form", src, &d.form));
  check(get_str(j, "fabric", src, &d.fabric));
  double ease_mm = d.ease * 1000, sa_mm = d.seam_allowance * 1000;
  check(get_num(j, "ease_mm", src, &ease_mm));
  check(get_num(j, "seam_allowance_mm", src, &sa_mm));
  check(get_num(j, "length_below_waist", src, &d.length_below_waist));
  check(get_num(j, "extraction_step", src, &d.extraction_step));
  check(get_num(j, "remesh_edge", src, &d.remesh_edge));
  double it = d.relax_iterations;
  check(get_num(j, "relax_iterations", src, &it));
  check(get_str(j, "flare", src, &d.flare));
  if (!err.empty()) return Error{err};
  if (d.flare != "none" && d.flare != "close_darts")
    return Error{src + ".flare: unknown '" + d.flare + "' (known: none, close_darts)"};
  d.ease = ease_mm / 1000;
  d.seam_allowance = sa_mm / 1000;
  d.relax_iterations = static_cast<int>(it);
  if (d.ease < 0 || d.ease > 0.3) return Error{src + ".ease_mm: must be within 0..300 mm"};
  if (d.seam_allowance < 0 || d.seam_allowance > 0.05)
    return Error{src + ".seam_allowance_mm: must be within 0..50 mm"};
  if (d.length_below_waist <= 0.05 || d.length_below_waist > 1.2)
    return Error{src + ".length_below_waist: must be within 0.05..1.2 m"};
  if (d.extraction_step <= 0 || d.extraction_step > 0.05)
    return Error{src + ".extraction_step: must be within 0..0.05 m"};
  if (d.remesh_edge <= 0.001 || d.remesh_edge > 0.1)
    return Error{src + ".remesh_edge: must be within 0.001..0.1 m"};
  if (d.relax_iterations < 0 || d.relax_iterations > 100000)
    return Error{src + ".relax_iterations: must be within 0..100000"};
  if (!j.contains("pieces") || !j["pieces"].is_array() || j["pieces"].empty())
    return Error{src + ".pieces: must be a non-empty array"};
  const auto& known = known_lines();
  for (size_t i = 0; i < j["pieces"].size(); ++i) {
    const json& pj = j["pieces"][i];
    const std::string w = src + ": pieces[" + std::to_string(i) + "]";
    if (!pj.is_object()) return Error{w + ": must be an object"};
    PieceDesign p;
    check(get_str(pj, "name", w, &p.name));
    check(get_str(pj, "centre_line", w, &p.centre_line));
    check(get_str(pj, "side_line", w, &p.side_line));
    check(get_str(pj, "top_line", w, &p.top_line));
    check(get_str(pj, "bottom_line", w, &p.bottom_line));
    double q = p.quantity;
    check(get_num(pj, "quantity", w, &q));
    if (!err.empty()) return Error{err};
    p.quantity = static_cast<int>(q);
    const std::pair<const char*, std::string*> lines[] = {{"centre_line", &p.centre_line},
                                                          {"side_line", &p.side_line},
                                                          {"top_line", &p.top_line},
                                                          {"bottom_line", &p.bottom_line}};
    for (const auto& [field, val] : lines) {
      if (std::find(known.begin(), known.end(), *val) == known.end()) {
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        return Error{w + "." + field + ": unknown line '" + *val + "' (known lines: " + list + ")"};
      }
    }
    if (p.centre_line != "centre_front" && p.centre_line != "centre_back")
      return Error{w + ".centre_line: '" + p.centre_line + "' is not a centre line"};
    if (p.side_line != "left_side" && p.side_line != "right_side")
      return Error{w + ".side_line: '" + p.side_line + "' is not a side line"};
    if (p.top_line != "waist")
      return Error{w + ".top_line: only 'waist' is supported as the top line"};
    if (p.bottom_line != "hem" && p.bottom_line != "hip")
      return Error{w + ".bottom_line: must be 'hem' or 'hip'"};
    if (p.quantity < 1 || p.quantity > 100) return Error{w + ".quantity: must be within 1..100"};
    if (!pj.contains("panel") || !pj["panel"].is_object())
      return Error{w + ".panel: missing object"};
    const json& panel = pj["panel"];
    const std::string pw = w + ".panel";
    check(get_num(panel, "width", pw, &p.panel.width));
    check(get_num(panel, "height", pw, &p.panel.height));
    check(get_num(panel, "spacing", pw, &p.panel.spacing));
    check(get_num(panel, "top_above_waist", pw, &p.panel.top_above_waist));
    std::string edge = p.panel.centre_edge_left ? "left" : "right";
    check(get_str(panel, "centre_edge", pw, &edge));
    if (!err.empty()) return Error{err};
    if (edge != "left" && edge != "right")
      return Error{pw + ".centre_edge: must be 'left' or 'right'"};
    p.panel.centre_edge_left = edge == "left";
    if (pj.contains("darts")) {
      if (!pj["darts"].is_array()) return Error{w + ".darts: must be an array"};
      for (size_t k = 0; k < pj["darts"].size(); ++k) {
        const json& dj = pj["darts"][k];
        const std::string dw = w + ".darts[" + std::to_string(k) + "]";
        if (!dj.is_object()) return Error{dw + ": must be an object"};
        DartSlit s;
        for (const char* req : {"position", "depth", "intake"})
          if (!dj.contains(req)) return Error{dw + "." + req + ": missing"};
        check(get_num(dj, "position", dw, &s.position));
        check(get_num(dj, "depth", dw, &s.depth));
        check(get_num(dj, "intake", dw, &s.intake));
        if (!err.empty()) return Error{err};
        p.panel.slits.push_back(s);
      }
    }
    // Field-named validation of the panel itself (slits off the panel, overlapping...).
    std::string perr = validate_panel(p.panel, pw);
    if (!perr.empty()) {
      // validate_panel names slits "slits[i]"; the design calls them "darts[i]".
      const size_t at = perr.find(".slits[");
      if (at != std::string::npos) perr = w + ".darts[" + perr.substr(at + 7);
      return Error{perr};
    }
    d.pieces.push_back(p);
  }
  return d;
}

Result<Design> load_design(const std::string& path) {
  std::ifstream f(path);
  if (!f) return Error{path + ": cannot open the design file"};
  std::stringstream ss;
  ss << f.rdbuf();
  return parse_design(ss.str(), path);
}

std::string PipelineReport::to_json() const {
  json j;
  j["design"] = design;
  j["form"] = form;
  j["ease_mm"] = ease_mm;
  j["form_hip_girth_mm"] = form_hip_girth_mm;
  j["form_waist_girth_mm"] = form_waist_girth_mm;
  j["hip_width_sum_mm"] = hip_width_sum_mm;
  j["hip_width_error_mm"] = hip_width_error_mm;
  j["waist_width_minus_intakes_sum_mm"] = waist_width_minus_intakes_sum_mm;
  j["waist_width_error_mm"] = waist_width_error_mm;
  j["area_error_pct"] = area_error_pct;
  j["garment_hip_girth_mm"] = garment_hip_girth_mm;
  j["garment_hip_girth_error_pct"] = garment_hip_girth_error_pct;
  j["garment_waist_girth_mm"] = garment_waist_girth_mm;
  j["garment_waist_girth_error_pct"] = garment_waist_girth_error_pct;
  j["flare"] = flare;
  j["hem_sweep_mm"] = hem_sweep_mm;
  j["pattern_hip_girth_mm"] = pattern_hip_girth_mm;
  j["garment_hip_line_mm"] = garment_hip_line_mm;
  j["garment_hip_girth_vs_pattern_pct"] = garment_hip_girth_vs_pattern_pct;
  j["outline_error_before_relax_mm"] = outline_error_before_relax_mm;
  j["quarter_difference_mm"] = quarter_difference_mm;
  j["relax_backend"] = relax_backend;
  j["timing_ms"] = {{"mapping_extraction", mapping_extraction_ms},
                    {"relax", relax_ms},
                    {"remesh", remesh_ms},
                    {"sew", sew_ms},
                    {"export", export_ms}};
  j["pipeline_ms"] = pipeline_ms;
  j["files"] = files;
  for (const PieceReport& p : pieces) {
    json pj;
    pj["name"] = p.name;
    pj["hip_width_mm"] = p.hip_width_mm;
    pj["waist_width_mm"] = p.waist_width_mm;
    pj["waist_seam_mm"] = p.waist_seam_mm;
    double total = 0;
    for (double v : p.dart_intake_mm) total += v;
    pj["darts"] = json::array();
    for (size_t k = 0; k < p.dart_intake_mm.size(); ++k)
      pj["darts"].push_back(
          {{"intake_mm", p.dart_intake_mm[k]},
           {"intake_wanted_mm", p.dart_intake_wanted_mm[k]},
           {"fraction_of_quarter_difference",
            quarter_difference_mm > 0 ? p.dart_intake_mm[k] / quarter_difference_mm : 0}});
    pj["dart_intake_total_mm"] = total;
    pj["side_shaping_mm"] = quarter_difference_mm - total;
    pj["outline_error_before_relax_mm"] = p.outline_error_before_relax_mm;
    pj["area_piece_cm2"] = p.area_piece_cm2;
    pj["area_draped_cm2"] = p.area_draped_cm2;
    pj["area_error_pct"] = p.area_error_pct;
    const auto grain = [](const GrainDeviation& g) {
      return json{{"zone_mean_tilt_deg", g.zone_mean_tilt_deg},
                  {"zone_max_tilt_deg", g.zone_max_tilt_deg},
                  {"max_tilt_near_darts_deg", g.max_tilt_near_darts_deg},
                  {"max_kink_near_darts_deg", g.max_kink_near_darts_deg},
                  {"max_kink_deg", g.max_kink_deg}};
    };
    pj["grain_deviation_mapped"] = grain(p.grain_before);
    pj["grain_deviation_relaxed"] = grain(p.grain_after);
    pj["relax"] = {{"backend", p.relax.backend},
                   {"iterations", p.relax.iterations},
                   {"max_strain", p.relax.max_strain},
                   {"rms_strain", p.relax.rms_strain},
                   {"ms", p.relax.ms}};
    pj["fairness_deg_per_mm"] = json::object();
    for (const auto& [label, f] : p.fairness_deg_per_mm) pj["fairness_deg_per_mm"][label] = f;
    pj["remesh"] = {{"vertices", p.remesh_vertices},
                    {"triangles", p.remesh_triangles},
                    {"min_angle_deg", p.remesh_min_angle_deg},
                    {"max_edge_mm", p.remesh_max_edge_mm}};
    pj["hem_mm"] = p.hem_mm;
    pj["spread_deg"] = p.spread_deg;
    j["pieces"].push_back(pj);
  }
  return j.dump(2);
}

Result<PipelineResult> run_pattern_pipeline(const Design& design_in, const DressForm& form,
                                            const FabricParams& fabric,
                                            const PipelineOptions& opt) {
  const auto t_all = Clock::now();
  PipelineResult R;
  R.design = design_in;
  Design& d = R.design;
  if (opt.ease >= 0) d.ease = opt.ease;
  if (opt.seam_allowance >= 0) d.seam_allowance = opt.seam_allowance;
  if (opt.remesh_edge > 0) d.remesh_edge = opt.remesh_edge;
  if (opt.relax_iterations >= 0) d.relax_iterations = opt.relax_iterations;
  const FormLandmarks& lm = form.landmarks();
  const MappingSurface surf(form, d.ease, true);
  PieceLines lines;
  lines.waist_y = lm.waist_y;
  lines.hip_y = lm.hip_y;
  lines.hem_y = lm.waist_y - d.length_below_waist;
  PipelineReport& rep = R.report;
  rep.design = d.name;
  rep.form = d.form;
  rep.ease_mm = d.ease * 1000;
  rep.flare = d.flare;
  rep.form_hip_girth_mm = form.girth_at(lm.hip_y) * 1000;
  rep.form_waist_girth_mm = form.girth_at(lm.waist_y) * 1000;
  rep.quarter_difference_mm = (rep.form_hip_girth_mm - rep.form_waist_girth_mm) / 4;
  double hip_sum = 0, waist_sum = 0;
  for (size_t i = 0; i < d.pieces.size(); ++i) {
    PieceDesign pd = d.pieces[i];
    const std::string where = d.name + ": pieces[" + std::to_string(i) + "].panel";
    if (opt.spacing > 0) pd.panel.spacing = opt.spacing;
    const double top_y = lm.waist_y + pd.panel.top_above_waist;
    if (std::string e = validate_panel(pd.panel, where, &form, d.ease, top_y); !e.empty())
      return Error{e};
    if (top_y - pd.panel.height >
        (pd.bottom_line == "hip" ? lines.hip_y : lines.hem_y) - pd.panel.spacing)
      return Error{where + ".height: the panel does not reach the " + pd.bottom_line + " line"};
    auto panel = build_panel(pd.panel, fabric, where);
    if (!panel) return Error{panel.error()};
    const double th_c = line_theta(pd.centre_line, lm), th_s = line_theta(pd.side_line, lm);
    double delta = std::fmod(th_s - th_c + 3 * kPi, 2 * kPi) - kPi;
    const int dir = delta < 0 ? -1 : 1;
    PieceLines pl = lines;
    pl.centre_label = pd.centre_line;
    if (pd.bottom_line == "hip") pl.hem_y = lines.hip_y - 0.01;
    PieceReport pr;
    pr.name = pd.name;
    const auto t_map = Clock::now();
    const PieceMapping pm = make_piece_mapping(*panel, surf, th_c, dir, th_s, lm.waist_y);
    map_panel(*panel, surf, pm);
    ExtractOptions eo;
    eo.step = d.extraction_step;
    auto before = extract_piece(*panel, surf, pm, pl, eo);
    rep.mapping_extraction_ms += ms_since(t_map);
    if (!before) return Error{d.name + ": pieces[" + std::to_string(i) + "]: " + before.error()};
    pr.outline_error_before_relax_mm = outline_error_vs_mapping(*before, *panel, surf, pm) * 1000;
    pr.grain_before = measure_grain(*panel, surf, pl.hem_y, lm.waist_y);
    PanelRelaxOptions ro;
    ro.iterations = d.relax_iterations;
    ro.use_static_solver = opt.use_static_solver;
    ro.grain_control = opt.grain_control;
    pr.relax = relax_panel(*panel, surf, pm, ro);
    rep.relax_ms += pr.relax.ms;
    rep.relax_backend = pr.relax.backend;
    pr.grain_after = measure_grain(*panel, surf, pl.hem_y, lm.waist_y);
    auto piece = extract_piece(*panel, surf, pm, pl, eo);
    if (!piece) return Error{d.name + ": pieces[" + std::to_string(i) + "]: " + piece.error()};
    piece->name = pd.name;
    piece->size = d.form;
    piece->quantity = pd.quantity;
    pr.hip_width_mm = piece->hip_width() * 1000;
    pr.waist_seam_mm = piece->seam_length("waist") * 1000;
    pr.waist_width_mm = pr.waist_seam_mm;
    for (size_t k = 0; k < piece->darts.size(); ++k) {
      pr.dart_intake_mm.push_back(piece->darts[k].intake * 1000);
      pr.dart_intake_wanted_mm.push_back(panel->slits[k].intake * 1000);
      pr.waist_width_mm += piece->darts[k].intake * 1000;
    }
    double a3 = draped_area(*piece, *panel);
    if (d.flare == "close_darts") {
      // Slash and spread: the widths are measured on the spread piece (the darts are closed,
      // so the waist seam is the whole waist width); its draped area comes from the sewn
      // garment below.
      auto sp = slash_and_spread(*piece, d.extraction_step);
      if (!sp) return Error{d.name + ": pieces[" + std::to_string(i) + "]: " + sp.error()};
      for (const SpreadStep& st : sp->steps) pr.spread_deg.push_back(st.angle * 180 / kPi);
      pr.hip_width_mm = sp->hip_width * 1000;
      for (const SpreadStep& st : sp->steps) rep.pattern_hip_girth_mm += 2 * st.hip_gap * 1000;
      pr.hem_mm = sp->hem_length * 1000;
      *piece = sp->piece;
      pr.waist_seam_mm = piece->seam_length("waist") * 1000;
      R.spread.push_back(std::move(*sp));
    } else {
      pr.hem_mm = piece->seam_length("hem") * 1000;
    }
    rep.hem_sweep_mm += 2 * pr.hem_mm;
    for (const std::string& label : piece->labels)
      pr.fairness_deg_per_mm.emplace_back(label, seam_fairness(*piece, label));
    const double a2 = std::abs(piece->area());
    pr.area_piece_cm2 = a2 * 1e4;
    pr.area_draped_cm2 = a3 * 1e4;
    pr.area_error_pct = a3 > 0 ? std::abs(a2 - a3) / a3 * 100 : 100;
    rep.area_error_pct = std::max(rep.area_error_pct, pr.area_error_pct);
    rep.outline_error_before_relax_mm =
        std::max(rep.outline_error_before_relax_mm, pr.outline_error_before_relax_mm);
    hip_sum += 2 * pr.hip_width_mm;  // right piece + its mirror image
    waist_sum += 2 * pr.waist_seam_mm;
    const auto t_rm = Clock::now();
    RemeshOptions rmo;
    rmo.max_edge = d.remesh_edge;
    auto mesh = remesh_piece(*piece, rmo);
    rep.remesh_ms += ms_since(t_rm);
    if (!mesh) return Error{mesh.error()};
    pr.remesh_vertices = static_cast<int>(mesh->material.size());
    pr.remesh_triangles = static_cast<int>(mesh->triangles.size());
    pr.remesh_min_angle_deg = mesh->min_angle_deg;
    pr.remesh_max_edge_mm = mesh->max_edge * 1000;
    R.panels.push_back(std::move(*panel));
    R.mappings.push_back(pm);
    R.pieces.push_back(std::move(*piece));
    R.meshes.push_back(std::move(*mesh));
    rep.pieces.push_back(pr);
  }
  rep.hip_width_sum_mm = hip_sum;
  rep.pattern_hip_girth_mm += hip_sum;
  rep.hip_width_error_mm = hip_sum - (rep.form_hip_girth_mm + rep.ease_mm);
  rep.waist_width_minus_intakes_sum_mm = waist_sum;
  rep.waist_width_error_mm = waist_sum - (rep.form_waist_girth_mm + rep.ease_mm);
  // Mirror, sew, relax the garment.
  const auto t_sew = Clock::now();
  std::vector<SewInput> in;
  for (size_t i = 0; i < R.pieces.size(); ++i) {
    in.push_back({&R.pieces[i], &R.meshes[i], &R.panels[i], {}});
    if (!R.spread.empty()) in.back().place = cone_placement(R, i, surf);
  }
  SewOptions so;
  so.mirror_x = surf.centre(lm.waist_y).x();
  so.relax_iterations = d.relax_iterations;
  so.waist_y = lm.waist_y;
  // The flare hangs: no pressure pulls a spread garment onto the form (it stands away below the
  // dart tips; measured with the pressure: sewn hip line -3.4 % of the pattern's).
  if (!R.spread.empty()) so.pressure_step = 0;
  auto garment = sew_garment(in, surf, so);
  if (!garment) return Error{garment.error()};
  R.garment = std::move(*garment);
  rep.sew_ms = ms_since(t_sew);
  rep.garment_hip_girth_mm = garment_girth(R.garment, surf, lm.hip_y) * 1000;
  const double target = rep.form_hip_girth_mm + rep.ease_mm;
  rep.garment_hip_girth_error_pct = (rep.garment_hip_girth_mm - target) / target * 100;
  for (size_t i = 0; i < R.pieces.size(); ++i)
    for (int half = 0; half < 2; ++half)
      rep.garment_hip_line_mm += garment_line_length(R.garment, static_cast<int>(2 * i + half),
                                                     R.pieces[i].hip_line, half == 1) *
                                 1000;
  rep.garment_hip_girth_vs_pattern_pct =
      (rep.garment_hip_line_mm - rep.pattern_hip_girth_mm) / rep.pattern_hip_girth_mm * 100;
  rep.garment_waist_girth_mm = garment_girth(R.garment, surf, lm.waist_y) * 1000;
  const double waist_target = rep.form_waist_girth_mm + rep.ease_mm;
  rep.garment_waist_girth_error_pct =
      (rep.garment_waist_girth_mm - waist_target) / waist_target * 100;
  if (!R.spread.empty()) {
    // A spread piece's draped area: its right half in the sewn, relaxed garment.
    rep.area_error_pct = 0;
    for (size_t i = 0; i < R.pieces.size(); ++i) {
      PieceReport& pr = rep.pieces[i];
      pr.area_draped_cm2 = garment_piece_area(R.garment, static_cast<int>(2 * i)) * 1e4;
      pr.area_error_pct =
          pr.area_draped_cm2 > 0
              ? std::abs(pr.area_piece_cm2 - pr.area_draped_cm2) / pr.area_draped_cm2 * 100
              : 100;
      rep.area_error_pct = std::max(rep.area_error_pct, pr.area_error_pct);
    }
  }
  // Files.
  if (!opt.out_dir.empty()) {
    const auto t_ex = Clock::now();
    std::error_code ec;
    std::filesystem::create_directories(opt.out_dir, ec);
    if (ec) return Error{opt.out_dir + ": cannot create the output directory: " + ec.message()};
    const std::string o = opt.out_dir + "/";
    ExportOptions xo;
    xo.seam_allowance = d.seam_allowance;
    xo.style = d.name;
    std::string e;
    const auto out = [&](const std::string& f, std::string err) {
      if (e.empty() && !err.empty()) e = err;
      rep.files.push_back(f);
    };
    out("pattern.svg", write_svg(o + "pattern.svg", R.pieces, xo));
    out("pattern.dxf", write_dxf(o + "pattern.dxf", R.pieces, xo));
    out("pattern_a4.pdf", write_pdf(o + "pattern_a4.pdf", R.pieces, xo, Paper::a4()));
    out("pattern_letter.pdf", write_pdf(o + "pattern_letter.pdf", R.pieces, xo, Paper::letter()));
    std::vector<TriMesh> draped;
    for (size_t i = 0; i < R.panels.size(); ++i)
      draped.push_back(panel_mesh(R.panels[i], R.pieces[i].name));
    out("draped_panels.gltf", write_meshes(o + "draped_panels.gltf", draped));
    out("garment.gltf", write_meshes(o + "garment.gltf", {garment_to_mesh(R.garment, d.name)}));
    if (!e.empty()) return Error{e};
    rep.export_ms = ms_since(t_ex);
    rep.pipeline_ms = ms_since(t_all);
    std::ofstream f(o + "report.json");
    f << rep.to_json() << "\n";
    if (!f) return Error{o + "report.json: write failed"};
    rep.files.push_back("report.json");
  }
  rep.pipeline_ms = ms_since(t_all);
  return R;
}

}  // namespace drape::sim
