// The cloth energy every solver minimises (docs/solvers.md):
//   E(x) = membrane (anisotropic StVK on material coordinates: warp, weft, shear)
//        + bending (default: a consistent anisotropic per-triangle shape-operator energy built
//          from the hinge vectors, constant Hessian; the discrete-shell dihedral-angle hinges
//          and the quadratic hinges stay available as EnergyOptions::Bending::kDihedral/kLinear)
//        + gravity + optional weak pressure toward the form + contact penalty,
// or, as a second model, the baseline's 8-neighbour springs + gravity + contact.
// Everything is cooked once per topology_version into flat arrays (no allocation per step).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/core/scene_objects.hpp"

namespace drape::sim {

class ThreadPool;  // sim/core/thread_pool.hpp

using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

struct EnergyOptions {
  enum class Model { kFem, kSprings };
  Model model = Model::kFem;
  bool gravity = true;
  Vec3 g{0, -kGravity, 0};
  double pressure = 0.0;  // Pa: weak pressure pushing the cloth toward the form's axis
  bool bending = true;
  // Bending model.
  // kTensor (default): per triangle t the shape operator S = (S_uu, S_vv, S_uv) (material
  //   coordinates) is recovered from the angles of its (up to three) hinges, theta_e = L_e . S
  //   (exact for any constant curvature on any mesh), and E_t = 1/2 A_t (B_weft S_uu^2 +
  //   B_warp S_vv^2 + 2 B_twist S_uv^2); a free edge (no hinge) leaves S to the least energy
  //   (see curvature_estimator for how S_t is formed). theta_e is the linear hinge vector
  //   s_e = sum_k K_k x_k, so E = 1/2 x^T (P (x) I3) x with a constant sparse PSD vertex matrix
  //   P (the triangle, its neighbours and their flaps: ~32 entries per row): gradient P x,
  //   Hessian P (x) I3.
  // kDihedral: E = 1/2 w theta^2 per hinge with theta the dihedral angle between the two
  //   triangles' normals (discrete shells, Grinspun et al. 2003; rest angle 0: flat material).
  // kLinear: E = 1/2 w |sum_k K_k x_k|^2 per hinge (Bergou et al. 2006 form; constant Hessian).
  // The hinge models use the same w and K. They are not consistent on the criss-cross grid
  // (a warp bend can go through alternating diagonal folds: the Peirce strip is ~15-20 % too
  // soft against the elastica).
  enum class Bending { kTensor, kDihedral, kLinear };
  Bending bending_model = Bending::kTensor;
  // Twist rigidity B_twist (N m) of kTensor; <= 0: sqrt(bending_warp * bending_weft) (Huber's
  // orthotropic-plate estimate with nu = 0; = B for an isotropic fabric: the nu = 0 plate).
  double bending_twist = 0;
  // kTensor's curvature estimate per triangle from the hinge angles (docs/solvers.md):
  // kLocal: S_t = L_t^-1 theta_t (exact for constant curvature on any mesh, but its
  //   element average is not the surface's: alternating diagonal folds bend a strip for
  //   twist energy only; the Peirce strip comes out ~23 % soft);
  // kDivergence: S_t = 1/A_t sum_e |e|/2 theta_e n_e n_e^T (the distributional Hessian; no
  //   soft mode, but element-to-element noise: twist on the criss-cross grid 2x too stiff);
  // kBlended (default): S = S_loc + W (S_div - S_loc), W a mass-conserving average over the
  //   triangle and its edge neighbours: the average of kDivergence, the accuracy of kLocal
  //   (exact on the criss-cross grid for any constant curvature).
  enum class Curvature { kBlended, kLocal, kDivergence };
  Curvature curvature_estimator = Curvature::kBlended;
  // kBlended: number of W passes (W^k). 2 halves the error on irregular meshes (30 % jitter:
  // <= 2.3 % instead of <= 6.6 %) at twice P's stencil (~59 entries per row, 27 VBD colours at
  // 128^2 instead of 32 and 17); both are exact on the criss-cross grid.
  int curvature_smoothing = 1;
  // A hinge between a deformable triangle and a rigid one (all three vertices pinned or
  // kinematic when the energy is built) takes only the deformable triangle's area as its dual
  // area: the clamped side does not bend, so the hinge's curvature theta/width lives on half
  // the usual strip. Without it a clamped edge is first-order wrong (docs/solvers.md).
  // kTensor: rigid triangles store no bending energy, and such a hinge's L_e is that of the
  // free side alone (the rigid opposite vertex is taken on the edge's chord).
  bool rigid_boundary_hinges = true;
  double contact_stiffness = 0;   // N/m per vertex; 0 = automatic (from mass and dt)
  double contact_margin = 0.005;  // m: contacts detected within offset + margin
  // kTensor: assemble the vertex matrix P (bending_offsets() ...). The energy, its gradient and
  // the per-vertex blocks (Verlet, VBD, Newton, relax) read P; XPBD projects the curvature rows
  // only and switches it off: P is the largest part of a rebuild (40 ms of ~120 ms at 128^2,
  // after every cut). Without P the energy and gradient are summed over the rows (same values);
  // vertex_force_hessian() and vertex_neighbours() then throw std::logic_error.
  bool bending_matrix = true;
  bool cull_by_bounds = true;  // test only objects whose bounds touch the cloth's bounds
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
  // Cooks element data for the cloth's current topology and rest state (material coords). With
  // a pool, the tensor bending's sparse products run on it (the same result as without).
  void build(const Cloth& cloth, const EnergyOptions& opt, ThreadPool* pool = nullptr);
  // The same for a cloth whose topology changed since the last build (a cut, slit or sew), with
  // the tensor bending rows of every triangle the change did not reach kept from that build:
  // the rows made again are those of the triangles whose vertices, material coordinates or
  // rigidity changed, their edge neighbours before and after the change, and those neighbours'
  // neighbours (a row reads its triangle's hinges and its neighbours'). The result equals
  // build()'s bit for bit. Falls back to build() (returns false) unless the last build and this
  // one are of the tensor bending with the blended estimate (one smoothing pass) without the
  // matrix P, with the same options and fabric and the same triangle count, no triangle
  // degenerate in material space, and at most an eighth of the triangles changed.
  bool update(const Cloth& cloth, const EnergyOptions& opt, ThreadPool* pool = nullptr);
  // What a later update() of this energy reads: the last build's triangles, their hinges'
  // triangles, tensor bending rows and inputs (update() or build() on the copy makes the same
  // elements and rows as on this energy; the rest, contacts, friction and the contact stiffness
  // included, is left at its defaults). It reads nothing a step writes, so one thread may make it
  // while another steps with this energy; the large arrays are copied in parts with a pause
  // point before each (TickGate).
  ClothEnergy spare_copy() const;
  // Per triangle: 1 when the last build or update made its bending rows, 0 when it kept them.
  const std::vector<char>& rebuilt_triangles() const { return rebuilt_; }
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

