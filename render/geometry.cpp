// CPU geometry of a frame (render/geometry.hpp).
#include "render/geometry.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/core/strain.hpp"
#include "sim/form/dress_form.hpp"

namespace drape::render {
namespace {

using V3 = Eigen::Vector3f;
constexpr float kPi = 3.14159265358979323846f;

Vertex make_vertex(const V3& p, const V3& n, const std::array<float, 3>& rgb, ShadeMode mode,
                   float u = 0, float v = 0, float cx = 0, float cz = 0, float s = 0) {
  return Vertex{{p.x(), p.y(), p.z()},
                {n.x(), n.y(), n.z()},
                {u, v},
                {rgb[0], rgb[1], rgb[2], 1.0f},
                {static_cast<float>(static_cast<int>(mode)), cx, cz, s}};
}

void add_quad(Mesh& out, const V3& a, const V3& b, const V3& c, const V3& d, const V3& n,
              const std::array<float, 3>& rgb, ShadeMode mode) {
  const auto base = static_cast<uint32_t>(out.vertices.size());
  for (const V3* p : {&a, &b, &c, &d}) out.vertices.push_back(make_vertex(*p, n, rgb, mode));
  for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) out.indices.push_back(base + i);
}

// Any unit vector perpendicular to d.
V3 perpendicular(const V3& d) {
  V3 p = std::abs(d.y()) < 0.9f ? d.cross(V3::UnitY()) : d.cross(V3::UnitX());
  return p.normalized();
}

}  // namespace

void append_sphere(Mesh& out, const V3& c, float r, const std::array<float, 3>& rgb, ShadeMode mode,
                   int slices, int stacks) {
  const auto base = static_cast<uint32_t>(out.vertices.size());
  for (int i = 0; i <= stacks; ++i) {
    const float phi = kPi * i / stacks;
    for (int k = 0; k <= slices; ++k) {
      const float th = 2.0f * kPi * k / slices;
      const V3 n(std::sin(phi) * std::sin(th), std::cos(phi), std::sin(phi) * std::cos(th));
      out.vertices.push_back(make_vertex(c + r * n, n, rgb, mode));
    }
  }
  const auto row = static_cast<uint32_t>(slices + 1);
  for (int i = 0; i < stacks; ++i)
    for (int k = 0; k < slices; ++k) {
      const uint32_t a = base + i * row + k, b = a + row;
      for (uint32_t q : {a, b, a + 1, a + 1, b, b + 1}) out.indices.push_back(q);
    }
}

void append_box(Mesh& out, const V3& c, const V3& h, const std::array<float, 3>& rgb) {
  for (int axis = 0; axis < 3; ++axis)
    for (float sgn : {-1.0f, 1.0f}) {
      V3 n = V3::Zero();
      n[axis] = sgn;
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      V3 corner[4];
      const float s1[4] = {-1, 1, 1, -1}, s2[4] = {-1, -1, 1, 1};
      for (int q = 0; q < 4; ++q) {
        V3 p = c;
        p[axis] += sgn * h[axis];
        p[a1] += s1[q] * h[a1];
        p[a2] += s2[q] * h[a2];
        corner[q] = p;
      }
      add_quad(out, corner[0], corner[1], corner[2], corner[3], n, rgb, ShadeMode::kLit);
    }
}

void append_tube(Mesh& out, const V3& a, const V3& b, float r, const std::array<float, 3>& rgb,
                 ShadeMode mode, int sides) {
  const V3 d = b - a;
  if (d.norm() < 1e-7f) return;
  const V3 e1 = perpendicular(d.normalized()), e2 = d.normalized().cross(e1);
  const auto base = static_cast<uint32_t>(out.vertices.size());
  for (int k = 0; k <= sides; ++k) {
    const float t = 2.0f * kPi * k / sides;
    const V3 n = std::cos(t) * e1 + std::sin(t) * e2;
    out.vertices.push_back(make_vertex(a + r * n, n, rgb, mode));
    out.vertices.push_back(make_vertex(b + r * n, n, rgb, mode));
  }
  for (int k = 0; k < sides; ++k) {
    const uint32_t i = base + 2 * k;
    for (uint32_t q : {i, i + 2, i + 1, i + 1, i + 2, i + 3}) out.indices.push_back(q);
  }
}

