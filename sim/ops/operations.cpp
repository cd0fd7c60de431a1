// The hand operations (docs/operations.md):
// release never frees a pinched particle, pin fixes first and offsets out of collision last,
// candidates come from the surface under the hand (ray) as well as the nearest particle.
#include "sim/ops/operations.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "sim/draping/mapping.hpp"
#include "sim/form/dress_form.hpp"

namespace drape::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string hand_name(int hand) {
  return hand == 0 ? "left hand" : "right hand";
}

bool valid_index(int hand) {
  return hand == 0 || hand == 1;
}

bool in_any_triangle(const Cloth& c, std::vector<char>& cache) {
  cache.assign(c.num_vertices(), 0);
  for (const auto& t : c.topo.triangles)
    for (int k = 0; k < 3; ++k) cache[t[k]] = 1;
  return true;
}

// Möller–Trumbore ray/triangle; returns t (or +inf) and barycentrics.
double ray_triangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c,
                    Vec3& bary) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 pv = d.cross(e2);
  const double det = e1.dot(pv);
  if (std::abs(det) < 1e-14) return kInf;
  const double inv = 1.0 / det;
  const Vec3 tv = o - a;
  const double u = tv.dot(pv) * inv;
  if (u < 0 || u > 1) return kInf;
  const Vec3 qv = tv.cross(e1);
  const double v = d.dot(qv) * inv;
  if (v < 0 || u + v > 1) return kInf;
  const double t = e2.dot(qv) * inv;
  bary = Vec3(1 - u - v, u, v);
  return t;
}

bool is_pinched_by_any(const OperationsState& s, int32_t v) {
  return s.pinched[0] == v || s.pinched[1] == v;
}

std::string mm(double m) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f mm", m * 1000.0);
  return buf;
}

// A reach as a user reads it ("3 cm", "2.5 cm").
std::string cm(double m) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g cm", m * 100.0);
  return buf;
}

}  // namespace

Vec3 hand_direction(const HandProxy& h) {
  Vec3 d = h.orientation.normalized() * Vec3(0, 0, -1);
  return d.allFinite() && d.norm() > 0 ? d.normalized() : Vec3(0, 0, -1);
}

bool hand_pose_finite(const HandProxy& h) {
  return h.position.allFinite() && h.tip.allFinite() && h.orientation.coeffs().allFinite() &&
         std::isfinite(h.radius) && h.radius >= 0 && h.orientation.coeffs().norm() > 1e-9;
}

void set_vertex_flags(Cloth& c, int32_t v, uint8_t set, uint8_t clear) {
  auto& f = c.state.flags[v];
  f = static_cast<uint8_t>((f | set) & ~clear);
  const double m = c.state.mass[v];
  c.state.inv_mass[v] = (c.is_free(v) && m > 0) ? 1.0 / m : 0.0;
}

void ops_set_hands(World& w, OperationsState& s, const std::array<HandProxy, 2>& hands) {
  for (int h = 0; h < 2; ++h) {
    if (!hand_pose_finite(hands[h])) {
      if (hands[h].tracked || s.hand_valid[h])
        w.report("hands: " + hand_name(h) + " pose is not finite: ignored, previous pose kept");
      s.hand_valid[h] = false;
      continue;
    }
    s.hands[h] = hands[h];
    s.hands[h].id = h;
    s.hand_valid[h] = hands[h].tracked;
  }
}

