// Slash and spread of a draped block (see blocks.hpp).
#include "sim/draping/blocks.hpp"

#include <algorithm>
#include <cmath>

namespace drape::sim {
namespace {
constexpr double kPi = 3.141592653589793;

double cross2(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}
Vec2 rotate(const Vec2& v, double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

// The point where the ray from `o` along unit `d` crosses segment p-q (t along the ray, f along
// the segment), or false.
bool ray_hits_segment(const Vec2& o, const Vec2& d, const Vec2& p, const Vec2& q, double* t,
                      double* f) {
  const Vec2 e = q - p;
  const double den = cross2(d, e);
  if (std::abs(den) < 1e-15) return false;
  const Vec2 w = p - o;
  *t = cross2(w, e) / den;
  *f = cross2(w, d) / den;
  return *t > 0 && *f >= 0 && *f <= 1;
}

// Ends of the chain of segments labelled `li`: the point shared with `other_li`'s chain (the
// dart tip) and the far end (the leg's top at the waist).
bool leg_ends(const PatternPiece& pc, int li, int other_li, int* tip, int* top) {
  const int n = static_cast<int>(pc.outline.size());
  std::vector<int> count(n, 0), other(n, 0);
  for (int i = 0; i < n; ++i) {
    if (pc.seg_label[i] == li) ++count[i], ++count[(i + 1) % n];
    if (pc.seg_label[i] == other_li) ++other[i], ++other[(i + 1) % n];
  }
  *tip = *top = -1;
  for (int i = 0; i < n; ++i) {
    if (count[i] != 1) continue;
    if (other[i] > 0)
      *tip = i;
    else
      *top = i;
  }
  return *tip >= 0 && *top >= 0;
}

// Spreads one dart (labels "dartN_leg1"/"dartN_leg2") of `pc` in place.
std::string spread_one(PatternPiece& pc, const std::string& dart, double arc_step,
                       SpreadStep* step) {
  const int l1 = pc.label_index(dart + "_leg1"), l2 = pc.label_index(dart + "_leg2");
  const int hem = pc.label_index("hem");
  const int n = static_cast<int>(pc.outline.size());
  int tip = -1, b = -1, tip1 = -1, a = -1;
  if (l1 < 0 || l2 < 0 || !leg_ends(pc, l2, l1, &tip, &b) || !leg_ends(pc, l1, l2, &tip1, &a) ||
      tip != tip1)
    return dart + ": its legs do not meet at a tip";
  if (hem < 0) return dart + ": the piece has no hem to spread";
  const auto& P = pc.outline;
  // Walk from the tip up leg 2 (the side part), round the side and along the hem.
  const int dir = pc.seg_label[tip] == l2 ? 1 : -1;
  const auto next = [&](int i) { return (i + dir + n) % n; };
  const auto seg_label_walk = [&](int i) { return pc.seg_label[dir > 0 ? i : (i - 1 + n) % n]; };
  const Vec2 t0 = P[tip];
  Vec2 d = t0 - P[b];
  if (d.norm() < 1e-9) return dart + ": degenerate leg";
  d.normalize();
  const double alpha = std::atan2(cross2(P[b] - t0, P[a] - t0), (P[b] - t0).dot(P[a] - t0));
  // The side chain: b .. i, where segment (i, next(i)) is the hem segment the slash crosses.
  std::vector<int> side_chain;
  int i = b, hit = -1;
  double hf = 0, ht = 0;
  for (int guard = 0; guard < n; ++guard) {
    side_chain.push_back(i);
    const int j = next(i);
    double t = 0, f = 0;
    if (seg_label_walk(i) == hem && ray_hits_segment(t0, d, P[i], P[j], &t, &f)) {
      hit = i;
      hf = f;
      ht = t;
      break;
    }
    if (j == a || j == tip) break;
    i = j;
  }
  if (hit < 0) return dart + ": the slash from its tip down the grain does not reach the hem";
  const Vec2 H = P[hit] + hf * (P[next(hit)] - P[hit]);
  // The centre chain: next(hit) .. a.
  std::vector<int> centre_chain;
  for (int k = next(hit), guard = 0; guard < n; k = next(k), ++guard) {
    centre_chain.push_back(k);
    if (k == a) break;
  }
  if (centre_chain.back() != a) return dart + ": the outline does not close round the centre";
  std::vector<uint8_t> notch(n, 0);
  for (int v : pc.notches) notch[v] = 1;
  PatternPiece out = pc;
  out.outline.clear();
  out.seg_label.clear();
  out.notches.clear();
  out.darts.clear();
  const int waist = seg_label_walk(b);
  const auto push = [&](const Vec2& p, int label, bool is_notch) {
    if (is_notch) out.notches.push_back(static_cast<int>(out.outline.size()));
    out.outline.push_back(p);
    out.seg_label.push_back(label);
  };
  for (int v : side_chain)
    push(t0 + rotate(P[v] - t0, alpha), seg_label_walk(v), notch[v] && v != b);
  // The hem across the wedge: an arc about the tip from the turned slash end to the other.
  const double rho = ht;
  const int arc_n = std::max(1, static_cast<int>(std::ceil(rho * std::abs(alpha) / arc_step)));
  for (int k = 0; k < arc_n; ++k)
    push(t0 + rotate(H - t0, alpha * (1.0 - static_cast<double>(k) / arc_n)), hem, false);
  push(H, hem, false);
  for (int v : centre_chain) push(P[v], v == a ? waist : seg_label_walk(v), notch[v] && v != a);
  // The closed dart's two leg tops meet at their midpoint. The extracted legs can differ in
  // length by millimetres (leg 1 on the relaxed overlapping layer), which would leave a step in
  // the waist; the waist is trued as a pattern maker does: each side's waist points within
  // kTrue of the dart move by the step's share, fading linearly to nothing at kTrue.
  constexpr double kTrue = 0.04;
  const Vec2 mid = 0.5 * (out.outline.front() + out.outline.back());
  const Vec2 shift_side = mid - out.outline.front(), shift_centre = mid - out.outline.back();
  const int m = static_cast<int>(out.outline.size());
  const Vec2 top_side = out.outline.front();
  for (int k = 1; k < m && out.seg_label[k - 1] == waist; ++k) {
    const double along = (out.outline[k] - top_side).norm();
    const double w = std::max(0.0, 1.0 - along / kTrue);
    if (w <= 0) break;
    out.outline[k] += w * shift_side;
  }
  for (int k = m - 2; k > 0 && out.seg_label[k] == waist; --k) {
    const double along = (out.outline[k] - out.outline[m - 1]).norm();
    const double w = std::max(0.0, 1.0 - along / kTrue);
    if (w <= 0) break;
    out.outline[k] += w * shift_centre;
  }
  out.outline.front() = mid;
  out.outline.pop_back();
  out.seg_label.pop_back();
  out.seg_label.back() = waist;
  // Hip line: the part beyond the slash turns with the side part.
  {
    std::vector<Vec2> hl;
    const Vec2 c_ref = P[a] - t0;  // the centre side of the slash line
    const auto side_of = [&](const Vec2& p) { return cross2(d, p - t0) * cross2(d, c_ref) >= 0; };
    for (size_t k = 0; k < pc.hip_line.size(); ++k) {
      const Vec2& p = pc.hip_line[k];
      if (k > 0 && side_of(pc.hip_line[k - 1]) && !side_of(p)) {
        double t = 0, f = 0;
        if (ray_hits_segment(t0, d, pc.hip_line[k - 1], p, &t, &f)) {
          const Vec2 x = pc.hip_line[k - 1] + f * (p - pc.hip_line[k - 1]);
          step->hip_gap = (t0 + rotate(x - t0, alpha) - x).norm();
          hl.push_back(x);
          hl.push_back(t0 + rotate(x - t0, alpha));
        }
      }
      hl.push_back(side_of(p) ? p : Vec2(t0 + rotate(p - t0, alpha)));
    }
    out.hip_line = hl;
  }
  // Counter-clockwise again (the walk ran against the outline's order when dir < 0).
  if (out.area() < 0) {
    const int m = static_cast<int>(out.outline.size());
    std::reverse(out.outline.begin(), out.outline.end());
    std::vector<int> lab(m);
    for (int k = 0; k < m; ++k) lab[k] = out.seg_label[((m - 2 - k) % m + m) % m];
    out.seg_label = lab;
    for (int& v : out.notches) v = m - 1 - v;
  }
  out.outline3d.clear();
  out.ref.clear();
  step->tip = t0;
  step->dir = d;
  step->angle = alpha;
  step->hem_gap = (t0 + rotate(H - t0, alpha) - H).norm();
  pc = std::move(out);
  return "";
}
}  // namespace

Result<SpreadPiece> slash_and_spread(const PatternPiece& block, double arc_step) {
  SpreadPiece sp;
  sp.piece = block;
  for (const auto& d : block.darts) sp.dart_intake_closed += d.intake;
  // The darts in label order, dart1 nearest the centre line.
  std::vector<std::string> darts;
  for (const std::string& l : block.labels)
    if (l.rfind("dart", 0) == 0 && l.size() > 5 && l.compare(l.size() - 5, 5, "_leg1") == 0)
      darts.push_back(l.substr(0, l.size() - 5));
  std::sort(darts.begin(), darts.end());
  for (const std::string& dn : darts) {
    SpreadStep st;
    if (std::string e = spread_one(sp.piece, dn, arc_step, &st); !e.empty())
      return Error{"piece '" + block.name + "': " + e};
    sp.steps.push_back(st);
  }
  // The hip line's length on the cloth: the polyline less the openings the slashes made.
  double gaps = 0;
  for (const auto& st : sp.steps) gaps += st.hip_gap;
  sp.hip_width = sp.piece.hip_width() - gaps;
  sp.hem_length = sp.piece.seam_length("hem");
  // Dart labels stay in `labels` (indices of other labels must not move) but no segment has them.
  return sp;
}

Vec2 unspread_arc(const SpreadPiece& sp, const Vec2& m_in, double* extra_arc) {
  Vec2 m = m_in;
  double extra = 0;
  for (auto it = sp.steps.rbegin(); it != sp.steps.rend(); ++it) {
    const SpreadStep& st = *it;
    const double s = st.angle < 0 ? -1.0 : 1.0, a = std::abs(st.angle);
    const Vec2 v = m - st.tip;
    double phi = s * std::atan2(cross2(st.dir, v), st.dir.dot(v));
    if (phi <= -kPi + a) phi += 2 * kPi;
    if (phi < 0) continue;
    if (phi <= a) {
      m = st.tip + v.norm() * st.dir;
      extra += v.norm() * phi;
    } else {
      m = st.tip + rotate(v, -st.angle);
      extra += std::max(0.0, (m - st.tip).dot(st.dir)) * a;
    }
  }
  if (extra_arc) *extra_arc = extra;
  return m;
}

double spread_arc_at_row(const SpreadPiece& sp, double v) {
  double extra = 0;
  for (const SpreadStep& st : sp.steps)
    if (st.dir.y() < 0) extra += std::max(0.0, (st.tip.y() - v) / -st.dir.y()) * std::abs(st.angle);
  return extra;
}

}  // namespace drape::sim