float form_distance(const sim::DressForm& form, const V3& p) {
  const int ns = form.num_sections();
  if (ns < 2 || form.section_spacing() <= 0) return std::numeric_limits<float>::infinity();
  const double t = (p.y() - form.min_y()) / form.section_spacing();
  if (t < 0 || t > ns - 1) return std::numeric_limits<float>::infinity();
  const int j0 = std::min(static_cast<int>(t), ns - 2);
  const double fj = t - j0;
  const sim::Vec2 c = (1 - fj) * form.centre(j0) + fj * form.centre(j0 + 1);
  const double dx = p.x() - c.x(), dz = p.z() - c.y();
  double theta = std::atan2(dx, dz);
  if (theta < 0) theta += 2 * 3.14159265358979323846;
  const double a = theta / (2 * 3.14159265358979323846) * sim::DressForm::kAngles;
  const int n0 = static_cast<int>(a) % sim::DressForm::kAngles;
  const int n1 = (n0 + 1) % sim::DressForm::kAngles;
  const double fn = a - std::floor(a);
  const double r0 = (1 - fn) * form.radius(j0, n0) + fn * form.radius(j0, n1);
  const double r1 = (1 - fn) * form.radius(j0 + 1, n0) + fn * form.radius(j0 + 1, n1);
  return static_cast<float>(std::sqrt(dx * dx + dz * dz) - ((1 - fj) * r0 + fj * r1));
}

FormLod form_lod_for_pixels(float rad_per_pixel, float quad_px) {
  FormLod lod;
  if (!(rad_per_pixel > 0) || !(quad_px > 0)) return lod;
  const float quad_m = quad_px * rad_per_pixel;  // at 1 m
  lod.section_spacing = std::clamp(quad_m, 0.008f, 0.03f);
  constexpr float kGirth = 1.3f;  // m, a generous bust girth
  lod.angle_step = 1;
  while (lod.angle_step < 32 &&
         kGirth / (sim::DressForm::kAngles / (2.0f * lod.angle_step)) <= lod.section_spacing)
    lod.angle_step *= 2;
  return lod;
}