bool nearest_object_point(const SceneObjects& scene, const Vec3& q, Vec3& point, Vec3& normal,
                          bool& is_form) {
  double best = kInf;
  auto consider = [&](const Vec3& p, const Vec3& n, bool form) {
    const double d = (p - q).norm();
    if (d < best) best = d, point = p, normal = n, is_form = form;
  };
  if (scene.form && scene.form->num_sections() > 0) {
    const DressForm& f = *scene.form;
    const double y = std::clamp(q.y(), f.min_y(), f.max_y());
    const Vec2 c = f.centre_at(y);
    const double theta = std::atan2(q.x() - c.x(), q.z() - c.y());
    const Vec3 p = f.surface_at(y, theta);
    consider(p, DressForm::direction(theta), true);
  }
  for (const Plate& pl : scene.plates) {
    const Vec3 p(std::clamp(q.x(), pl.centre.x() - pl.half_x, pl.centre.x() + pl.half_x),
                 pl.centre.y(),
                 std::clamp(q.z(), pl.centre.z() - pl.half_z, pl.centre.z() + pl.half_z));
    consider(p, Vec3(0, 1, 0), false);
  }
  for (const Box& b : scene.boxes) {
    const Vec3 lo = b.centre - b.half, hi = b.centre + b.half;
    Vec3 p = q.cwiseMax(lo).cwiseMin(hi);
    Vec3 n(0, 1, 0);
    if (p == q) {  // inside: nearest face
      double dmin = kInf;
      for (int k = 0; k < 3; ++k) {
        if (q[k] - lo[k] < dmin) dmin = q[k] - lo[k], p = q, p[k] = lo[k], n = -Vec3::Unit(k);
        if (hi[k] - q[k] < dmin) dmin = hi[k] - q[k], p = q, p[k] = hi[k], n = Vec3::Unit(k);
      }
    } else {
      n = (q - p).normalized();
    }
    consider(p, n, false);
  }
  for (const Sphere& sp : scene.spheres) {
    Vec3 d = q - sp.centre;
    d = d.norm() > 1e-12 ? Vec3(d.normalized()) : Vec3(0, 1, 0);
    consider(sp.centre + sp.radius * d, d, false);
  }
  return best < kInf;
}

void ops_update_candidates(const World& w, OperationsState& s, const OperationParams& p) {
  const Cloth& c = w.cloth;
  const auto& x = c.state.x;
  std::vector<char> used;
  in_any_triangle(c, used);
  for (int h = 0; h < 2; ++h) {
    HandCandidates& hc = s.candidates[h];
    hc.particles.clear();
    hc.release_vertex = -1;
    hc.has_object_point = false;
    if (!s.hand_valid[h]) continue;
    const HandProxy& hp = s.hands[h];
    const double reach = std::max(p.pinch_reach, hp.radius);
    // Nearest particle, and nearest fixed particle that is not pinched (release).
    int32_t nearest = -1, fixed = -1;
    double dn = kInf, df = kInf;
    for (int32_t i = 0; i < c.num_vertices(); ++i) {
      if (!used[i]) continue;
      const double d = (x[i] - hp.position).norm();
      if (d < dn) dn = d, nearest = i;
      const uint8_t f = c.state.flags[i];
      if ((f & (kFlagPinned | kFlagKinematic)) && !(f & kFlagPinched) && !is_pinched_by_any(s, i) &&
          d < df)
        df = d, fixed = i;
    }
    if (fixed >= 0 && df <= p.release_reach) hc.release_vertex = fixed;
    // Surfaces under the hand: every triangle the pointing ray crosses, nearest first, from a
    // hand radius behind the palm (the hand may already be in the cloth).
    const Vec3 dir = hand_direction(hp);
    const Vec3 o = hp.position - dir * hp.radius;
    std::vector<std::pair<double, int32_t>> hits;
    for (int32_t ti = 0; ti < c.topo.num_triangles(); ++ti) {
      const auto& t = c.topo.triangles[ti];
      Vec3 b = Vec3::Zero();
      const double tt = ray_triangle(o, dir, x[t[0]], x[t[1]], x[t[2]], b);
      if (tt >= 0 && tt <= p.ray_length + hp.radius) {
        int k = 0;
        b.maxCoeff(&k);
        hits.push_back({tt, t[k]});
      }
    }
    std::sort(hits.begin(), hits.end());
    std::vector<Candidate> ray;
    for (const auto& [tt, v] : hits) {
      bool dup = false;
      for (const auto& cd : ray) dup = dup || cd.vertex == v;
      if (dup) continue;
      ray.push_back({v, (x[v] - hp.position).norm(), true, static_cast<int>(ray.size())});
    }
    // The nearest particle first when it is within reach (the hand is at the cloth); else the
    // first surface under the hand. The rest are alternatives (other layers).
    if (nearest >= 0 && dn <= reach) hc.particles.push_back({nearest, dn, false, 0});
    for (const auto& cd : ray) {
      if (static_cast<int>(hc.particles.size()) >= p.max_candidates) break;
      if (cd.vertex != nearest || hc.particles.empty()) hc.particles.push_back(cd);
    }
    if (nearest >= 0 && dn > reach && static_cast<int>(hc.particles.size()) < p.max_candidates) {
      bool dup = false;
      for (const auto& cd : hc.particles) dup = dup || cd.vertex == nearest;
      if (!dup) hc.particles.push_back({nearest, dn, false, 0});
    }
    hc.chosen = hc.particles.empty()
                    ? 0
                    : std::clamp(s.selected[h], 0, static_cast<int>(hc.particles.size()) - 1);
    Vec3 op, on;
    bool form = false;
    if (nearest_object_point(w.scene, hp.position, op, on, form) &&
        (op - hp.position).norm() <= p.pin_reach) {
      hc.has_object_point = true;
      hc.object_point = op;
      hc.object_normal = on;
      hc.object_is_form = form;
    }
  }
}

