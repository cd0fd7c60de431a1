// Dress form from a mesh (any format assimp reads): detect units, up axis and centre front,
// then resample as a scanner would: from each section centre, cast 256 horizontal rays and
// keep the outermost hit (method 1). See docs/dress-form.md.
//
// A horizontal ray at height y meets a triangle exactly where it meets the triangle's slice
// segment in the plane y, so each section slices the triangles of its height band (bucketed
// once) and intersects the rays with the segments, each segment only with the rays inside the
// angle it subtends: O(triangles + sections x 256) overall.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "sim/core/mesh.hpp"
#include "sim/form/dress_form.hpp"

namespace drape::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kN = DressForm::kAngles;

struct Seg {
  Vec2 a, b;  // (x, z)
};

inline double cross2(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Slice segment of triangle (p0,p1,p2) with the plane Y = y (half-open rule: a vertex is above
// when its y > the plane), in (x, z). Returns false when the plane does not cross it.
inline bool slice(const Vec3& p0, const Vec3& p1, const Vec3& p2, double y, Seg& s) {
  const Vec3* p[3] = {&p0, &p1, &p2};
  const bool up[3] = {p0.y() > y, p1.y() > y, p2.y() > y};
  if (up[0] == up[1] && up[1] == up[2]) return false;
  Vec2 pts[2];
  int k = 0;
  for (int e = 0; e < 3; ++e) {
    const Vec3& a = *p[e];
    const Vec3& b = *p[(e + 1) % 3];
    if (up[e] == up[(e + 1) % 3]) continue;
    const double t = (y - a.y()) / (b.y() - a.y());
    pts[k++] = Vec2(a.x() + t * (b.x() - a.x()), a.z() + t * (b.z() - a.z()));
    if (k == 2) break;
  }
  if (k != 2) return false;
  s.a = pts[0];
  s.b = pts[1];
  return true;
}

// Rotation taking the file's up axis to +y (proper rotations).
Mat3 up_rotation(MeshImportOptions::UpAxis up) {
  Mat3 r;
  using U = MeshImportOptions::UpAxis;
  switch (up) {
    case U::kZ:
      r << 1, 0, 0, 0, 0, 1, 0, -1, 0;
      break;
    case U::kX:
      r << 0, -1, 0, 1, 0, 0, 0, 0, 1;
      break;
    case U::kNegY:
      r << 1, 0, 0, 0, -1, 0, 0, 0, -1;
      break;
    case U::kNegZ:
      r << 1, 0, 0, 0, 0, -1, 0, 1, 0;
      break;
    case U::kNegX:
      r << 0, 1, 0, -1, 0, 0, 0, 0, 1;
      break;
    default:
      r.setIdentity();
      break;
  }
  return r;
}

const char* up_name(MeshImportOptions::UpAxis up) {
  using U = MeshImportOptions::UpAxis;
  switch (up) {
    case U::kZ:
      return "+z";
    case U::kX:
      return "+x";
    case U::kNegY:
      return "-y";
    case U::kNegZ:
      return "-z";
    case U::kNegX:
      return "-x";
    default:
      return "+y";
  }
}

// Horizontal size of the slice at height y (sqrt of its bounding-box area), 0 if empty.
double slice_size(const std::vector<Vec3>& v, const TriMesh& m, double y) {
  Vec2 lo(1e300, 1e300), hi(-1e300, -1e300);
  Seg s;
  bool any = false;
  for (const auto& t : m.triangles) {
    if (!slice(v[t[0]], v[t[1]], v[t[2]], y, s)) continue;
    any = true;
    lo = lo.cwiseMin(s.a).cwiseMin(s.b);
    hi = hi.cwiseMax(s.a).cwiseMax(s.b);
  }
  if (!any) return 0.0;
  const Vec2 e = hi - lo;
  return std::sqrt(std::max(e.x() * e.y(), 0.0));
}

}  // namespace

Result<DressForm> DressForm::from_triangles(const TriMesh& mesh, const MeshImportOptions& opt,
                                            const std::string& name, MeshImportInfo* info) {
  using U = MeshImportOptions::UpAxis;
  MeshImportInfo inf;
  inf.triangles = static_cast<int>(mesh.triangles.size());
  if (mesh.triangles.empty() || mesh.vertices.empty()) return make_error(name, "no triangles");
  for (const auto& t : mesh.triangles)
    for (int32_t i : t)
      if (i < 0 || i >= static_cast<int32_t>(mesh.vertices.size()))
        return make_error(name, "triangle index out of range");
  for (const Vec3& p : mesh.vertices)
    if (!p.allFinite()) return make_error(name, "non-finite vertex coordinate");
  const double dy = opt.section_spacing;
  if (!(dy >= 0.0005 && dy <= 0.05))
    return make_error(name, "section_spacing must be in [0.0005, 0.05] m");

  // --- up axis -------------------------------------------------------------------------------
  Vec3 lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (const Vec3& p : mesh.vertices) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Vec3 ext = hi - lo;
  U up = opt.up;
  if (up == U::kAuto) {
    inf.up_detected = true;
    int axis;
    ext.maxCoeff(&axis);
    up = axis == 0 ? U::kX : axis == 1 ? U::kY : U::kZ;
  }
  Mat3 R = up_rotation(up);
  std::vector<Vec3> v(mesh.vertices.size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = R * mesh.vertices[i];
  double ymin = 1e300, ymax = -1e300;
  for (const Vec3& p : v) ymin = std::min(ymin, p.y()), ymax = std::max(ymax, p.y());
  const double h = ymax - ymin;
  if (!(h > 0)) return make_error(name, "the mesh is flat along the up axis (no torso)");
  if (inf.up_detected) {
    // Sign: a torso is narrow at the neck (top) and wide at the hips/thighs (bottom).
    const double s_lo = slice_size(v, mesh, ymin + 0.04 * h);
    const double s_hi = slice_size(v, mesh, ymax - 0.04 * h);
    if (s_lo > 0 && s_hi > 0 && s_lo < 0.7 * s_hi) {
      const Mat3 flip = up_rotation(U::kNegY);
      R = flip * R;
      for (Vec3& p : v) p = flip * p;
      std::swap(ymin, ymax);
      ymin = -ymin, ymax = -ymax;
      up = up == U::kX ? U::kNegX : up == U::kY ? U::kNegY : U::kNegZ;
    }
  }
  inf.up = up_name(up);

  // --- units ---------------------------------------------------------------------------------
  double scale = 1.0;
  using Un = MeshImportOptions::Units;
  switch (opt.units) {
    case Un::kMetres:
      scale = 1.0, inf.units = "m";
      break;
    case Un::kCentimetres:
      scale = 0.01, inf.units = "cm";
      break;
    case Un::kMillimetres:
      scale = 0.001, inf.units = "mm";
      break;
    case Un::kInches:
      scale = 0.0254, inf.units = "in";
      break;
    case Un::kAuto: {
      // A torso is 0.5-2 m tall. Ranges: m [0.5, 2], in [19.7, 50), cm [50, 200], mm [500, 2000].
      inf.units_detected = true;
      if (h >= 0.5 && h <= 2.0)
        scale = 1.0, inf.units = "m";
      else if (h >= 19.7 && h < 50.0)
        scale = 0.0254, inf.units = "in";
      else if (h >= 50.0 && h <= 200.0)
        scale = 0.01, inf.units = "cm";
      else if (h >= 500.0 && h <= 2000.0)
        scale = 0.001, inf.units = "mm";
      else {
        std::ostringstream os;
        os << "cannot detect the units: the height extent " << h
           << " (file units) fits no torso of 0.5-2 m in m, cm, mm or inches; give the units "
              "(--units)";
        return make_error(name, os.str());
      }
      break;
    }
  }
  inf.scale = scale;
  for (Vec3& p : v) p *= scale;
  ymin *= scale, ymax *= scale;
  const double height = ymax - ymin;
  if (!(height >= 0.1 && height <= 3.0)) {
    std::ostringstream os;
    os << "the mesh is " << height << " m tall in " << inf.units
       << ": not a torso (0.1-3 m); check the units (--units)";
    return make_error(name, os.str());
  }
  {
    double wmax = 0;
    for (const Vec3& p : v) wmax = std::max({wmax, std::abs(p.x()), std::abs(p.z())});
    if (!(wmax <= 3.0))
      return make_error(name, "the mesh is wider than 3 m: not a torso; check the units (--units)");
  }
  if (height < 4 * dy) return make_error(name, "the mesh is too short for the section spacing");

  // --- centre front --------------------------------------------------------------------------
  Vec2 front(0, 0);  // (x, z)
  bool have_front = false;
  if (opt.front_auto) {
    // Area-weighted horizontal covariance: the major axis is the width (side to side), the
    // minor one the depth (front-back).
    double area = 0;
    Vec2 mean = Vec2::Zero();
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (const auto& t : mesh.triangles) {
      const Vec3 &a = v[t[0]], &b = v[t[1]], &c = v[t[2]];
      const double w = 0.5 * (b - a).cross(c - a).norm();
      const Vec3 g = (a + b + c) / 3.0;
      const Vec2 q(g.x(), g.z());
      area += w, mean += w * q, cov += w * q * q.transpose();
    }
    if (area > 0) {
      mean /= area;
      cov = cov / area - mean * mean.transpose();
      const double tr = cov.trace(), det = cov(0, 0) * cov(1, 1) - cov(0, 1) * cov(1, 0);
      const double disc = std::sqrt(std::max(tr * tr / 4 - det, 0.0));
      const double l1 = tr / 2 + disc, l2 = tr / 2 - disc;
      if (l1 > 0 && l2 < 0.9 * l1) {
        // Eigenvector of the smaller eigenvalue: the depth axis.
        Vec2 depth(cov(0, 1), l2 - cov(0, 0));
        if (depth.norm() < 1e-12 * l1) depth = Vec2(l2 - cov(1, 1), cov(0, 1));
        if (depth.norm() < 1e-12 * l1) depth = cov(0, 0) < cov(1, 1) ? Vec2(1, 0) : Vec2(0, 1);
        depth.normalize();
        // The bust protrudes at the front in the upper half, the seat at the back in the lower
        // half: the front is the side whose upper-half extreme exceeds its lower-half extreme.
        const int bands = 24;
        std::vector<double> ep(bands, -1e300), en(bands, -1e300);
        for (const Vec3& p : v) {
          const int b = std::clamp(static_cast<int>((p.y() - ymin) / height * bands), 0, bands - 1);
          const double d = depth.dot(Vec2(p.x(), p.z()) - mean);
          ep[b] = std::max(ep[b], d), en[b] = std::max(en[b], -d);
        }
        auto score = [&](const std::vector<double>& e) {
          double up_max = -1e300, lo_max = -1e300;
          for (int b = 2; b < bands - 2; ++b)
            (b >= bands / 2 ? up_max : lo_max) = std::max(b >= bands / 2 ? up_max : lo_max, e[b]);
          return up_max - lo_max;
        };
        const double sp = score(ep), sn = score(en);
        if (std::abs(sp - sn) > 0.005) {
          front = sp > sn ? depth : Vec2(-depth);
          inf.front_detected = true;
        } else {  // depth axis clear, front/back not: the side nearer the given front axis
          const Vec2 given(opt.front_axis.x(), opt.front_axis.z());
          front = depth.dot(given) >= 0 ? depth : Vec2(-depth);
        }
        have_front = true;
      }
    }
  }
  if (!have_front) {
    front = Vec2(opt.front_axis.x(), opt.front_axis.z());
    if (!(front.norm() > 1e-9) || !front.allFinite())
      return make_error(name, "front axis is vertical or zero");
    front.normalize();
  }
  const double phi = std::atan2(front.x(), front.y());
  inf.front_angle = -phi;
  {
    const double c = std::cos(phi), s = std::sin(phi);
    for (Vec3& p : v) {  // rotate about y by -phi: front -> +z
      const double x = c * p.x() - s * p.z(), z = s * p.x() + c * p.z();
      p.x() = x, p.z() = z;
    }
  }

  // --- vertical placement --------------------------------------------------------------------
  double lift = 0.0;
  if (std::isfinite(opt.bottom_y))
    lift = opt.bottom_y - ymin;
  else if (ymin < 0)
    lift = 0.60 - ymin;
  inf.lift = lift;
  for (Vec3& p : v) p.y() += lift;
  ymin += lift, ymax += lift;

  // --- sections ------------------------------------------------------------------------------
  const double y0 = ymin + 0.5 * dy;
  const int ns = static_cast<int>(std::floor((height - dy) / dy + 1e-9)) + 1;
  // Bucket triangles by the sections they cross (CSR).
  std::vector<int> count(ns + 1, 0);
  auto range = [&](const std::array<int32_t, 3>& t, int& j0, int& j1) {
    const double a = std::min({v[t[0]].y(), v[t[1]].y(), v[t[2]].y()});
    const double b = std::max({v[t[0]].y(), v[t[1]].y(), v[t[2]].y()});
    j0 = std::max(0, static_cast<int>(std::floor((a - y0) / dy)));
    j1 = std::min(ns - 1, static_cast<int>(std::ceil((b - y0) / dy)));
  };
  for (const auto& t : mesh.triangles) {
    int j0, j1;
    range(t, j0, j1);
    for (int j = j0; j <= j1; ++j) ++count[j + 1];
  }
  for (int j = 0; j < ns; ++j) count[j + 1] += count[j];
  std::vector<int> bucket(count[ns]);
  {
    std::vector<int> fill(count.begin(), count.end() - 1);
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
      int j0, j1;
      range(mesh.triangles[i], j0, j1);
      for (int j = j0; j <= j1; ++j) bucket[fill[j]++] = static_cast<int>(i);
    }
  }

  std::vector<Vec2> centres(ns, Vec2::Zero());
  std::vector<double> radii(static_cast<size_t>(ns) * kN, 0.0);
  std::vector<char> valid(ns, 0);
  std::vector<Seg> segs;
  const double k_ang = kN / (2 * kPi);
  for (int j = 0; j < ns; ++j) {
    const double y = y0 + dy * j;
    segs.clear();
    Seg s;
    for (int q = count[j]; q < count[j + 1]; ++q) {
      const auto& t = mesh.triangles[bucket[q]];
      if (slice(v[t[0]], v[t[1]], v[t[2]], y, s)) segs.push_back(s);
    }
    double len = 0;
    Vec2 c = Vec2::Zero();
    for (const Seg& g : segs) {
      const double l = (g.b - g.a).norm();
      len += l, c += l * 0.5 * (g.a + g.b);
    }
    if (!(len > 0)) continue;
    c /= len;
    centres[j] = c;
    double* r = &radii[static_cast<size_t>(j) * kN];
    for (const Seg& g : segs) {
      const Vec2 a = g.a - c, b = g.b - c, e = b - a;
      if (std::abs(cross2(a, e)) < 1e-14) continue;  // the segment's line passes the centre
      const double ta = std::atan2(a.x(), a.y()), tb = std::atan2(b.x(), b.y());
      double d = tb - ta;
      if (d > kPi) d -= 2 * kPi;
      if (d < -kPi) d += 2 * kPi;
      const double start = d >= 0 ? ta : tb, span = std::abs(d);
      const int n0 = static_cast<int>(std::ceil(start * k_ang - 1e-9));
      const int n1 = static_cast<int>(std::floor((start + span) * k_ang + 1e-9));
      for (int n = n0; n <= n1; ++n) {
        const int nn = ((n % kN) + kN) % kN;
        const double th = DressForm::theta(nn);
        const Vec2 dir(std::sin(th), std::cos(th));
        const double den = cross2(dir, e);
        if (std::abs(den) < 1e-300) continue;
        const double t = cross2(a, e) / den;
        if (t > 0 && t > r[nn]) r[nn] = t;
      }
    }
    int misses = 0;
    for (int n = 0; n < kN; ++n) misses += r[n] > 0 ? 0 : 1;
    if (misses > kN / 10) continue;
    if (misses > 0) {  // fill short gaps (holes in a scan) linearly between the nearest hits
      for (int n = 0; n < kN; ++n) {
        if (r[n] > 0) continue;
        int a = n, b = n;
        while (!(r[(a + kN - 1) % kN] > 0)) --a;
        while (!(r[(b + 1) % kN] > 0)) ++b;
        const double ra = r[(a + kN - 1) % kN], rb = r[(b + 1) % kN];
        const double w = static_cast<double>(n - a + 1) / (b - a + 2);
        r[n] = -(ra + (rb - ra) * w);  // negative marks "filled" until the loop ends
        ++inf.filled_rays;
      }
      for (int n = 0; n < kN; ++n) r[n] = std::abs(r[n]);
    }
    valid[j] = 1;
  }
  // Trim invalid sections at both ends (open ends, caps); interpolate isolated ones inside.
  int first = 0, last = ns - 1;
  while (first < ns && !valid[first]) ++first;
  while (last >= 0 && !valid[last]) --last;
  const int kept = std::max(last - first + 1, 0);
  int inner_bad = 0;
  for (int j = first; j <= last; ++j) inner_bad += valid[j] ? 0 : 1;
  if (kept < std::max(8, ns / 2) || inner_bad > std::max(1, kept / 50)) {
    std::ostringstream os;
    os << "rays cast from the section centres miss the surface (" << (ns - kept + inner_bad)
       << " of " << ns
       << " sections without a closed outline): not a torso (a flat or open shape?)";
    return make_error(name, os.str());
  }
  for (int j = first; j <= last; ++j) {
    if (valid[j]) continue;
    int b = j + 1;
    while (!valid[b]) ++b;
    const int a = j - 1;
    const double w = static_cast<double>(j - a) / (b - a);
    centres[j] = centres[a] + w * (centres[b] - centres[a]);
    for (int n = 0; n < kN; ++n) {
      const double ra = radii[static_cast<size_t>(a) * kN + n],
                   rb = radii[static_cast<size_t>(b) * kN + n];
      radii[static_cast<size_t>(j) * kN + n] = ra + w * (rb - ra);
    }
    valid[j] = 1;
  }
  std::vector<Vec2> c2(centres.begin() + first, centres.begin() + last + 1);
  std::vector<double> r2(radii.begin() + static_cast<size_t>(first) * kN,
                         radii.begin() + static_cast<size_t>(last + 1) * kN);
  if (opt.centre_on_axis) {
    Vec2 mean = Vec2::Zero();
    for (const Vec2& c : c2) mean += c;
    mean /= static_cast<double>(c2.size());
    for (Vec2& c : c2) c -= mean;
  }

  FormLandmarks lm;
  const double fy0 = y0 + dy * first;
  lm.bottom_y = fy0;
  lm.top_y = y0 + dy * last;
  lm.neck_y = lm.top_y;
  DressForm form(fy0, dy, c2, r2, lm);
  // Landmarks (heuristic, for a torso): waist = smallest girth in the middle of the height,
  // hip = largest girth below it, bust = largest girth in the lower 60 % above it (the
  // shoulders are above that).
  const double H = lm.top_y - lm.bottom_y;
  auto arg_ext = [&](double a, double b, bool want_max) {
    double best_y = a, best = want_max ? -1.0 : 1e300;
    for (double y = a; y <= b; y += dy) {
      const double g = form.girth_at(y);
      if (want_max ? g > best : g < best) best = g, best_y = y;
    }
    return best_y;
  };
  lm.waist_y = arg_ext(lm.bottom_y + 0.3 * H, lm.bottom_y + 0.7 * H, false);
  lm.hip_y = arg_ext(lm.bottom_y + 0.05 * H, lm.waist_y, true);
  lm.bust_y = arg_ext(lm.waist_y + 0.1 * (lm.top_y - lm.waist_y),
                      lm.waist_y + 0.6 * (lm.top_y - lm.waist_y), true);
  lm.armpit_y = lm.bust_y + kArmpitAboveBust * (lm.neck_y - lm.bust_y);
  lm.shoulder_y = lm.neck_y - kShoulderBelowNeck * (lm.neck_y - lm.bust_y);
  {  // side lines: the widest points of the waist section
    const int jw = std::clamp(static_cast<int>(std::lround((lm.waist_y - fy0) / dy)), 0,
                              static_cast<int>(c2.size()) - 1);
    double bl = -1, br = -1;
    for (int n = 0; n < kN; ++n) {
      const double x = form.radius(jw, n) * std::sin(theta(n));
      if (n < kN / 2 && x > bl) bl = x, lm.left_side_theta = theta(n);
      if (n > kN / 2 && -x > br) br = -x, lm.right_side_theta = theta(n);
    }
  }
  if (info) *info = inf;
  return DressForm(fy0, dy, std::move(c2), std::move(r2), lm);
}

}  // namespace drape::sim