void append_form(const sim::DressForm& form, float max_spacing, const DrawOptions& opt, Mesh& out) {
  const int ns = form.num_sections();
  // Every astep-th of the form's angles (a power of two dividing kAngles).
  int astep = 1;
  while (astep < 32 && 2 * astep <= opt.form_angle_step) astep *= 2;
  const int na = sim::DressForm::kAngles / astep;
  if (ns < 2) return;
  // Keep every step-th section (and the last) so the drawn grid is about max_spacing apart.
  const int step = std::max(1, static_cast<int>(max_spacing / form.section_spacing()));
  std::vector<int> rows;
  for (int j = 0; j < ns - 1; j += step) rows.push_back(j);
  rows.push_back(ns - 1);
  const int nr = static_cast<int>(rows.size());
  std::vector<V3> pts(static_cast<size_t>(nr) * na);
  for (int i = 0; i < nr; ++i) {
    const int j = rows[i];
    const sim::Vec2 c = form.centre(j);
    for (int n = 0; n < na; ++n) {
      const double th = sim::DressForm::theta(n * astep), r = form.radius(j, n * astep);
      pts[static_cast<size_t>(i) * na + n] =
          V3(static_cast<float>(c.x() + r * std::sin(th)), static_cast<float>(form.section_y(j)),
             static_cast<float>(c.y() + r * std::cos(th)));
    }
  }
  const auto P = [&](int i, int n) -> const V3& {
    return pts[static_cast<size_t>(std::clamp(i, 0, nr - 1)) * na + ((n + na) % na)];
  };
  const auto base = static_cast<uint32_t>(out.vertices.size());
  for (int i = 0; i < nr; ++i) {
    const sim::Vec2 c = form.centre(rows[i]);
    const float cx = static_cast<float>(c.x()), cz = static_cast<float>(c.y());
    for (int n = 0; n < na; ++n) {
      const V3 ta = P(i, n + 1) - P(i, n - 1), th = P(i + 1, n) - P(i - 1, n);
      V3 nrm = th.cross(ta);
      const V3 radial(P(i, n).x() - cx, 0, P(i, n).z() - cz);
      if (nrm.dot(radial) < 0) nrm = -nrm;
      nrm = nrm.norm() > 1e-12f ? nrm.normalized() : radial.normalized();
      out.vertices.push_back(
          make_vertex(P(i, n), nrm, opt.form_colour, ShadeMode::kForm, 0, 0, cx, cz));
    }
  }
  for (int i = 0; i + 1 < nr; ++i)
    for (int n = 0; n < na; ++n) {
      const uint32_t a = base + i * na + n, b = base + i * na + (n + 1) % na;
      for (uint32_t q : {a, b, a + na, b, b + na, a + na}) out.indices.push_back(q);
    }
  // Caps: flat discs at the bottom and top sections.
  for (int cap = 0; cap < 2; ++cap) {
    const int i = cap == 0 ? 0 : nr - 1;
    const sim::Vec2 c = form.centre(rows[i]);
    const V3 n(0, cap == 0 ? -1.0f : 1.0f, 0);
    const auto cb = static_cast<uint32_t>(out.vertices.size());
    const V3 centre(static_cast<float>(c.x()), P(i, 0).y(), static_cast<float>(c.y()));
    out.vertices.push_back(make_vertex(centre, n, opt.form_colour, ShadeMode::kLit));
    for (int k = 0; k < na; ++k)
      out.vertices.push_back(make_vertex(P(i, k), n, opt.form_colour, ShadeMode::kLit));
    for (int k = 0; k < na; ++k) {  // counter-clockwise seen from outside (below / above)
      out.indices.push_back(cb);
      out.indices.push_back(cb + 1 + (cap == 0 ? (k + 1) % na : k));
      out.indices.push_back(cb + 1 + (cap == 0 ? k : (k + 1) % na));
    }
  }
}

void vertex_normals(const std::vector<sim::Vec3f>& pos, const std::vector<uint32_t>& idx,
                    std::vector<sim::Vec3f>& normals) {
  normals.assign(pos.size(), sim::Vec3f::Zero());
  for (size_t t = 0; t + 2 < idx.size(); t += 3) {
    const uint32_t a = idx[t], b = idx[t + 1], c = idx[t + 2];
    if (a >= pos.size() || b >= pos.size() || c >= pos.size()) continue;
    const sim::Vec3f n = (pos[b] - pos[a]).cross(pos[c] - pos[a]);  // |n| = 2 area
    normals[a] += n;
    normals[b] += n;
    normals[c] += n;
  }
  for (auto& n : normals) {
    const float l = n.norm();
    n = l > 1e-20f ? sim::Vec3f(n / l) : sim::Vec3f(0, 1, 0);
  }
}

void material_strain(const std::vector<sim::Vec3f>& pos, const std::vector<sim::Vec2f>& mat,
                     const std::vector<uint32_t>& idx, std::vector<float>& strain) {
  strain.assign(pos.size(), 0.0f);
  std::vector<float> weight(pos.size(), 0.0f);
  if (mat.size() != pos.size()) return;
  for (size_t t = 0; t + 2 < idx.size(); t += 3) {
    const uint32_t a = idx[t], b = idx[t + 1], c = idx[t + 2];
    if (a >= pos.size() || b >= pos.size() || c >= pos.size()) continue;
    const sim::TriangleStrain<float> ts =
        sim::triangle_strain_of(pos[a], pos[b], pos[c], mat[a], mat[b], mat[c], 1e-12f);
    if (ts.area == 0) continue;
    const float area = ts.area, s = ts.strain;
    for (uint32_t v : {a, b, c}) {
      strain[v] += area * s;
      weight[v] += area;
    }
  }
  for (size_t i = 0; i < strain.size(); ++i)
    if (weight[i] > 0) strain[i] /= weight[i];
}