bool ops_pinch_begin(World& w, OperationsState& s, const OperationParams& p, int hand) {
  if (!valid_index(hand)) return w.report("pinch: no hand " + std::to_string(hand)), false;
  if (!s.hand_valid[hand])
    return w.report("pinch: " + hand_name(hand) + " not tracked: ignored"), false;
  if (s.pinched[hand] >= 0)
    return w.report("pinch: " + hand_name(hand) + " already pinches a particle"), false;
  ops_update_candidates(w, s, p);
  const HandCandidates& hc = s.candidates[hand];
  const int32_t v = hc.chosen_vertex();
  const double reach = std::max(p.pinch_reach, s.hands[hand].radius);
  if (v < 0 || hc.particles[hc.chosen].distance > reach)
    return w.report("pinch: nothing within " + cm(reach) + " of the " + hand_name(hand) +
                    " to pinch"),
           false;
  if (is_pinched_by_any(s, v))
    return w.report("pinch: that particle is held by the other hand: ignored"), false;
  if (w.cloth.state.flags[v] & kFlagKinematic)
    return w.report("pinch: that particle is being moved: ignored"), false;
  s.pinched[hand] = v;
  set_vertex_flags(w.cloth, v, kFlagPinched, kFlagPinned);
  auto& st = w.cloth.state;
  st.x[v] = s.hands[hand].position;
  st.x_prev[v] = st.x[v];
  st.v[v].setZero();
  // A pin still settling on this particle is superseded.
  std::erase_if(s.settling, [v](const SettlingPin& sp) { return sp.vertex == v; });
  return true;
}

bool ops_pinch_end(World& w, OperationsState& s, int hand) {
  if (!valid_index(hand) || s.pinched[hand] < 0)
    return w.report("pinch end: nothing pinched by the " + hand_name(hand)), false;
  const int32_t v = s.pinched[hand];
  s.pinched[hand] = -1;
  if (v < w.cloth.num_vertices()) {
    set_vertex_flags(w.cloth, v, 0, kFlagPinched | kFlagPinned);
    w.cloth.state.v[v].setZero();
    w.cloth.state.x_prev[v] = w.cloth.state.x[v];
  }
  return true;
}

bool ops_release(World& w, OperationsState& s, const OperationParams& p, int hand) {
  if (!valid_index(hand)) return w.report("release: no hand " + std::to_string(hand)), false;
  if (!s.hand_valid[hand])
    return w.report("release: " + hand_name(hand) + " not tracked: ignored"), false;
  ops_update_candidates(w, s, p);
  const int32_t v = s.candidates[hand].release_vertex;
  if (v < 0)
    return w.report("release: no fixed particle (other than pinched ones) within " +
                    mm(p.release_reach) + " of the " + hand_name(hand) + ": ignored"),
           false;
  for (int h = 0; h < 2; ++h)
    if (s.move_vertex[h] == v) s.move_vertex[h] = -1;  // a released corner no longer follows
  std::erase_if(s.settling, [v](const SettlingPin& sp) { return sp.vertex == v; });
  set_vertex_flags(w.cloth, v, 0, kFlagPinned | kFlagKinematic);
  return true;
}

// The particle a pin takes: the one the hand pinches, else the cloth under the hand (a pattern
// maker also pins muslin where the hand lays it on the form; a tracked hand cannot hold a
// thumb-index pinch while it makes the pin gesture). -1 with the reason reported.
static int32_t pin_particle(World& w, const OperationsState& s, const OperationParams& p,
                            int hand) {
  if (s.pinched[hand] >= 0) return s.pinched[hand];
  const std::string none = "pin: nothing pinched by the " + hand_name(hand);
  if (!s.hand_valid[hand]) return w.report(none + " and it is not tracked: ignored"), -1;
  const HandCandidates& hc = s.candidates[hand];
  const int32_t v = hc.chosen_vertex();
  const double reach = std::max(p.pinch_reach, s.hands[hand].radius);
  if (v < 0 || hc.particles[hc.chosen].distance > reach)
    return w.report(none + " and no cloth within " + cm(reach) + " of it: ignored"), -1;
  if (is_pinched_by_any(s, v) || (w.cloth.state.flags[v] & kFlagKinematic))
    return w.report(none + "; the cloth under it is held or moved: ignored"), -1;
  return v;
}