  // --- bending, whichever model --------------------------------------------------------------
  double bending_energy(const std::vector<Vec3>& x) const;
  void add_bending_gradient(const std::vector<Vec3>& x, std::vector<Vec3>& grad) const;
  // kTensor: the constant vertex matrix P (E_bend = 1/2 sum_ij P_ij x_i . x_j), CSR with sorted
  // columns, symmetric, diagonal always stored; empty for the hinge models.
  bool tensor_bending() const { return tensor_; }
  bool has_bending_matrix() const { return !bend_col_.empty(); }
  const std::vector<int>& bending_offsets() const { return bend_off_; }
  const std::vector<int>& bending_columns() const { return bend_col_; }
  const std::vector<double>& bending_values() const { return bend_val_; }
  // kTensor: energy 1/2 A_t sum_c D_c |S_t,c|^2 of triangle t alone (S_t,c = its curvature
  // rows below, vectors along the normal), and its number of own hinges (3: interior; 1-2:
  // free boundary; 0: rigid or no hinge, no bending energy).
  double bending_triangle_energy(int t, const std::vector<Vec3>& x) const;
  int bending_triangle_hinges(int t) const { return tri_nh_.empty() ? 0 : tri_nh_[t]; }
  // kTensor as linear vector constraints (for XPBD): row r = 3t + c (c = uu, vv, uv) is
  // V_r = sum_k bending_row_values()[k] x[bending_row_columns()[k]] over
  // k in [bending_row_offsets()[r], [r + 1]) (the curvature component c of triangle t, carried
  // by the surface normal), and E_bend = 1/2 sum_r bending_row_stiffness(r) |V_r|^2.
  int num_bending_rows() const {
    return tri_S_off_.empty() ? 0 : static_cast<int>(tri_S_off_.size()) - 1;
  }
  const std::vector<int>& bending_row_offsets() const { return tri_S_off_; }
  const std::vector<int>& bending_row_columns() const { return tri_S_col_; }
  const std::vector<double>& bending_row_values() const { return tri_S_val_; }
  double bending_row_stiffness(int r) const { return tri_area_[r / 3] * bend_D_[r % 3]; }

