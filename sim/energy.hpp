// The cloth energy every solver minimises (docs/solvers.md):
//   E(x) = membrane (anisotropic StVK on material coordinates: warp, weft, shear)
//        + bending (discrete-shell dihedral-angle hinges, warp/weft rigidity; the former
//          quadratic linear-operator hinge stays available as EnergyOptions::Bending::kLinear)
//        + gravity + optional weak pressure toward the form + contact penalty,
// or, as a second model, the study's 8-neighbour springs (method eq. 3-1) + gravity + contact.
// Everything is cooked once per topology_version into flat arrays (no allocation per step).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "sim/cloth.hpp"
#include "sim/scene.hpp"

namespace drape::sim {

using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

struct EnergyOptions {
  enum class Model { kFem, kSprings };
  Model model = Model::kFem;
  bool gravity = true;
  Vec3 g{0, -kGravity, 0};
  double pressure = 0.0;  // Pa: weak pressure pushing the cloth toward the form's axis
  bool bending = true;
  // Bending hinge model. kDihedral (default): E = 1/2 w theta^2 with theta the dihedral angle
  // between the two triangles' normals (discrete shells, Grinspun et al. 2003; rest angle 0:
  // the material is flat). kLinear: E = 1/2 w |sum_k K_k x_k|^2 with the rest-state weights
  // (Bergou et al. 2006 form; constant Hessian). Both use the same w and K.
  enum class Bending { kDihedral, kLinear };
  Bending bending_model = Bending::kDihedral;
  // A hinge between a deformable triangle and a rigid one (all three vertices pinned or
  // kinematic when the energy is built) takes only the deformable triangle's area as its dual
  // area: the clamped side does not bend, so the hinge's curvature theta/width lives on half
  // the usual strip. Without it a clamped edge is first-order wrong (docs/solvers.md).
  bool rigid_boundary_hinges = true;
  double contact_stiffness = 0;   // N/m per vertex; 0 = automatic (from mass and dt)
  double contact_margin = 0.005;  // m: contacts detected within offset + margin
  bool cull_by_bounds = true;     // test only objects whose bounds touch the cloth's bounds
  // Springs model only: structural and diagonal stiffness (N/m); 0 = derived from the fabric.
  double spring_k_struct = 0, spring_k_diag = 0;
};

// One active contact: a half-space n.(x - p) >= 0 per vertex, linearised at detection time.
struct Contact {
  int vertex;
  Vec3 n;  // unit outward normal
  Vec3 p;  // point on the offset surface
};

class ClothEnergy {
 public:
  // Cooks element data for the cloth's current topology and rest state (material coords).
  void build(const Cloth& cloth, const EnergyOptions& opt);
  bool up_to_date(const Cloth& cloth) const {
    return built_version_ == cloth.topology_version && num_vertices_ == cloth.num_vertices();
  }
  const EnergyOptions& options() const { return opt_; }
  EnergyOptions& mutable_options() { return opt_; }

  // Total energy (J) and gradient (dE/dx, N) over every vertex, contacts included.
  double energy(const std::vector<Vec3>& x, const std::vector<double>& mass) const;
  void gradient(const std::vector<Vec3>& x, const std::vector<double>& mass,
                std::vector<Vec3>& grad) const;

  // --- membrane triangles -------------------------------------------------------------------
  int num_triangles() const { return static_cast<int>(tri_v_.size()); }
  const std::array<int32_t, 3>& tri(int t) const { return tri_v_[t]; }
  double tri_energy(int t, const std::vector<Vec3>& x) const;
  void tri_gradient(int t, const std::vector<Vec3>& x, Vec3 g[3]) const;
  // Full 9x9 Hessian; `project` clamps the second Piola stress to PSD, which makes it PSD.
  void tri_hessian(int t, const std::vector<Vec3>& x, Mat9& H, bool project) const;
  // The 3x3 block of vertex slot a (0..2) and that slot's gradient (for VBD).
  void tri_vertex_block(int t, int a, const std::vector<Vec3>& x, Vec3& g, Mat3& H) const;

  // --- bending hinges ------------------------------------------------------------------------
  // Hinge h: edge (0, 1), opposite vertices 2 (first triangle) and 3 (second triangle).
  // kDihedral: E = 1/2 w theta^2, theta = signed dihedral angle (0 when flat, in (-pi, pi]);
  // kLinear:   E = 1/2 w |sum_k K_k x_k|^2.
  // w = B(n) |e|^2 / (A_1 + A_2) (rest areas; A of a rigid triangle left out, see
  // EnergyOptions::rigid_boundary_hinges), B(n) = bending_warp n_v^2 + bending_weft n_u^2 with
  // n the edge's in-plane normal in material space (the direction of curvature it resists).
  int num_hinges() const { return static_cast<int>(hinge_v_.size()); }
  const std::array<int32_t, 4>& hinge(int h) const { return hinge_v_[h]; }
  double hinge_energy(int h, const std::vector<Vec3>& x) const;
  void hinge_gradient(int h, const std::vector<Vec3>& x, Vec3 g[4]) const;
  // Model Hessian (12x12). kDihedral: exact w (dtheta dtheta^T + theta d2theta) when
  // `project` is false; with `project` its eigenvalues are clamped at 0 (PSD). kLinear: the
  // constant w K K^T (x) I (exact and PSD, `project` ignored).
  void hinge_hessian(int h, const std::vector<Vec3>& x, Mat12& H, bool project = true) const;
  // The linear model's constant Hessian w K K^T (x) I (exact for kLinear; for kDihedral the
  // rest-state stiffness with the tangential directions added; kept for callers without x).
  void hinge_hessian(int h, Mat12& H) const;
  // Gradient and 3x3 Hessian block of vertex slot a (0..3), for block descent (VBD).
  // kDihedral: g = w theta dtheta_a, H = w dtheta_a dtheta_a^T (Gauss-Newton, PSD);
  // kLinear: g = w K_a s, H = w K_a^2 I.
  void hinge_vertex_block(int h, int a, const std::vector<Vec3>& x, Vec3& g, Mat3& H) const;
  // Dihedral angle of hinge h and its gradient (d theta / d x_k for the four slots); false
  // (theta = 0, zero gradient) when a triangle is degenerate in x.
  bool hinge_angle(int h, const std::vector<Vec3>& x, double& theta, Vec3 dtheta[4]) const;
  // Rest-state linear weights K (sum_k K_k x_k ~ theta n for isometric bending near flat) and
  // the weight w; used by the linear model and by XPBD's hinge constraints.
  const std::array<double, 4>& hinge_K(int h) const { return hinge_k_[h]; }
  double hinge_w(int h) const { return hinge_w_[h]; }