bool ops_pin(World& w, OperationsState& s, const OperationParams& p, int hand) {
  if (!valid_index(hand)) return w.report("pin: no hand " + std::to_string(hand)), false;
  ops_update_candidates(w, s, p);
  const int32_t v = pin_particle(w, s, p, hand);
  if (v < 0) return false;
  const HandCandidates& hc = s.candidates[hand];
  const bool held = s.pinched[hand] == v;
  if (!hc.has_object_point)
    return w.report("pin: no object point within " + mm(p.pin_reach) + " of the " +
                    hand_name(hand) + ": ignored" + (held ? " (still pinched)" : "")),
           false;
  if (held) s.pinched[hand] = -1;
  // Fix first, exactly on the chosen point; the rest relaxes around it for a few ticks; then the
  // particle is offset out of collision along the surface normal.
  set_vertex_flags(w.cloth, v, kFlagPinned, kFlagPinched);
  auto& st = w.cloth.state;
  st.x[v] = hc.object_point;
  st.x_prev[v] = st.x[v];
  st.v[v].setZero();
  s.settling.push_back({v, hc.object_point, hc.object_normal, std::max(0, p.pin_relax_ticks)});
  return true;
}

namespace {
// Top corners of the panel: material (min u, max v) and (max u, max v), originals preferred.
std::array<int32_t, 2> top_corners(const Cloth& c) {
  std::vector<char> used;
  in_any_triangle(c, used);
  double vmax = -kInf;
  for (int32_t i = 0; i < c.num_vertices(); ++i)
    if (used[i]) vmax = std::max(vmax, c.topo.material[i].y());
  int32_t a = -1, b = -1;
  const double tol = 1e-9 + 1e-6 * std::abs(vmax);
  for (int32_t i = 0; i < c.num_vertices(); ++i) {
    if (!used[i] || c.topo.material[i].y() < vmax - tol) continue;
    const double u = c.topo.material[i].x();
    if (a < 0 || u < c.topo.material[a].x() - 1e-12) a = i;
    if (b < 0 || u > c.topo.material[b].x() + 1e-12) b = i;
  }
  return {a, b};
}
}  // namespace

bool ops_move_begin(World& w, OperationsState& s) {
  if (s.moving) return w.report("move: already moving"), false;
  if (!s.hand_valid[0] && !s.hand_valid[1])
    return w.report("move: no hand tracked: ignored"), false;
  auto corners = top_corners(w.cloth);
  if (corners[0] < 0 || corners[0] == corners[1])
    return w.report("move: the cloth has no two top corners: ignored"), false;
  // Pair corners and hands so the total distance is least (the left hand need not hold the
  // left corner when the cloth faces the user).
  const auto& x = w.cloth.state.x;
  auto dist = [&](int h, int32_t v) {
    return s.hand_valid[h] ? (x[v] - s.hands[h].position).norm() : 0.0;
  };
  const bool swap =
      dist(0, corners[1]) + dist(1, corners[0]) < dist(0, corners[0]) + dist(1, corners[1]);
  std::array<int32_t, 2> mv{swap ? corners[1] : corners[0], swap ? corners[0] : corners[1]};
  for (int h = 0; h < 2; ++h) {
    if (is_pinched_by_any(s, mv[h])) {
      w.report("move: a top corner is pinched: it stays with the pinching hand");
      mv[h] = -1;
    }
  }
  s.moving = true;
  s.move_vertex = mv;
  for (int h = 0; h < 2; ++h) {
    // The grab offset: the corner keeps its place relative to the hand (no jump).
    s.move_grabbed[h] = mv[h] >= 0 && s.hand_valid[h];
    s.move_offset[h] = s.move_grabbed[h] ? Vec3(x[mv[h]] - s.hands[h].position) : Vec3::Zero();
    if (mv[h] >= 0) set_vertex_flags(w.cloth, mv[h], kFlagKinematic, 0);
  }
  return true;
}