  // --- bending hinges ------------------------------------------------------------------------
  // Hinge h: edge (0, 1), opposite vertices 2 (first triangle) and 3 (second triangle).
  // kDihedral: E = 1/2 w theta^2, theta = signed dihedral angle (0 when flat, in (-pi, pi]);
  // kLinear:   E = 1/2 w |sum_k K_k x_k|^2.
  // Under kTensor the per-hinge functions below evaluate the kLinear hinge (XPBD's bending
  // constraint); the energy's bending term is then bending_energy(), not their sum.
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
  // deepest penetration (m). Reuses internal storage. With a pool the vertices are tested in
  // parallel and the contacts then listed in vertex order (the same list as without).
  double detect_contacts(const Cloth& cloth, const SceneObjects& scene, ThreadPool* pool = nullptr);
  // Between detections (after one, with the same cloth and objects): vertex i tested again alone,
  // as detect_contacts tests it (without its culling of objects by the cloth's bounds, which only
  // skips objects out of reach); returns its penetration (as detect_contacts). Its contact
  // changes in contacts() once list_contacts() lists the tested candidates (safe to call for
  // different vertices on several threads).
  double retest_contact(const Cloth& cloth, const SceneObjects& scene, int i);
  void list_contacts(int num_vertices, ThreadPool* pool = nullptr);
  // project_contacts over vertices [b, e) with their contacts as last tested (listed or not).
  void project_tested_contacts(std::vector<Vec3>& x, const std::vector<Vec3>* start, double mu,
                               int b, int e) const;
  // Vertex i's contact as last tested (vertex -1: none), listed or not yet.
  const Contact& tested_contact(int i) const { return candidate_[i]; }
  // The square of how far vertex i can move from where it was last tested without coming within
  // reach of any object (a lower bound; 0 with a contact): until then a test again finds nothing.
  double clearance2(int i) const { return clearance2_[i]; }
  void clear_contacts();
  double contact_stiffness() const { return k_contact_; }
  void set_contact_stiffness(double k) { k_contact_ = k; }
  // Index of the contact of vertex i, or -1.
  int contact_of(int i) const { return contact_index_[i]; }
  const std::vector<Contact>& contacts() const { return contacts_; }
  // Projects x onto every contact's half-space (used by position-based solvers). With `start`
  // (the positions where the substep began) and mu > 0, Coulomb friction as a position
  // correction: the tangential motion of the substep is removed when it is within mu times
  // the normal correction (static), else shortened by that much (kinetic).
  void project_contacts(std::vector<Vec3>& x, const std::vector<Vec3>* start = nullptr,
                        double mu = 0) const;

