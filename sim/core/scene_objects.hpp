// Rigid objects of a draping scene (a table plate and a cube, spheres for tests) and the
// hand proxies operations act with. All analytic; the dress form is in dress_form.hpp.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "sim/core/types.hpp"

namespace drape::sim {

class DressForm;

// Horizontal square plate (a table): top face at centre.y, half extents in x and z.
struct Plate {
  Vec3 centre{0, 0.8, 0};
  double half_x = 0.3, half_z = 0.3;
  double thickness = 0.01;
};

// Axis-aligned box (a cube).
struct Box {
  Vec3 centre{0, 0.9, 0};
  Vec3 half{0.1, 0.1, 0.1};
};

struct Sphere {
  Vec3 centre{0, 1, 0};
  double radius = 0.2;
};

// Horizontal disc with a rounded rim (a drape tester's support disc): top face at top.y(),
// centred on top, `thickness` thick; the rim is a half-torus of radius edge_radius (at most
// thickness / 2), so the cloth folding over it meets a smooth edge.
struct Disc {
  Vec3 top{0, 0, 0};
  double radius = 0.09;
  double thickness = 0.004;
  double edge_radius = 0.002;
};

// Signed distance from p to the disc's surface (< 0 inside) and the outward unit normal
// there: the distance to a solid cylinder of radius radius - edge_radius and height
// thickness - 2 edge_radius, less edge_radius (the rounded cylinder is that core grown by it).
inline double disc_distance(const Vec3& p, const Disc& d, Vec3* normal) {
  const double re = std::min(d.edge_radius, 0.5 * d.thickness);
  const double a = d.radius - re;
  const double yt = d.top.y() - re, yb = d.top.y() - d.thickness + re;
  const Vec3 q = p - d.top;
  const double rho = std::hypot(q.x(), q.z());
  const Vec3 radial = rho > 1e-12 ? Vec3(q.x() / rho, 0, q.z() / rho) : Vec3::UnitX();
  const double dr = rho - a;
  const double mid = 0.5 * (yt + yb);
  const double dy = std::abs(p.y() - mid) - 0.5 * (yt - yb);
  const Vec3 up(0, p.y() >= mid ? 1.0 : -1.0, 0);
  double core = 0;
  Vec3 n;
  if (dr > 0 && dy > 0) {
    core = std::hypot(dr, dy);
    n = (dr * radial + dy * up) / core;
  } else if (dr > dy) {
    core = dr;
    n = radial;
  } else {
    core = dy;
    n = up;
  }
  if (normal) *normal = n;
  return core - re;
}

// A hand as the simulation sees it: no device, only a pose and a size. `id` is 0 (left) or
// 1 (right); a capsule from palm to fingertip when `tip` differs from `position`.
struct HandProxy {
  int id = 0;
  bool tracked = false;
  Vec3 position{0, 0, 0};  // palm or pinch point (m)
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Vec3 tip{0, 0, 0};      // capsule end (= position: a sphere)
  double radius = 0.04;   // collision radius (m)
  bool collides = false;  // push cloth away (hand as obstacle)
};

// Coulomb friction of muslin on a dress form's linen cover (woven cotton on woven cotton or
// linen: static coefficients of about 0.4-0.6 are reported; this is the middle).
inline constexpr double kFormFriction = 0.5;
// The energy-based solvers' friction (Newton, VBD) sticks below this tangential speed (m/s):
// IPC's eps_v, the smoothing width of the lagged friction potential is eps_v h.
inline constexpr double kFrictionSlipSpeed = 1e-3;

// Coulomb friction as a position correction (the position-based solvers' contact step): x was
// just pushed `push` (m, > 0) along the unit normal n out of a surface at rest; the tangential
// part of its motion since `start` is removed while within mu * push (sticking), else shortened
// by mu * push (sliding). With push = g_n h^2 for a resting vertex this is Coulomb's law per step.
inline void coulomb_position_friction(Vec3& x, const Vec3& start, const Vec3& n, double push,
                                      double mu) {
  const Vec3 dx = x - start;
  const Vec3 t = dx - n.dot(dx) * n;
  const double tl = t.norm(), lim = mu * push;
  x -= tl <= lim ? t : (lim / tl) * t;
}

// Everything the cloth can touch.
struct SceneObjects {
  std::shared_ptr<const DressForm> form;  // may be null
  std::vector<Plate> plates;
  std::vector<Box> boxes;
  std::vector<Sphere> spheres;
  std::vector<Disc> discs;  // not kept in session logs (only the drape tester sets them)
  std::vector<HandProxy> hands;
  bool floor = true;      // the stage floor y = 0
  double offset = 0.002;  // cloth thickness / collision offset (m): kept-out distance
  // Coulomb friction coefficient of the cloth on every object (0: frictionless). Muslin on a
  // dress form's linen cover or on itself: ~0.4-0.6 (kFormFriction). Position-based solvers
  // apply it in their contact projection, Newton and VBD through a lagged dissipation
  // potential (ClothEnergy::set_friction), the static solve too (docs/solvers.md).
  double friction = 0;
  // The cloth against itself (vertex-triangle pairs found through a spatial hash, kept
  // `offset` apart; sim/energy/self_collision.hpp). Off unless the scene asks: it costs a hash
  // build per contact detection and a pass per substep. Solved by XPBD (the default solver); the
  // other solvers ignore it (docs/solvers.md).
  bool self_collision = false;
};

}  // namespace drape::sim