bool ops_move_end(World& w, OperationsState& s) {
  if (!s.moving) return w.report("move end: not moving"), false;
  s.moving = false;
  for (int h = 0; h < 2; ++h) {
    const int32_t v = s.move_vertex[h];
    s.move_vertex[h] = -1;
    s.move_grabbed[h] = false;
    s.move_offset[h].setZero();
    if (v < 0 || v >= w.cloth.num_vertices()) continue;
    // Kept fixed where they are (otherwise the cloth falls).
    set_vertex_flags(w.cloth, v, kFlagPinned, kFlagKinematic);
    w.cloth.state.x_prev[v] = w.cloth.state.x[v];
    w.cloth.state.v[v].setZero();
  }
  return true;
}

bool ops_cut_begin(World& w, OperationsState& s, int hand) {
  if (!valid_index(hand)) return w.report("cut: no hand " + std::to_string(hand)), false;
  s.cutting[hand] = true;
  s.stroke[hand].clear();
  if (s.hand_valid[hand]) s.stroke[hand].push_back(s.hands[hand].position);
  return true;
}

namespace {
bool apply_cut(World& w, OperationsState& s, CutResult r) {
  if (!r.ok) {
    w.report("cut: ignored: " + r.reason);
    s.last_cut = std::move(r);
    return false;
  }
  // Duplicates inherit flags; only the original stays attached to a hand or a move.
  for (int32_t nv : r.new_vertices) {
    if (w.cloth.state.flags[nv] & (kFlagPinched | kFlagKinematic))
      set_vertex_flags(w.cloth, nv, kFlagPinned, kFlagPinched | kFlagKinematic);
  }
  char buf[160];
  std::snprintf(buf, sizeof buf, "cut: %zu edges, %zu new particles, %d → %d pieces, %.3f ms",
                r.path.size() - 1, r.new_vertices.size(), r.components_before, r.components_after,
                r.ms);
  w.report(buf);
  s.cut_strokes.push_back({r.smooth_stroke, r.smooth_stroke_uv});
  s.last_cut = std::move(r);
  return true;
}
}  // namespace

bool ops_cut_end(World& w, OperationsState& s, const OperationParams& p, int hand) {
  if (!valid_index(hand) || !s.cutting[hand])
    return w.report("cut end: the " + hand_name(hand) + " is not cutting"), false;
  s.cutting[hand] = false;
  std::vector<Vec3> stroke = std::move(s.stroke[hand]);
  s.stroke[hand].clear();
  if (stroke.size() < 2) {
    w.report("cut: ignored: stroke has fewer than 2 samples");
    return false;
  }
  return apply_cut(w, s, cut_along(w.cloth, stroke, p.cut));
}

bool ops_cut_stroke(World& w, OperationsState& s, const OperationParams& p,
                    const std::vector<Vec3>& stroke) {
  if (stroke.size() < 2) {
    w.report("cut: ignored: stroke has fewer than 2 samples");
    return false;
  }
  return apply_cut(w, s, cut_along(w.cloth, stroke, p.cut));
}

bool ops_smooth_begin(World& w, OperationsState& s, int hand) {
  if (!valid_index(hand)) return w.report("smooth: no hand " + std::to_string(hand)), false;
  if (!w.scene.form) return w.report("smooth: no dress form in the scene: ignored"), false;
  s.smoothing[hand] = true;
  return true;
}

bool ops_smooth_end(World& w, OperationsState& s, int hand) {
  if (!valid_index(hand) || !s.smoothing[hand])
    return w.report("smooth end: the " + hand_name(hand) + " is not smoothing"), false;
  s.smoothing[hand] = false;
  return true;
}

// The map's boundary conditions: the top edge, the centre line (the warp thread u = uc) and the
// rows at the heights of the form's reference lines (material v in `rows`: the waist and the
// hip) are fixed where the map put them, as the geometric draping's relaxation holds the hip and
// waist lines; everything else is freed. Without the two lines the strained, mapped cloth
// relaxes at once (the along-grain mapping stretches the warp where the sections change girth)
// and slides by up to a centimetre at the side lines before a hand can pin or cut there.
void pin_map_lines(Cloth& c, double uc, double vmax, const std::array<double, 2>& rows) {
  const double tol = 0.5 * c.topo.spacing + 1e-9;
  for (int32_t i = 0; i < c.num_vertices(); ++i) {
    const Vec2 m = c.topo.material[i];
    bool fixed = m.y() > vmax - 1e-9 || std::abs(m.x() - uc) <= tol;
    for (double r : rows) fixed = fixed || std::abs(m.y() - r) < tol;
    const uint8_t set = fixed ? kFlagPinned : 0;
    set_vertex_flags(c, i, set,
                     static_cast<uint8_t>(kFlagPinned | kFlagKinematic | kFlagPinched) &
                         static_cast<uint8_t>(~set));
  }
}

