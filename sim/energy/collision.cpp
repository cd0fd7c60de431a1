// Cloth-object collision: analytic primitives, the dress form's section lookup, bounds culling.
#include "sim/energy/collision.hpp"

#include <algorithm>
#include <cmath>

#include "sim/form/dress_form.hpp"

namespace drape::sim {

Aabb form_bounds(const DressForm& form) {
  Aabb box;
  for (int j = 0; j < form.num_sections(); ++j) {
    for (int n = 0; n < DressForm::kAngles; ++n) box.grow(form.point(j, n));
  }
  return box;
}

double collide_floor(Vec3& p, double offset) {
  if (p.y() >= offset) return 0;
  const double pen = offset - p.y();
  p.y() = offset;
  return pen;
}

double collide_sphere(Vec3& p, const Vec3& centre, double radius, double offset) {
  const Vec3 d = p - centre;
  const double r = radius + offset;
  const double dist2 = d.squaredNorm();
  if (dist2 >= r * r) return 0;
  const double dist = std::sqrt(dist2);
  const Vec3 n = dist > 1e-12 ? Vec3(d / dist) : Vec3::UnitY();
  p = centre + r * n;
  return r - dist;
}

double collide_capsule(Vec3& p, const Vec3& a, const Vec3& b, double radius, double offset) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return collide_sphere(p, a + t * ab, radius, offset);
}

double collide_box(Vec3& p, const Vec3& centre, const Vec3& half, double offset) {
  const Vec3 q = p - centre;
  const Vec3 outside = (q.cwiseAbs() - half).cwiseMax(0.0);
  const double out_dist = outside.norm();
  if (out_dist > 0) {
    if (out_dist >= offset) return 0;
    // Outside but within the offset: push away from the nearest box point.
    const Vec3 nearest = q.cwiseMax(-half).cwiseMin(half);
    const Vec3 n = (q - nearest) / out_dist;
    p = centre + nearest + offset * n;
    return offset - out_dist;
  }
  // Inside: leave through the nearest face.
  const Vec3 depth = half - q.cwiseAbs();  // >= 0 per axis
  int axis = 0;
  if (depth.y() < depth[axis]) axis = 1;
  if (depth.z() < depth[axis]) axis = 2;
  const double s = q[axis] >= 0 ? 1.0 : -1.0;
  p[axis] = centre[axis] + s * (half[axis] + offset);
  return depth[axis] + offset;
}

double collide_plate(Vec3& p, const Plate& plate, double offset) {
  const Vec3 c = plate.centre - Vec3(0, 0.5 * plate.thickness, 0);
  return collide_box(p, c, Vec3(plate.half_x, 0.5 * plate.thickness, plate.half_z), offset);
}

double collide_disc(Vec3& p, const Disc& disc, double offset) {
  Vec3 n;
  const double d = disc_distance(p, disc, &n);
  if (d >= offset) return 0;
  p += (offset - d) * n;
  return offset - d;
}

void Collider::prepare(const ClothState& state, const SceneObjects& scene) {
  cloth_box_ = Aabb{};
  for (const Vec3& p : state.x) cloth_box_.grow(p);
  const Aabb cb = cloth_box_.inflated(scene.offset);
  active_.clear();  // capacity kept: no allocation once warmed up
  if (scene.floor && cb.lo.y() < 0) active_.push_back({Kind::kFloor, 0});
  if (scene.form) {
    if (cached_form_ != scene.form.get()) {
      cached_form_ = scene.form.get();
      form_box_ = form_bounds(*scene.form);
    }
    if (cb.overlaps(form_box_)) active_.push_back({Kind::kForm, 0});
  }
  for (size_t i = 0; i < scene.plates.size(); ++i) {
    const Plate& pl = scene.plates[i];
    const Aabb box{pl.centre - Vec3(pl.half_x, pl.thickness, pl.half_z),
                   pl.centre + Vec3(pl.half_x, 0, pl.half_z)};
    if (cb.overlaps(box)) active_.push_back({Kind::kPlate, static_cast<int>(i)});
  }
  for (size_t i = 0; i < scene.boxes.size(); ++i) {
    const Box& b = scene.boxes[i];
    if (cb.overlaps({b.centre - b.half, b.centre + b.half}))
      active_.push_back({Kind::kBox, static_cast<int>(i)});
  }
  for (size_t i = 0; i < scene.spheres.size(); ++i) {
    const Sphere& s = scene.spheres[i];
    if (cb.overlaps({s.centre.array() - s.radius, s.centre.array() + s.radius}))
      active_.push_back({Kind::kSphere, static_cast<int>(i)});
  }
  for (size_t i = 0; i < scene.discs.size(); ++i) {
    const Disc& d = scene.discs[i];
    const Vec3 half(d.radius, d.thickness, d.radius);
    if (cb.overlaps({d.top - half, d.top + Vec3(d.radius, 0, d.radius)}))
      active_.push_back({Kind::kDisc, static_cast<int>(i)});
  }
  for (size_t i = 0; i < scene.hands.size(); ++i) {
    const HandProxy& h = scene.hands[i];
    if (!h.tracked || !h.collides) continue;
    Aabb box;
    box.grow(h.position);
    box.grow(h.tip);
    if (cb.overlaps(box.inflated(h.radius))) active_.push_back({Kind::kHand, static_cast<int>(i)});
  }
  n_active_ = static_cast<int>(active_.size());
}

