// Cloth collision against the scene: the dress form by O(1) section lookup (method 2.2,
// DressForm::push_outside), plates, boxes, spheres and discs analytically, hand spheres/capsules,
// and the floor. Every object keeps the cloth `offset` (thickness) away from its surface. Objects
// whose bounding box does not touch the cloth's (grown by the offset) are skipped.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/core/scene_objects.hpp"

namespace drape::sim {

struct Aabb {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  void grow(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Aabb inflated(double r) const { return {lo.array() - r, hi.array() + r}; }
  bool overlaps(const Aabb& o) const {
    return (lo.array() <= o.hi.array()).all() && (o.lo.array() <= hi.array()).all();
  }
};

// Bounding box of the form's section model (all samples, every height).
Aabb form_bounds(const DressForm& form);

// Keeps point p at least `offset` outside each object; each returns the penetration depth
// (offset - distance from the surface; > 0 when p was moved, else 0 and p untouched).
double collide_floor(Vec3& p, double offset);
double collide_sphere(Vec3& p, const Vec3& centre, double radius, double offset);
double collide_capsule(Vec3& p, const Vec3& a, const Vec3& b, double radius, double offset);
double collide_box(Vec3& p, const Vec3& centre, const Vec3& half, double offset);
double collide_plate(Vec3& p, const Plate& plate, double offset);
double collide_disc(Vec3& p, const Disc& disc, double offset);

struct CollisionStats {
  double max_penetration = 0;  // deepest (offset - distance) found before the response (m)
  int contacts = 0;            // vertices moved
  int objects_tested = 0;      // objects whose bounds touched the cloth's
};

// Collision of a whole cloth against the scene. prepare() once per step (bounding-box tests;
// caches the form's bounds), then push_out() per vertex. No allocation after the first call.
class Collider {
 public:
  // Computes the cloth's bounding box and decides which objects can be touched.
  void prepare(const ClothState& state, const SceneObjects& scene);
  // Moves p out of every active object in turn; returns its largest penetration.
  double push_out(Vec3& p, const SceneObjects& scene) const;
  // Projects every collidable vertex (not pinned, pinched, kinematic or kNoCollide) out of the
  // objects, changing only x (for position-based solvers). With scene.friction > 0, Coulomb
  // friction against the motion since x_prev (the substep's start).
  CollisionStats project(ClothState& state, const SceneObjects& scene);
  // The baseline's collision response: for each collidable vertex closer than the offset, the
  // response displacement F_resp dt^2 / m = -(eps - d) n (it moves the vertex to distance eps) is
  // written to disp[i] (zero elsewhere). Positions are not changed.
  CollisionStats response_displacements(const ClothState& state, const SceneObjects& scene,
                                        std::vector<Vec3>& disp);
  int active_objects() const { return n_active_; }
  const Aabb& cloth_bounds() const { return cloth_box_; }

 private:
  enum class Kind : uint8_t { kFloor, kForm, kPlate, kBox, kSphere, kDisc, kHand };
  struct Active {
    Kind kind;
    int index;
  };
  std::vector<Active> active_;
  int n_active_ = 0;
  Aabb cloth_box_;
  const DressForm* cached_form_ = nullptr;
  Aabb form_box_;
};

}  // namespace drape::sim