// The centre line the map puts the grain on: centre back when the hand asking for the map is
// tracked behind the form's centre at the waist (the user stands at the back), else centre front.
double map_centre_theta(const World& w, const OperationsState& s, int hand) {
  const DressForm& form = *w.scene.form;
  if (!valid_index(hand) || !s.hands[hand].tracked) return form.landmarks().centre_front_theta;
  const Vec2 c = form.centre_at(form.landmarks().waist_y);
  return s.hands[hand].position.z() < c.y() ? form.landmarks().centre_back_theta
                                            : form.landmarks().centre_front_theta;
}

bool ops_map(World& w, OperationsState& s, int hand) {
  if (!w.scene.form || w.scene.form->num_sections() < 2)
    return w.report("map: no dress form in the scene: ignored"), false;
  if (s.pinched[0] >= 0 || s.pinched[1] >= 0 || s.moving)
    return w.report("map: not while pinching or moving (map does not combine with them)"), false;
  Cloth& c = w.cloth;
  std::vector<char> used;
  in_any_triangle(c, used);
  double umin = kInf, umax = -kInf, vmin = kInf, vmax = -kInf;
  for (int32_t i = 0; i < c.num_vertices(); ++i) {
    if (!used[i]) continue;
    umin = std::min(umin, c.topo.material[i].x()), umax = std::max(umax, c.topo.material[i].x());
    vmin = std::min(vmin, c.topo.material[i].y()), vmax = std::max(vmax, c.topo.material[i].y());
  }
  if (!(umax > umin && vmax > vmin)) return w.report("map: the cloth is empty: ignored"), false;
  // Chapter 2 mapping (sim/draping/mapping.hpp) with the grain (warp, v) on the centre line: the
  // panel's middle warp line u = uc on theta = tc (centre front, or centre back when the hand is
  // behind the form), each half wrapped toward its side line along the sections (u > uc toward
  // increasing theta: the user's right whichever side the user stands), the top edge 3 cm above
  // the waist (eq. 2-1).
  const DressForm& form = *w.scene.form;
  const double tc = map_centre_theta(w, s, hand);
  const MappingSurface surf(form, 0.0, false);  // the form itself (no tight-skirt hip shape)
  Panel shape;
  shape.design.width = umax - umin;
  shape.design.height = vmax - vmin;
  shape.design.top_above_waist = 0.03;
  const double waist = form.landmarks().waist_y;
  const double pi = 3.14159265358979323846;
  const PieceMapping left =
      make_piece_mapping(shape, surf, tc, +1, std::fmod(tc + pi / 2, 2 * pi), waist);
  const PieceMapping right =
      make_piece_mapping(shape, surf, tc, -1, std::fmod(tc + 3 * pi / 2, 2 * pi), waist);
  const double uc = 0.5 * (umin + umax);
  std::vector<std::pair<double, std::array<ArcTable, 2>>> tables;  // per distinct height
  auto& st = c.state;
  for (int32_t i = 0; i < c.num_vertices(); ++i) {
    const Vec2 m = c.topo.material[i];
    const double y = left.y_of_v(m.y() - vmin);
    const std::array<ArcTable, 2>* T = nullptr;
    for (const auto& [ty, t] : tables)
      if (std::abs(ty - y) < 1e-12) T = &t;
    if (!T) {
      tables.push_back({y, {ArcTable::build(surf, y, tc, +1), ArcTable::build(surf, y, tc, -1)}});
      T = &tables.back().second;
    }
    const double l = m.x() - uc;
    const PieceMapping& pm = l >= 0 ? left : right;
    const double theta = pm.theta(0, std::abs(l), y, (*T)[l >= 0 ? 0 : 1]);
    Vec3 p = surf.point(y, theta);
    p += DressForm::direction(theta) * w.scene.offset;  // just outside the collision offset
    if (!p.allFinite()) return w.report("map: mapping produced a non-finite point: ignored"), false;
    st.x[i] = p;
  }
  st.x_prev = st.x;
  for (auto& v : st.v) v.setZero();
  pin_map_lines(c, uc, vmax,
                {vmax - (left.y_top - waist), vmax - (left.y_top - form.landmarks().hip_y)});
  s.settling.clear();
  w.report(std::string("map: cloth mapped onto the form, grain on centre ") +
           (tc == form.landmarks().centre_front_theta ? "front" : "back") +
           "; top edge, centre line, waist and hip lines fixed");
  return true;
}