void append_cloth(const sim::SceneSnapshot& snap, const DrawOptions& opt, Mesh& out) {
  const size_t nv = snap.positions.size();
  if (nv == 0 || snap.indices.size() < 3) return;
  std::vector<sim::Vec3f> computed;
  const std::vector<sim::Vec3f>* normals = &snap.normals;
  if (snap.normals.size() != nv) {
    vertex_normals(snap.positions, snap.indices, computed);
    normals = &computed;
  }
  const bool have_uv = snap.material.size() == nv;
  std::vector<float> own_strain;
  const std::vector<float>* strain_values = &snap.strain;
  if (opt.colour_map == ColourMap::kStrain && snap.strain.size() != nv) {
    material_strain(snap.positions, snap.material, snap.indices, own_strain);
    strain_values = &own_strain;
  }
  const bool strain = opt.colour_map == ColourMap::kStrain && strain_values->size() == nv;
  const bool ease = opt.colour_map == ColourMap::kEase && snap.form != nullptr;
  const auto base = static_cast<uint32_t>(out.vertices.size());
  out.vertices.reserve(out.vertices.size() + nv);
  for (size_t i = 0; i < nv; ++i) {
    float s = 0;
    if (strain) s = std::clamp((*strain_values)[i] / opt.strain_range, -1.0f, 1.0f);
    if (ease) {
      const float d = form_distance(*snap.form, snap.positions[i]);
      s = std::isfinite(d) ? std::clamp(d / opt.ease_range, 0.0f, 1.0f) : 1.0f;
    }
    const sim::Vec2f uv = have_uv ? snap.material[i] : sim::Vec2f::Zero();
    out.vertices.push_back(make_vertex(snap.positions[i], (*normals)[i], opt.cloth_colour,
                                       ShadeMode::kCloth, uv.x(), uv.y(), 0, 0, s));
  }
  for (size_t t = 0; t + 2 < snap.indices.size(); t += 3) {
    const uint32_t a = snap.indices[t], b = snap.indices[t + 1], c = snap.indices[t + 2];
    if (a >= nv || b >= nv || c >= nv) continue;  // a malformed triangle is skipped, not drawn
    out.indices.insert(out.indices.end(), {base + a, base + b, base + c});
  }
}