  // --- springs (second model, and the chain) -------------------------------------------------
  int num_springs() const { return static_cast<int>(spring_v_.size()); }
  const std::array<int32_t, 2>& spring(int s) const { return spring_v_[s]; }
  double spring_rest(int s) const { return spring_rest_[s]; }
  double spring_k(int s) const { return spring_k_[s]; }
  double spring_energy(int s, const std::vector<Vec3>& x) const;
  void spring_gradient(int s, const std::vector<Vec3>& x, Vec3 g[2]) const;
  void spring_hessian(int s, const std::vector<Vec3>& x, Eigen::Matrix<double, 6, 6>& H,
                      bool project) const;
  // Adds a spring (the chain scene, custom models). Invalidates nothing else.
  void add_spring(int a, int b, double k, double rest);

  // --- external: gravity + pressure ----------------------------------------------------------
  // Force on vertex i from gravity and pressure (constant in x except the pressure direction).
  Vec3 external_force(int i, const Vec3& xi, double mass) const;
  void set_form(const SceneObjects* scene) { scene_ = scene; }

  // --- contacts (penalty 1/2 k min(0, n.(x-p))^2, detected once per step) --------------------
  // Detects contacts of every non-kinematic vertex against the scene's objects; returns the
  // deepest penetration (m). Reuses internal storage.
  double detect_contacts(const Cloth& cloth, const SceneObjects& scene);
  void clear_contacts();
  double contact_stiffness() const { return k_contact_; }
  void set_contact_stiffness(double k) { k_contact_ = k; }
  // Index of the contact of vertex i, or -1.
  int contact_of(int i) const { return contact_index_[i]; }
  const std::vector<Contact>& contacts() const { return contacts_; }
  // Projects x onto every contact's half-space (used by position-based solvers).
  void project_contacts(std::vector<Vec3>& x) const;
  int num_culled_objects() const { return culled_; }

  // --- per-vertex queries for block descent --------------------------------------------------
  // Elastic + external + contact force f = -dE/dx_i and 3x3 Hessian block (PSD-projected).
  void vertex_force_hessian(int i, const std::vector<Vec3>& x, double mass, Vec3& f, Mat3& H) const;
  // Vertex adjacency (vertices sharing any element), CSR; for colouring.
  void vertex_neighbours(std::vector<int>& offsets, std::vector<int>& nbrs) const;
  double rest_area(int t) const { return tri_area_[t]; }
  // F = sum_k x_k D.row(k) for triangle t.
  const Eigen::Matrix<double, 3, 2>& tri_D(int t) const { return tri_D_[t]; }

 private:
  EnergyOptions opt_;
  uint64_t built_version_ = 0;
  int num_vertices_ = 0;
  const SceneObjects* scene_ = nullptr;
  // triangles
  std::vector<std::array<int32_t, 3>> tri_v_;
  std::vector<Eigen::Matrix<double, 3, 2>> tri_D_;  // F = [x0 x1 x2] * D (3x2)
  std::vector<double> tri_area_;
  double ku_ = 0, kv_ = 0, kshear_ = 0;
  // hinges
  std::vector<std::array<int32_t, 4>> hinge_v_;  // edge (0,1), opposite (2,3)
  std::vector<std::array<double, 4>> hinge_k_;
  std::vector<double> hinge_w_;
  // springs
  std::vector<std::array<int32_t, 2>> spring_v_;
  std::vector<double> spring_rest_, spring_k_;
  // per-vertex element lists (CSR): triangles with local slot, hinges with slot, springs
  std::vector<int> vt_off_, vt_;  // entries: t*3 + slot
  std::vector<int> vh_off_, vh_;  // entries: h*4 + slot
  std::vector<int> vs_off_, vs_;  // entries: s*2 + slot
  std::vector<double> vertex_area_;
  // contacts
  std::vector<Contact> contacts_;
  std::vector<int> contact_index_;
  double k_contact_ = 1e3;
  int culled_ = 0;

  void build_vertex_lists();
  void stress(int t, const std::vector<Vec3>& x, Eigen::Matrix<double, 3, 2>& F,
              Eigen::Matrix2d& S) const;
};

// Lumped masses from triangle areas in material space (areal density), for scenes that do
// not use Cloth::relump_masses; inverse masses 0 where not free.
void lump_masses(Cloth& cloth);

}  // namespace drape::sim