void ops_stop(World& w, OperationsState& s) {
  for (int h = 0; h < 2; ++h) {
    if (s.pinched[h] >= 0) ops_pinch_end(w, s, h);
    if (s.cutting[h]) {
      s.cutting[h] = false;
      s.stroke[h].clear();
      w.report("stop: unfinished cut stroke of the " + hand_name(h) + " discarded");
    }
    s.smoothing[h] = false;
  }
  if (s.moving) ops_move_end(w, s);
}

bool hand_busy(const OperationsState& s, int hand) {
  return s.pinched[hand] >= 0 || s.cutting[hand] || s.smoothing[hand] ||
         (s.moving && s.move_vertex[hand] >= 0 && s.move_grabbed[hand]);
}

int grace_ticks(const OperationParams& p, double dt) {
  const double g = p.tracking_grace;
  if (!(g > 0) || !(dt > 0)) return 1;  // no grace (or a bad value): ends on the first tick
  return std::max(1, static_cast<int>(std::ceil(g / dt - 1e-9)));
}

void ops_track_loss(World& w, OperationsState& s, const OperationParams& p, double dt) {
  for (int h = 0; h < 2; ++h) {
    if (s.hand_valid[h] || !hand_busy(s, h)) {
      s.lost_ticks[h] = 0;
      continue;
    }
    if (++s.lost_ticks[h] < grace_ticks(p, dt)) continue;
    char secs[32];
    std::snprintf(secs, sizeof secs, "%.2g s", s.lost_ticks[h] * dt);
    const std::string lost = hand_name(h) + " lost for " + secs + ": ";
    s.lost_ticks[h] = 0;
    auto say = [&](const std::string& m) {
      w.report(m);
      s.loss_reports.push_back(m);
      if (s.loss_reports.size() > 16) s.loss_reports.erase(s.loss_reports.begin());
    };
    if (s.pinched[h] >= 0) {
      const int32_t v = s.pinched[h];
      ops_pinch_end(w, s, h);
      say("pinch: " + lost + "let go of particle " + std::to_string(v));
    }
    if (s.cutting[h]) {
      s.cutting[h] = false;
      s.stroke[h].clear();
      say("cut: " + lost + "stroke cancelled, nothing cut");
    }
    if (s.smoothing[h]) {
      s.smoothing[h] = false;
      say("smooth: " + lost + "smoothing ended");
    }
    if (s.moving && s.move_vertex[h] >= 0) {
      ops_move_end(w, s);
      say("move: " + lost + "move ended, the corners fixed where they are");
    }
  }
}

void ops_before_step(World& w, OperationsState& s, const OperationParams& p, double dt) {
  ops_track_loss(w, s, p, dt);
  Cloth& c = w.cloth;
  auto& st = c.state;
  const int n = c.num_vertices();
  for (int h = 0; h < 2; ++h) {
    if (!s.hand_valid[h]) continue;
    const Vec3 hp = s.hands[h].position;
    const int32_t v = s.pinched[h];
    if (v >= 0 && v < n) {
      st.x_prev[v] = st.x[v];
      st.x[v] = hp;
      st.v[v] = dt > 0 ? Vec3((st.x[v] - st.x_prev[v]) / dt) : Vec3::Zero();
    }
    if (s.moving && s.move_vertex[h] >= 0 && s.move_vertex[h] < n) {
      const int32_t m = s.move_vertex[h];
      if (!s.move_grabbed[h]) {  // untracked at move begin: grabbed now, where it is
        s.move_offset[h] = st.x[m] - hp;
        s.move_grabbed[h] = true;
      }
      st.x_prev[m] = st.x[m];
      st.x[m] = hp + s.move_offset[h];
      st.v[m] = dt > 0 ? Vec3((st.x[m] - st.x_prev[m]) / dt) : Vec3::Zero();
    }
    if (s.cutting[h]) s.stroke[h].push_back(hp);
    if (s.smoothing[h] && w.scene.form) {
      // Weak pressure toward the form: a force per area (a = pressure / areal density) along
      // the inward radial direction, applied as a velocity change a·dt per tick (Verlet's
      // x_prev shifted to match), so it accumulates like a weak pressure term; the inward
      // speed is capped so that one tick never carries a particle past the surface + offset.
      const DressForm& f = *w.scene.form;
      const double a = p.smooth_pressure / std::max(1e-6, c.fabric.areal_density);
      for (int32_t i = 0; i < n; ++i) {
        if (!c.is_free(i) || (st.x[i] - hp).norm() > p.smooth_radius) continue;
        const double sd = f.signed_distance(st.x[i]);
        if (!std::isfinite(sd) || sd <= w.scene.offset) continue;
        const Vec2 cc = f.centre_at(st.x[i].y());
        Vec3 inward(cc.x() - st.x[i].x(), 0, cc.y() - st.x[i].z());
        if (inward.norm() < 1e-9) continue;
        inward.normalize();
        const double vin = st.v[i].dot(inward);
        const double cap = dt > 0 ? (sd - w.scene.offset) / dt : 0.0;
        const double dv = std::max(0.0, std::min(a * dt, cap - vin));
        st.v[i] += dv * inward;
        st.x_prev[i] -= dv * dt * inward;
      }
    }
  }
}