  // --- friction for the energy-based solvers (Newton, VBD, the static solve) -----------------
  // Coulomb friction as IPC's lagged dissipation potential: over the vertices with a contact,
  // D = sum_i mu lambda_i f0(|u_i|), u_i = T_i (x_i - a_i), T_i = I - n_i n_i^T (n_i the normal
  // of its current contact), a_i its anchor (where the step or the static solve started),
  // lambda_i its normal load held fixed while minimising (lagged), and f0 smoothed below eps:
  // f0(y) = y^2/eps - y^3/(3 eps^2) + eps/3 (y < eps), y beyond (C1; f0' = 1 beyond eps, so the
  // force is mu lambda once sliding). energy(), gradient() and vertex_force_hessian() include
  // it once set_friction() was called, until clear_friction().
  void set_friction(double mu, double eps, const std::vector<Vec3>& anchor);
  void clear_friction() { friction_mu_ = 0; }
  bool friction_on() const { return friction_mu_ > 0; }
  // Normal loads from the state: the part of -(dE/dx) without contact and friction terms that
  // presses each contact vertex into its plane (a static load), or the penalty's k max(0, -d)
  // (a step of a penalty solver, whose contacts carry the inertia too).
  void lag_friction_load(const std::vector<Vec3>& x, const std::vector<double>& mass);
  void lag_friction_penalty(const std::vector<Vec3>& x);
  double friction_load(int i) const { return friction_load_[i]; }
  // Vertex i's friction gradient (dD/dx_i) and its 3x3 Hessian block (PSD), zero without one.
  void friction_gradient_hessian(int i, const Vec3& xi, Vec3& g, Mat3* H) const;
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
  std::vector<std::array<int32_t, 2>> hinge_t_;  // the triangles of slots 2 and 3
  // kTensor: hinges per deformable triangle, its curvature rows S_t = sum_j G_tj x_j (CSR over
  // rows 3t + c, c = uu, vv, uv), D = (B_weft, B_warp, 2 B_twist) and P in CSR.
  std::vector<int> tri_nh_, tri_S_off_, tri_S_col_;
  std::vector<double> tri_S_val_;
  Eigen::Vector3d bend_D_ = Eigen::Vector3d::Zero();
  std::vector<int> bend_off_, bend_col_;
  std::vector<double> bend_val_, bend_diag_;
  bool tensor_ = false;  // kTensor with nonzero rigidity: rows (and P unless switched off)
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
  std::vector<Contact> candidate_;      // per vertex, the deepest candidate (vertex -1: none)
  std::vector<uint8_t> has_candidate_;  // per vertex: candidate_[i].vertex >= 0 (a byte to scan)
  std::vector<float> clearance2_;       // per vertex: clearance2()
  // Tests vertex i against the scene's objects (the floor and the form only when on): its
  // deepest candidate into candidate_[i] and its clearance into clearance2_[i] (at most
  // culled_clear, the clearance from the objects detect_contacts culled); returns its deepest
  // penetration (0: none).
  double test_vertex(const Cloth& cloth, const SceneObjects& scene, int i, bool floor, bool form_on,
                     double culled_clear);
  std::vector<double> deepest_part_;  // per pool worker
  std::vector<Vec3> bounds_part_;     // per pool worker: lower and upper corner
  std::vector<int> block_contacts_;   // per block of kContactBlock vertices: contacts before it
  double k_contact_ = 1e3;
  int culled_ = 0;
  // friction (set_friction)
  double friction_mu_ = 0, friction_eps_ = 1e-4;
  std::vector<Vec3> friction_anchor_;
  std::vector<double> friction_load_;
  // lag_friction_load's scratch gradient (no allocation per step)
  std::vector<Vec3> friction_grad_;

  // The tangential part of contact c's vertex's motion from its friction anchor.
  Vec3 friction_slip(const Contact& c, const Vec3& xi) const;
  void build_vertex_lists();
  // update(): the last build's inputs (material coordinates, fabric, each triangle's rigidity),
  // its rows while the new ones are made, the triangles whose rows are made again (need_rows_),
  // those whose local estimates they read (need_local_), and per triangle whether the last
  // build made its rows (rebuilt_).
  std::vector<Vec2> built_material_;
  FabricParams built_fabric_;
  std::vector<char> built_rigid_, need_rows_, need_local_, rebuilt_;
  std::vector<int> old_S_off_, old_S_col_;
  std::vector<double> old_S_val_;
  bool reuse_rows_ = false;
  bool built_all_triangles_ = false;  // no triangle left out as degenerate
  bool mark_changed(const Cloth& cloth, const EnergyOptions& opt);
  void widen_reach();
  void note_built(const Cloth& cloth);
  bool hinge_needed(int h) const;
  void hinge_vectors(const std::vector<Vec2>& M, const std::vector<char>& rigid,
                     std::vector<Eigen::Vector3d>& L, std::vector<Eigen::Vector3d>& Nn,
                     std::vector<double>& len) const;
  void build_tensor_bending(const Cloth& cloth, ThreadPool* pool);
  void stress(int t, const std::vector<Vec3>& x, Eigen::Matrix<double, 3, 2>& F,
              Eigen::Matrix2d& S) const;
};

// Lumped masses from triangle areas in material space (areal density), for scenes that do
// not use Cloth::relump_masses; inverse masses 0 where not free.
void lump_masses(Cloth& cloth);

}  // namespace drape::sim