namespace {
// The floating square panel of DrawOptions (centre, yaw, size): its axes and the map from flat
// pattern coordinates (m) onto it, the given extent fitted into 85 % of it.
struct PanelFrame {
  V3 right, up, normal, centre;
  float half = 0, scale = 0;
  Eigen::Vector2f mid = Eigen::Vector2f::Zero();
  V3 at(const Eigen::Vector2f& q, float lift = 0.002f) const {
    const Eigen::Vector2f s = (q - mid) * scale;
    return centre + s.x() * right + s.y() * up + lift * normal;
  }
};

PanelFrame panel_frame(const DrawOptions& opt, const Eigen::Vector2f& lo,
                       const Eigen::Vector2f& hi) {
  PanelFrame f;
  f.right = V3(std::cos(opt.panel_yaw), 0, -std::sin(opt.panel_yaw));
  f.up = V3::UnitY();
  f.normal = f.right.cross(f.up);
  f.centre = opt.panel_centre;
  f.half = 0.5f * opt.panel_size;
  const float ext = std::max(hi.x() - lo.x(), hi.y() - lo.y());
  f.scale = ext > 1e-9f ? 0.85f * opt.panel_size / ext : 0.0f;
  f.mid = 0.5f * (lo + hi);
  return f;
}

void add_panel_background(const PanelFrame& f, Mesh& out) {
  const V3 c = f.centre, r = f.half * f.right, u = f.half * f.up;
  add_quad(out, c - r - u, c + r - u, c + r + u, c - r + u, f.normal, {0.93f, 0.93f, 0.90f},
           ShadeMode::kUnlit);
}

// A flat line of half width w from a to b on the panel (already mapped).
void add_panel_line(const PanelFrame& f, const V3& a, const V3& b, float w,
                    const std::array<float, 3>& rgb, Mesh& out) {
  if ((b - a).norm() < 1e-7f) return;
  const V3 side = (b - a).normalized().cross(f.normal) * w;
  add_quad(out, a - side, b - side, b + side, a + side, f.normal, rgb, ShadeMode::kUnlit);
}

void add_panel_loop(const PanelFrame& f, const std::vector<Eigen::Vector2f>& loop, float w,
                    const std::array<float, 3>& rgb, Mesh& out) {
  for (size_t i = 0; i < loop.size(); ++i)
    add_panel_line(f, f.at(loop[i]), f.at(loop[(i + 1) % loop.size()]), w, rgb, out);
}

void extend_bounds(const std::vector<Eigen::Vector2f>& pts, Eigen::Vector2f& lo,
                   Eigen::Vector2f& hi) {
  for (const auto& q : pts) {
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
}

void append_outline_panel(const std::vector<std::vector<Eigen::Vector2f>>& outlines,
                          const DrawOptions& opt, Mesh& out) {
  Eigen::Vector2f lo(1e30f, 1e30f), hi(-1e30f, -1e30f);
  for (const auto& o : outlines) extend_bounds(o, lo, hi);
  const PanelFrame f = panel_frame(opt, lo, hi);
  add_panel_background(f, out);
  if (f.scale <= 0) return;
  for (const auto& o : outlines) add_panel_loop(f, o, 0.0022f, {0.1f, 0.15f, 0.45f}, out);
}

// The grain line with an arrow head at each end (a pattern's "place on grain" mark).
void add_grain_arrow(const PanelFrame& f, const BoardPiece& p, Mesh& out) {
  const V3 a = f.at(p.grain_a, 0.003f), b = f.at(p.grain_b, 0.003f);
  if ((b - a).norm() < 1e-5f) return;
  const std::array<float, 3> red{0.75f, 0.1f, 0.1f};
  add_panel_line(f, a, b, 0.0015f, red, out);
  const V3 d = (b - a).normalized(), side = d.cross(f.normal);
  const float len = std::min(0.015f, 0.3f * (b - a).norm());
  for (const auto& [tip, dir] : {std::pair{b, d}, std::pair{a, V3(-d)}}) {
    add_panel_line(f, tip, tip - len * dir + 0.5f * len * side, 0.0015f, red, out);
    add_panel_line(f, tip, tip - len * dir - 0.5f * len * side, 0.0015f, red, out);
  }
}

// A notch: a short stroke across the outline, pointing into the piece (towards its centroid).
void add_notches(const PanelFrame& f, const BoardPiece& p, Mesh& out) {
  if (p.outline.empty()) return;
  Eigen::Vector2f c = Eigen::Vector2f::Zero();
  for (const auto& q : p.outline) c += q;
  c /= static_cast<float>(p.outline.size());
  for (const auto& n : p.notches) {
    const V3 a = f.at(n, 0.003f), inward = f.at(c, 0.003f) - a;
    if (inward.norm() < 1e-6f) continue;
    const V3 d = inward.normalized();
    add_panel_line(f, a - 0.008f * d, a + 0.016f * d, 0.003f, {0.05f, 0.5f, 0.1f}, out);
  }
}

// 10 cm of the pattern at the panel's lower left corner, with end ticks.
void add_scale_bar(const PanelFrame& f, Mesh& out) {
  const V3 a = f.centre - 0.9f * f.half * f.right - 0.93f * f.half * f.up + 0.002f * f.normal;
  const V3 b = a + 0.1f * f.scale * f.right;
  const std::array<float, 3> ink{0.1f, 0.1f, 0.1f};
  add_panel_line(f, a, b, 0.0012f, ink, out);
  for (const V3& e : {a, b}) add_panel_line(f, e, e + 0.01f * f.up, 0.0012f, ink, out);
}

void append_board(const PatternBoard& board, const DrawOptions& opt, Mesh& out) {
  Eigen::Vector2f lo(1e30f, 1e30f), hi(-1e30f, -1e30f);
  for (const auto& p : board.pieces) extend_bounds(p.outline, lo, hi);
  const PanelFrame f = panel_frame(opt, lo, hi);
  add_panel_background(f, out);
  if (f.scale <= 0) return;
  for (const auto& p : board.pieces) {
    add_panel_loop(f, p.outline, 0.0022f, {0.1f, 0.15f, 0.45f}, out);
    add_grain_arrow(f, p, out);
    add_notches(f, p, out);
  }
  add_scale_bar(f, out);
}
}  // namespace

void append_decorations(const sim::SceneSnapshot& snap, const DrawOptions& opt, Mesh& out) {
  const auto f = [](const sim::Vec3& v) { return V3(v.cast<float>()); };
  for (const auto& p : snap.plates) {
    const float t = static_cast<float>(p.thickness);
    append_box(out, f(p.centre) - V3(0, 0.5f * t, 0),
               V3(static_cast<float>(p.half_x), 0.5f * t, static_cast<float>(p.half_z)),
               {0.55f, 0.40f, 0.25f});
  }
  for (const auto& b : snap.boxes) append_box(out, f(b.centre), f(b.half), {0.45f, 0.55f, 0.70f});
  for (const auto& s : snap.spheres)
    append_sphere(out, f(s.centre), static_cast<float>(s.radius), {0.5f, 0.6f, 0.5f},
                  ShadeMode::kLit, 24, 16);
  for (const auto& h : snap.hands) {
    if (!h.tracked) continue;
    bool live = false;  // drawn from the frame's own pose instead (append_hand_overlays)
    for (const auto& o : opt.hands) live = live || o.id == h.id;
    if (live) continue;
    const std::array<float, 3> col = h.id == 0 ? std::array<float, 3>{0.15f, 0.65f, 0.65f}
                                               : std::array<float, 3>{0.9f, 0.5f, 0.15f};
    const float r = static_cast<float>(h.radius);
    append_sphere(out, f(h.position), r, col, ShadeMode::kLit);
    if ((h.tip - h.position).norm() > 1e-6) {
      append_sphere(out, f(h.tip), 0.5f * r, col, ShadeMode::kLit);
      append_tube(out, f(h.position), f(h.tip), 0.35f * r, col, ShadeMode::kLit);
    }
  }
  for (const auto& p : snap.pins) {
    append_sphere(out, p, 0.006f, {0.95f, 0.75f, 0.10f}, ShadeMode::kLit);
    append_tube(out, p, p + V3(0, 0.025f, 0), 0.0012f, {0.7f, 0.7f, 0.75f}, ShadeMode::kLit, 6);
  }
  for (int h = 0; h < 2; ++h) {
    const int32_t v = snap.candidate_vertex[h];
    if (v >= 0 && static_cast<size_t>(v) < snap.positions.size()) {
      append_sphere(out, snap.positions[v], 0.009f, {0.1f, 1.0f, 0.2f}, ShadeMode::kUnlit);
    } else if (snap.candidate_is_form[h]) {
      append_sphere(out, snap.candidate_point[h], 0.009f, {0.1f, 0.9f, 1.0f}, ShadeMode::kUnlit);
    }
  }
  for (const auto& stroke : snap.cut_strokes)
    for (size_t i = 0; i + 1 < stroke.size(); ++i) {
      append_tube(out, stroke[i], stroke[i + 1], 0.002f, {0.95f, 0.1f, 0.1f}, ShadeMode::kUnlit, 6);
      append_sphere(out, stroke[i + 1], 0.002f, {0.95f, 0.1f, 0.1f}, ShadeMode::kUnlit, 6, 4);
    }
  if (!opt.pattern_panel) return;
  if (opt.board)
    append_board(*opt.board, opt, out);
  else if (!snap.pattern_outlines.empty())
    append_outline_panel(snap.pattern_outlines, opt, out);
}

void append_hand_overlays(const sim::SceneSnapshot& snap, const DrawOptions& opt, Mesh& out) {
  // Bones of the XR_EXT_hand_tracking skeleton: wrist -> each finger's chain to its tip.
  static const int kChains[5][6] = {{1, 2, 3, 4, 5, -1},
                                    {1, 6, 7, 8, 9, 10},
                                    {1, 11, 12, 13, 14, 15},
                                    {1, 16, 17, 18, 19, 20},
                                    {1, 21, 22, 23, 24, 25}};
  for (const auto& m : opt.markers)
    if (m.at.allFinite()) append_sphere(out, m.at, 0.015f, m.colour, ShadeMode::kUnlit, 12, 8);
  for (const auto& h : opt.hands) {
    if (h.id != 0 && h.id != 1) continue;
    const std::array<float, 3> col = h.id == 0 ? std::array<float, 3>{0.15f, 0.65f, 0.65f}
                                               : std::array<float, 3>{0.9f, 0.5f, 0.15f};
    bool finite = h.pointer.allFinite();
    if (h.has_joints)
      for (const auto& j : h.joints) finite = finite && j.allFinite();
    if (!finite) continue;  // a bad pose is not drawn
    if (h.has_joints) {
      for (const auto& chain : kChains)
        for (int k = 0; k + 1 < 6 && chain[k + 1] >= 0; ++k) {
          const V3 &a = h.joints[chain[k]], &b = h.joints[chain[k + 1]];
          if ((b - a).norm() > 1e-5f) append_tube(out, a, b, 0.0035f, col, ShadeMode::kLit, 6);
        }
      for (int j = 1; j < 26; ++j)
        append_sphere(out, h.joints[j], 0.005f, col, ShadeMode::kLit, 8, 5);
      append_sphere(out, h.joints[0], 0.012f, col, ShadeMode::kLit, 10, 6);  // palm
    } else {
      // A controller: a short grip with the pointer at its front.
      append_tube(out, h.pointer + V3(0, -0.03f, 0.05f), h.pointer, 0.012f, col, ShadeMode::kLit,
                  8);
    }
    // The pointer: where an operation acts. White (unlit) while one is held.
    const std::array<float, 3> pc =
        h.active ? std::array<float, 3>{1.0f, 1.0f, 1.0f} : std::array<float, 3>{1.0f, 0.85f, 0.2f};
    append_sphere(out, h.pointer, h.active ? 0.008f : 0.006f, pc, ShadeMode::kUnlit, 10, 6);
    // Join the pointer to the hand's candidate (the particle or form point it would take).
    const int32_t v = snap.candidate_vertex[h.id];
    V3 target;
    bool has = false;
    if (v >= 0 && static_cast<size_t>(v) < snap.positions.size()) {
      target = snap.positions[v];
      has = true;
    } else if (snap.candidate_is_form[h.id]) {
      target = snap.candidate_point[h.id];
      has = true;
    }
    if (has && target.allFinite() && (target - h.pointer).norm() > 1e-4f)
      append_tube(out, h.pointer, target, 0.0012f, {0.1f, 1.0f, 0.2f}, ShadeMode::kUnlit, 4);
  }
}

void append_floor(Mesh& out) {
  const float s = 4.0f;
  add_quad(out, V3(-s, 0, -s), V3(s, 0, -s), V3(s, 0, s), V3(-s, 0, s), V3::UnitY(),
           {0.40f, 0.40f, 0.42f}, ShadeMode::kFloor);
}

}  // namespace drape::render