double Collider::push_out(Vec3& p, const SceneObjects& scene) const {
  const double off = scene.offset;
  double pen = 0;
  for (const Active& a : active_) {
    double d = 0;
    switch (a.kind) {
      case Kind::kFloor:
        d = collide_floor(p, off);
        break;
      case Kind::kForm:
        d = scene.form->push_outside(p, off);
        break;
      case Kind::kPlate:
        d = collide_plate(p, scene.plates[a.index], off);
        break;
      case Kind::kBox:
        d = collide_box(p, scene.boxes[a.index].centre, scene.boxes[a.index].half, off);
        break;
      case Kind::kSphere:
        d = collide_sphere(p, scene.spheres[a.index].centre, scene.spheres[a.index].radius, off);
        break;
      case Kind::kDisc:
        d = collide_disc(p, scene.discs[a.index], off);
        break;
      case Kind::kHand: {
        const HandProxy& h = scene.hands[a.index];
        d = collide_capsule(p, h.position, h.tip, h.radius, off);
        break;
      }
    }
    pen = std::max(pen, d);
  }
  return pen;
}

namespace {
bool collidable(uint8_t f) {
  return (f & (kFlagKinematic | kFlagNoCollide | kFlagPinned | kFlagPinched)) == 0;
}
}  // namespace

CollisionStats Collider::project(ClothState& state, const SceneObjects& scene) {
  prepare(state, scene);
  CollisionStats st;
  st.objects_tested = n_active_;
  if (n_active_ == 0) return st;
  const size_t n = state.x.size();
  for (size_t i = 0; i < n; ++i) {
    if (!collidable(state.flags[i])) continue;
    const Vec3 before = state.x[i];
    const double pen = push_out(state.x[i], scene);
    if (pen > 0) {
      ++st.contacts;
      st.max_penetration = std::max(st.max_penetration, pen);
      if (scene.friction > 0 && i < state.x_prev.size()) {
        // Against the motion since x_prev (the substep's start), along the push-out.
        const Vec3 push = state.x[i] - before;
        const double pl = push.norm();
        if (pl > 0)
          coulomb_position_friction(state.x[i], state.x_prev[i], push / pl, pl, scene.friction);
      }
    }
  }
  return st;
}

CollisionStats Collider::response_displacements(const ClothState& state, const SceneObjects& scene,
                                                std::vector<Vec3>& disp) {
  prepare(state, scene);
  CollisionStats st;
  st.objects_tested = n_active_;
  const size_t n = state.x.size();
  disp.resize(n);
  std::fill(disp.begin(), disp.end(), Vec3::Zero());
  if (n_active_ == 0) return st;
  for (size_t i = 0; i < n; ++i) {
    if (!collidable(state.flags[i])) continue;
    Vec3 p = state.x[i];
    const double pen = push_out(p, scene);
    if (pen > 0) {
      disp[i] = p - state.x[i];  // = -(eps - d) n, eq. 3-7 times dt^2 / m
      ++st.contacts;
      st.max_penetration = std::max(st.max_penetration, pen);
    }
  }
  return st;
}

}  // namespace drape::sim