void ops_after_step(World& w, OperationsState& s, const OperationParams& p, double /*dt*/) {
  // Keep the cloth ready for a cut (kept incidence, array headroom): the O(V) work happens
  // here, in a tick, only after a load, an undo or a cut used the headroom — never inside the
  // cut command.
  prepare_for_cuts(w.cloth);
  auto& st = w.cloth.state;
  for (auto it = s.settling.begin(); it != s.settling.end();) {
    if (it->vertex >= w.cloth.num_vertices() || !(st.flags[it->vertex] & kFlagPinned)) {
      it = s.settling.erase(it);
      continue;
    }
    if (--it->ticks_left > 0) {
      ++it;
      continue;
    }
    const Vec3 want = it->target + it->normal * w.scene.offset;
    st.x[it->vertex] = want;
    st.x_prev[it->vertex] = want;
    st.v[it->vertex].setZero();
    s.last_pin_distance = (st.x[it->vertex] - it->target).norm();
    s.last_pin_landing_error = (st.x[it->vertex] - want).norm();
    w.report("pin: particle " + std::to_string(it->vertex) + " fixed " + mm(s.last_pin_distance) +
             " off the chosen point (offset), landing error " + mm(s.last_pin_landing_error));
    it = s.settling.erase(it);
  }
  ops_update_candidates(w, s, p);
}

void ops_decorate(const World& w, const OperationsState& s, SceneSnapshot& snap) {
  for (int h = 0; h < 2; ++h) {
    const HandCandidates& hc = s.candidates[h];
    snap.candidate_vertex[h] = hc.chosen_vertex();
    snap.candidate_is_form[h] = false;
    snap.candidate_point[h] = Vec3f::Zero();
    const int32_t v = hc.chosen_vertex();
    if (v >= 0 && v < w.cloth.num_vertices())
      snap.candidate_point[h] = w.cloth.state.x[v].cast<float>();
    // While pinching, the object point where pin would fix the particle is what matters.
    if (s.pinched[h] >= 0 && hc.has_object_point) {
      snap.candidate_point[h] = hc.object_point.cast<float>();
      snap.candidate_is_form[h] = true;
    }
    snap.candidate_alternatives[h].clear();
    for (const Candidate& cd : hc.particles) snap.candidate_alternatives[h].push_back(cd.vertex);
    snap.release_candidate[h] = hc.release_vertex;
  }
  snap.cut_strokes.clear();
  snap.cut_strokes_material.clear();
  for (const CutStroke& cs : s.cut_strokes) {
    std::vector<Vec3f> pts;
    pts.reserve(cs.smooth.size());
    for (const Vec3& q : cs.smooth) pts.push_back(q.cast<float>());
    snap.cut_strokes.push_back(std::move(pts));
    std::vector<Vec2f> uv;
    uv.reserve(cs.material.size());
    for (const Vec2& q : cs.material) uv.push_back(q.cast<float>());
    snap.cut_strokes_material.push_back(std::move(uv));
  }
  for (int h = 0; h < 2; ++h) {
    if (!s.cutting[h] || s.stroke[h].size() < 2) continue;
    std::vector<Vec3f> pts;
    for (const Vec3& q : s.stroke[h]) pts.push_back(q.cast<float>());
    snap.cut_strokes.push_back(std::move(pts));
  }
}

}  // namespace drape::sim
