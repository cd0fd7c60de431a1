#include "sim/energy/energy.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "sim/core/thread_pool.hpp"
#include "sim/form/dress_form.hpp"

namespace drape::sim {

namespace {

using Mat32 = Eigen::Matrix<double, 3, 2>;

Eigen::Matrix2d clamp_psd(const Eigen::Matrix2d& S) {
  // Closed form for a symmetric 2x2: eigenvalues m +- r; with one positive eigenvalue l1 the
  // positive part is l1 P1, P1 = (S - l2 I) / (l1 - l2) the projector onto its eigenvector.
  const double m = 0.5 * (S(0, 0) + S(1, 1));
  const double d = 0.5 * (S(0, 0) - S(1, 1));
  const double r = std::sqrt(d * d + S(0, 1) * S(0, 1));
  const double l1 = m + r, l2 = m - r;
  if (l2 >= 0) return S;
  if (l1 <= 0) return Eigen::Matrix2d::Zero();
  return (l1 / (l1 - l2)) * (S - l2 * Eigen::Matrix2d::Identity());
}

}  // namespace

void lump_masses(Cloth& cloth) {
  auto& st = cloth.state;
  const int n = cloth.num_vertices();
  st.mass.assign(n, 0.0);
  for (const auto& t : cloth.topo.triangles) {
    const Vec2& a = cloth.topo.material[t[0]];
    const Vec2& b = cloth.topo.material[t[1]];
    const Vec2& c = cloth.topo.material[t[2]];
    const double area = 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    for (int k = 0; k < 3; ++k) st.mass[t[k]] += cloth.fabric.areal_density * area / 3.0;
  }
  st.inv_mass.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    if (st.mass[i] <= 0) st.mass[i] = 1e-6;
    st.inv_mass[i] = cloth.is_free(i) ? 1.0 / st.mass[i] : 0.0;
  }
}

void ClothEnergy::build(const Cloth& cloth, const EnergyOptions& opt, ThreadPool* pool) {
  opt_ = opt;
  num_vertices_ = cloth.num_vertices();
  built_version_ = cloth.topology_version;
  friction_mu_ = 0;  // anchors and loads belong to the old vertices
  const auto& topo = cloth.topo;
  const FabricParams& fab = cloth.fabric;
  ku_ = fab.stretch_weft;
  kv_ = fab.stretch_warp;
  kshear_ = fab.shear;
  tri_v_.clear();
  tri_D_.clear();
  tri_area_.clear();
  hinge_v_.clear();
  hinge_k_.clear();
  hinge_w_.clear();
  hinge_t_.clear();
  tri_nh_.clear();
  tri_S_off_.clear();
  bend_off_.clear();
  bend_col_.clear();
  bend_val_.clear();
  tensor_ = false;
  // Springs added by add_spring() before build are kept only for the springs model rebuild.
  spring_v_.clear();
  spring_rest_.clear();
  spring_k_.clear();
  vertex_area_.assign(num_vertices_, 0.0);

  const auto& M = topo.material;
  if (opt_.model == EnergyOptions::Model::kFem) {
    for (const auto& t : topo.triangles) {
      if ((tri_v_.size() & 1023) == 0) pause_point();
      Eigen::Matrix2d Dm;
      Dm.col(0) = M[t[1]] - M[t[0]];
      Dm.col(1) = M[t[2]] - M[t[0]];
      const double det = Dm.determinant();
      if (std::abs(det) < 1e-16) continue;  // degenerate in material space: no stiffness
      Eigen::Matrix<double, 3, 2> B;
      B << -1, -1, 1, 0, 0, 1;
      tri_v_.push_back(t);
      tri_D_.push_back(B * Dm.inverse());
      tri_area_.push_back(0.5 * std::abs(det));
    }
    pause_point();  // (a cook ahead waits here while a tick runs: TickGate)
    // Hinges: interior edges shared by exactly two triangles.
    if (opt_.bending) {
      // Edges seen so far, listed at their lower vertex (a vertex has a handful: a walk of its
      // list is cheaper than a map's lookup — 8 ms at 128^2 with std::map). An edge keeps the
      // first triangle that met it (tri, opposite vertex) until a hinge is made of it (tri -1).
      struct EdgeSeen {
        int hi, tri, opp, next;
      };
      std::vector<int> edge_head(num_vertices_, -1);
      std::vector<EdgeSeen> edges_seen;
      edges_seen.reserve(3 * tri_v_.size());
      for (int ti = 0; ti < static_cast<int>(tri_v_.size()); ++ti) {
        if ((ti & 1023) == 0) pause_point();
        const auto& t = tri_v_[ti];
        for (int k = 0; k < 3; ++k) {
          int a = t[k], b = t[(k + 1) % 3], o = t[(k + 2) % 3];
          const int e0 = std::min(a, b), e1 = std::max(a, b);
          int found = edge_head[e0];
          while (found >= 0 && edges_seen[found].hi != e1) found = edges_seen[found].next;
          if (found < 0) {
            edges_seen.push_back({e1, ti, o, edge_head[e0]});
            edge_head[e0] = static_cast<int>(edges_seen.size()) - 1;
          } else if (edges_seen[found].tri >= 0) {
            EdgeSeen& seen = edges_seen[found];
            const int oa = seen.opp;
            const Vec2 d = M[e1] - M[e0];
            const double len = d.norm();
            if (len < 1e-12) continue;
            const Vec2 dir = d / len;
            auto foot = [&](int ov, double& s, double& h) {
              const Vec2 r = M[ov] - M[e0];
              s = r.dot(dir) / len;
              h = std::abs(dir.x() * r.y() - dir.y() * r.x());
            };
            double sa, ha, sb, hb;
            foot(oa, sa, ha);
            foot(o, sb, hb);
            if (ha < 1e-12 || hb < 1e-12) continue;
            std::array<double, 4> K{-(1 - sa) / ha - (1 - sb) / hb, -sa / ha - sb / hb, 1 / ha,
                                    1 / hb};
            // Dual area: a rigid (fully fixed) triangle does not bend and is left out.
            auto rigid = [&](int tj) {
              const auto& tv = tri_v_[tj];
              return opt_.rigid_boundary_hinges && !cloth.is_free(tv[0]) && !cloth.is_free(tv[1]) &&
                     !cloth.is_free(tv[2]);
            };
            const int t1 = seen.tri;
            double area = (rigid(t1) ? 0.0 : tri_area_[t1]) + (rigid(ti) ? 0.0 : tri_area_[ti]);
            if (area <= 0) area = tri_area_[t1] + tri_area_[ti];
            // In-plane normal of the edge (direction of curvature the hinge resists).
            const double nu = -dir.y(), nv = dir.x();
            const double B = fab.bending_warp * nv * nv + fab.bending_weft * nu * nu;
            hinge_v_.push_back({e0, e1, oa, o});
            hinge_k_.push_back(K);
            hinge_w_.push_back(B * len * len / area);
            hinge_t_.push_back({t1, ti});
            seen.tri = -1;  // a third triangle on this edge makes no further hinge
          }
        }
      }
    }
    pause_point();
    if (opt_.bending && opt_.bending_model == EnergyOptions::Bending::kTensor)
      build_tensor_bending(cloth, pool);
  } else {
    // The study's 8-neighbour springs: structural springs along grid rows/columns and both
    // diagonals of every cell (grid panels), else along triangle edges.
    const double h = topo.spacing > 0 ? topo.spacing : 0.01;
    const double ks_u = opt_.spring_k_struct > 0 ? opt_.spring_k_struct : fab.stretch_weft;
    const double ks_v = opt_.spring_k_struct > 0 ? opt_.spring_k_struct : fab.stretch_warp;
    const double kd = opt_.spring_k_diag > 0 ? opt_.spring_k_diag : fab.shear;
    (void)h;
    auto add = [&](int a, int b, double k) {
      spring_v_.push_back({a, b});
      spring_rest_.push_back((M[a] - M[b]).norm());
      spring_k_.push_back(k);
    };
    const int nx = topo.grid_nx, ny = topo.grid_ny;
    if (nx > 0 && ny > 0 && nx * ny == num_vertices_) {
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const int v = j * nx + i;
          if (i + 1 < nx) add(v, v + 1, ks_u);
          if (j + 1 < ny) add(v, v + nx, ks_v);
          if (i + 1 < nx && j + 1 < ny) {
            add(v, v + nx + 1, kd);
            add(v + 1, v + nx, kd);
          }
        }
    } else {
      std::map<std::pair<int, int>, int> seen;
      for (const auto& t : topo.triangles)
        for (int k = 0; k < 3; ++k) {
          int a = std::min(t[k], t[(k + 1) % 3]), b = std::max(t[k], t[(k + 1) % 3]);
          if (seen.emplace(std::make_pair(a, b), 1).second) {
            const Vec2 d = M[b] - M[a];
            const double c2 = d.squaredNorm() > 0 ? d.x() * d.x() / d.squaredNorm() : 0;
            add(a, b, ks_u * c2 + ks_v * (1 - c2));
          }
        }
    }
  }
  for (const auto& t : topo.triangles) {
    Eigen::Matrix2d Dm;
    Dm.col(0) = M[t[1]] - M[t[0]];
    Dm.col(1) = M[t[2]] - M[t[0]];
    for (int k = 0; k < 3; ++k) vertex_area_[t[k]] += std::abs(Dm.determinant()) / 6.0;
  }
  pause_point();
  contact_index_.assign(num_vertices_, -1);
  // The contact tests' arrays sized and written here, so that the cook (on a cook ahead's worker)
  // takes their page faults rather than the first step's detection.
  contacts_.assign(num_vertices_, Contact{});
  contacts_.clear();
  candidate_.assign(num_vertices_, Contact{});
  has_candidate_.assign(num_vertices_, 0);
  clearance2_.assign(num_vertices_, 0.0f);
  build_vertex_lists();
  note_built(cloth);
}

// What update() compares the next topology with, and the triangles whose rows were made.
void ClothEnergy::note_built(const Cloth& cloth) {
  built_material_ = cloth.topo.material;
  built_fabric_ = cloth.fabric;
  built_all_triangles_ = tri_v_.size() == cloth.topo.triangles.size();
  if (reuse_rows_ && tensor_)
    rebuilt_.swap(need_rows_);
  else
    rebuilt_.assign(tri_v_.size(), 1);
  if (!tensor_) built_rigid_.clear();
  reuse_rows_ = false;
}

namespace {

// to = from, in parts of 64 Ki items with a pause point before each.
template <class T>
void copy_in_parts(const std::vector<T>& from, std::vector<T>& to) {
  constexpr size_t kPart = size_t{1} << 16;
  to.clear();
  to.reserve(from.size());
  for (size_t b = 0; b < from.size(); b += kPart) {
    pause_point();
    to.insert(to.end(), from.begin() + static_cast<std::ptrdiff_t>(b),
              from.begin() + static_cast<std::ptrdiff_t>(std::min(from.size(), b + kPart)));
  }
}

}  // namespace

ClothEnergy ClothEnergy::spare_copy() const {
  // update()'s eligibility and mark_changed() read these; its build() clears and remakes the rest.
  ClothEnergy c;
  c.opt_ = opt_;
  c.built_version_ = built_version_;
  c.num_vertices_ = num_vertices_;
  c.tensor_ = tensor_;
  c.built_fabric_ = built_fabric_;
  c.built_all_triangles_ = built_all_triangles_;
  copy_in_parts(tri_v_, c.tri_v_);
  copy_in_parts(hinge_t_, c.hinge_t_);
  copy_in_parts(built_material_, c.built_material_);
  copy_in_parts(built_rigid_, c.built_rigid_);
  copy_in_parts(tri_S_off_, c.tri_S_off_);
  copy_in_parts(tri_S_col_, c.tri_S_col_);
  copy_in_parts(tri_S_val_, c.tri_S_val_);
  return c;
}

namespace {

// The options and fabric values the tensor bending rows are made of (update(): equal, or a full
// build).
bool same_bending_cook(const EnergyOptions& a, const EnergyOptions& b) {
  return a.model == b.model && a.bending == b.bending && a.bending_model == b.bending_model &&
         a.bending_twist == b.bending_twist && a.curvature_estimator == b.curvature_estimator &&
         a.curvature_smoothing == b.curvature_smoothing &&
         a.rigid_boundary_hinges == b.rigid_boundary_hinges && a.bending_matrix == b.bending_matrix;
}
// to[b] |= from[a] and to[a] |= from[b] for each pair (a, b) of triangles sharing a hinge.
void spread(const std::vector<std::array<int32_t, 2>>& pairs, const std::vector<char>& from,
            std::vector<char>& to) {
  for (const auto& p : pairs) {
    if (from[p[0]]) to[p[1]] = 1;
    if (from[p[1]]) to[p[0]] = 1;
  }
}

}  // namespace

bool ClothEnergy::update(const Cloth& cloth, const EnergyOptions& opt, ThreadPool* pool) {
  const auto& T = cloth.topo.triangles;
  const int nt = static_cast<int>(T.size());
  const bool eligible = built_version_ != 0 && tensor_ && same_bending_cook(opt_, opt) &&
                        !opt.bending_matrix && opt.model == EnergyOptions::Model::kFem &&
                        opt.bending && opt.bending_model == EnergyOptions::Bending::kTensor &&
                        opt.curvature_estimator == EnergyOptions::Curvature::kBlended &&
                        opt.curvature_smoothing <= 1 &&
                        same_stiffness(built_fabric_, cloth.fabric) && built_all_triangles_ &&
                        nt == num_triangles() && static_cast<int>(built_rigid_.size()) == nt;
  if (!eligible || !mark_changed(cloth, opt)) {
    build(cloth, opt, pool);
    return false;
  }
  old_S_off_.swap(tri_S_off_);
  old_S_col_.swap(tri_S_col_);
  old_S_val_.swap(tri_S_val_);
  reuse_rows_ = true;
  build(cloth, opt, pool);
  return true;
}

// D0 (need_local_ for now): the triangles whose vertices, their material coordinates or their
// rigidity changed since the last build; need_rows_: D0 and its edge neighbours before the
// change (widen_reach() adds those after it). False when D0 is too large to gain (an eighth of
// the triangles) or a triangle is degenerate in material space (build() skips those: the
// triangle indices would not be the energy's).
bool ClothEnergy::mark_changed(const Cloth& cloth, const EnergyOptions& opt) {
  const auto& T = cloth.topo.triangles;
  const auto& M = cloth.topo.material;
  const int nt = static_cast<int>(T.size());
  const int n_old = static_cast<int>(built_material_.size());
  need_local_.assign(nt, 0);
  int changed = 0;
  for (int t = 0; t < nt; ++t) {
    if ((t & 1023) == 0) pause_point();
    const auto& tv = T[t];
    bool c = tv != tri_v_[t];
    for (int k = 0; k < 3 && !c; ++k) c = tv[k] >= n_old || M[tv[k]] != built_material_[tv[k]];
    const bool rigid = opt.rigid_boundary_hinges && !cloth.is_free(tv[0]) &&
                       !cloth.is_free(tv[1]) && !cloth.is_free(tv[2]);
    c = c || rigid != static_cast<bool>(built_rigid_[t]);
    if (c) {
      Eigen::Matrix2d Dm;
      Dm.col(0) = M[tv[1]] - M[tv[0]];
      Dm.col(1) = M[tv[2]] - M[tv[0]];
      if (std::abs(Dm.determinant()) < 1e-16) return false;
    }
    need_local_[t] = c;
    changed += c;
  }
  if (changed > nt / 8) return false;
  need_rows_ = need_local_;
  spread(hinge_t_, need_local_, need_rows_);
  return true;
}

// update(), once the new hinges are known: D1 = need_rows_ plus D0's edge neighbours after the
// change (every triangle whose own hinges or their data changed); the rows made again are A =
// D1 and its neighbours (a row reads its triangle's hinges and its neighbours'); need_local_:
// A and its neighbours (the local estimates those rows read).
void ClothEnergy::widen_reach() {
  spread(hinge_t_, need_local_, need_rows_);
  std::vector<char> d1 = need_rows_;
  spread(hinge_t_, d1, need_rows_);
  need_local_ = need_rows_;
  spread(hinge_t_, need_rows_, need_local_);
}

namespace {

// Minimal CSR matrix and Gustavson products for cooking P (Eigen's general sparse products
// cost ~0.3 s at 128^2; these ~30 ms).
struct Csr {
  std::vector<int> off{0}, col;
  std::vector<double> val;
  void reset(int rows) {
    off.assign(1, 0);
    off.reserve(rows + 1);
    col.clear();
    val.clear();
  }
  void push(int c, double v) {
    col.push_back(c);
    val.push_back(v);
  }
  void end_row() { off.push_back(static_cast<int>(col.size())); }
  int rows() const { return static_cast<int>(off.size()) - 1; }
};

// Rows [0, rows) of a matrix built in parts: part k (one per pool slot, or one without a pool)
// gets rows [lo, hi) and writes them, in order, into its own Csr with fill(lo, hi, part); the
// parts are then joined into C. Each row is computed as without parts: the same result.
template <class Fill>
void by_row_parts(int rows, ThreadPool* pool, Csr& C, Fill&& fill) {
  const int parts = pool && rows >= 4096 ? pool->size() : 1;
  if (parts == 1) {
    C.reset(rows);
    fill(0, rows, C);
    return;
  }
  std::vector<Csr> part(parts);
  pool->parallel_parts(rows, [&](int lo, int hi, int k) {
    part[k].reset(hi - lo);
    fill(lo, hi, part[k]);
  });
  C = std::move(part[0]);
  for (int k = 1; k < parts; ++k) {
    const int base = static_cast<int>(C.col.size());
    for (size_t r = 1; r < part[k].off.size(); ++r) C.off.push_back(base + part[k].off[r]);
    C.col.insert(C.col.end(), part[k].col.begin(), part[k].col.end());
    C.val.insert(C.val.end(), part[k].val.begin(), part[k].val.end());
  }
}

// C = A diag(s) B (s optional, over A's columns = B's rows); B has `ncols` columns. Rows of C
// sorted by column, exact zeros kept (the pattern is what VBD's colouring needs).
void spgemm(const Csr& A, const Csr& B, int ncols, Csr& C, const std::vector<double>* s,
            ThreadPool* pool = nullptr) {
  by_row_parts(A.rows(), pool, C, [&](int lo, int hi, Csr& out) {
    std::vector<double> acc(ncols, 0.0);
    std::vector<int> mark(ncols, -1), touched;
    // Reserve the product's upper bound (sum of the B rows each A entry selects): the output is
    // ~1M entries at 128^2, and growing it by push_back copied it ~20 times.
    size_t bound = 0;
    for (int k = A.off[lo]; k < A.off[hi]; ++k)
      bound += static_cast<size_t>(B.off[A.col[k] + 1] - B.off[A.col[k]]);
    out.col.reserve(bound);
    out.val.reserve(bound);
    for (int i = lo; i < hi; ++i) {
      touched.clear();
      for (int ka = A.off[i]; ka < A.off[i + 1]; ++ka) {
        const int r = A.col[ka];
        const double a = A.val[ka] * (s ? (*s)[r] : 1.0);
        for (int kb = B.off[r]; kb < B.off[r + 1]; ++kb) {
          const int j = B.col[kb];
          if (mark[j] != i) {
            mark[j] = i;
            acc[j] = 0.0;
            touched.push_back(j);
          }
          acc[j] += a * B.val[kb];
        }
      }
      std::sort(touched.begin(), touched.end());
      for (int j : touched) out.push(j, acc[j]);
      out.end_row();
    }
  });
}

// C = A + B (same row count).
void spadd(const Csr& A, const Csr& B, int ncols, Csr& C, ThreadPool* pool = nullptr) {
  by_row_parts(A.rows(), pool, C, [&](int lo, int hi, Csr& out) {
    const size_t bound = static_cast<size_t>(A.off[hi] - A.off[lo] + B.off[hi] - B.off[lo]);
    out.col.reserve(bound);
    out.val.reserve(bound);
    std::vector<double> acc(ncols, 0.0);
    std::vector<int> mark(ncols, -1), touched;
    for (int i = lo; i < hi; ++i) {
      touched.clear();
      for (const Csr* M : {&A, &B})
        for (int k = M->off[i]; k < M->off[i + 1]; ++k) {
          const int j = M->col[k];
          if (mark[j] != i) {
            mark[j] = i;
            acc[j] = 0.0;
            touched.push_back(j);
          }
          acc[j] += M->val[k];
        }
      std::sort(touched.begin(), touched.end());
      for (int j : touched) out.push(j, acc[j]);
      out.end_row();
    }
  });
}

// Gk = (Gl + W Gd) Km, row by row with the arithmetic (its order included) of spgemm(W, Gd) ->
// WG, spadd(Gl, WG) -> Gs, spgemm(Gs, Km) -> Gk: the same values without the two intermediate
// matrices (at 128^2 ~17 MB, whose filling was mostly page faults). Gd, Gl: nh columns; Km: n.
// One row at a time (row()): blend_rows() makes all of them, ClothEnergy::update() those of the
// triangles a topology edit reached, with the same arithmetic.
class RowBlender {
 public:
  RowBlender(const Csr& Gl, const Csr& W, const Csr& Gd, const Csr& Km, int nh, int n)
      : Gl_(Gl),
        W_(W),
        Gd_(Gd),
        Km_(Km),
        a1_(nh, 0.0),
        a2_(nh, 0.0),
        a3_(n, 0.0),
        m1_(nh, -1),
        m2_(nh, -1),
        m3_(n, -1) {}
  void row(int i, Csr& out) {
    t1_.clear();
    t2_.clear();
    t3_.clear();
    for (int ka = W_.off[i]; ka < W_.off[i + 1]; ++ka) {
      const int r = W_.col[ka];
      const double a = W_.val[ka];
      for (int kb = Gd_.off[r]; kb < Gd_.off[r + 1]; ++kb)
        add(a1_, m1_, t1_, i, Gd_.col[kb], a * Gd_.val[kb]);
    }
    std::sort(t1_.begin(), t1_.end());
    for (int k = Gl_.off[i]; k < Gl_.off[i + 1]; ++k) add(a2_, m2_, t2_, i, Gl_.col[k], Gl_.val[k]);
    for (int j : t1_) add(a2_, m2_, t2_, i, j, a1_[j]);
    std::sort(t2_.begin(), t2_.end());
    for (int j : t2_) {
      const double a = a2_[j];
      for (int kb = Km_.off[j]; kb < Km_.off[j + 1]; ++kb)
        add(a3_, m3_, t3_, i, Km_.col[kb], a * Km_.val[kb]);
    }
    std::sort(t3_.begin(), t3_.end());
    for (int j : t3_) out.push(j, a3_[j]);
    out.end_row();
  }

 private:
  static void add(std::vector<double>& acc, std::vector<int>& mark, std::vector<int>& touched,
                  int row, int j, double v) {
    if (mark[j] != row) {
      mark[j] = row;
      acc[j] = 0.0;
      touched.push_back(j);
    }
    acc[j] += v;
  }
  const Csr &Gl_, &W_, &Gd_, &Km_;
  std::vector<double> a1_, a2_, a3_;
  std::vector<int> m1_, m2_, m3_, t1_, t2_, t3_;
};

void blend_rows(const Csr& Gl, const Csr& W, const Csr& Gd, const Csr& Km, int nh, int n, Csr& Gk,
                ThreadPool* pool) {
  by_row_parts(Gl.rows(), pool, Gk, [&](int lo, int hi, Csr& out) {
    RowBlender blend(Gl, W, Gd, Km, nh, n);
    size_t bound = 0;  // (an upper bound of the output, as in spgemm)
    for (int k = Gl.off[lo]; k < Gl.off[hi]; ++k)
      bound += static_cast<size_t>(Km.off[Gl.col[k] + 1] - Km.off[Gl.col[k]]);
    for (int k = W.off[lo]; k < W.off[hi]; ++k)
      bound += 4 * static_cast<size_t>(Gd.off[W.col[k] + 1] - Gd.off[W.col[k]]);
    out.col.reserve(bound);
    out.val.reserve(bound);
    for (int i = lo; i < hi; ++i) blend.row(i, out);
  });
}

// ClothEnergy::update(): the rows of triangle t (3t .. 3t + 2) blended again where need[t], else
// copied from the last build's rows `old` (the same values: nothing they read changed).
void splice_rows(RowBlender&& blend, const std::vector<char>& need, const std::vector<int>& old_off,
                 const std::vector<int>& old_col, const std::vector<double>& old_val, Csr& Gk) {
  const int nt = static_cast<int>(need.size());
  Gk.reset(3 * nt);
  Gk.col.reserve(old_col.size() + 1024);
  Gk.val.reserve(old_val.size() + 1024);
  for (int t = 0; t < nt; ++t) {
    if ((t & 1023) == 0) pause_point();
    if (need[t]) {
      for (int c = 0; c < 3; ++c) blend.row(3 * t + c, Gk);
      continue;
    }
    const int b = old_off[3 * t], e = old_off[3 * t + 3];
    const int base = static_cast<int>(Gk.col.size()) - b;
    Gk.col.insert(Gk.col.end(), old_col.begin() + b, old_col.begin() + e);
    Gk.val.insert(Gk.val.end(), old_val.begin() + b, old_val.begin() + e);
    for (int c = 1; c <= 3; ++c) Gk.off.push_back(base + old_off[3 * t + c]);
  }
}

void transpose(const Csr& A, int ncols, Csr& T) {
  T.off.assign(ncols + 1, 0);
  for (int c : A.col) ++T.off[c + 1];
  for (int j = 0; j < ncols; ++j) T.off[j + 1] += T.off[j];
  T.col.assign(A.col.size(), 0);
  T.val.assign(A.col.size(), 0.0);
  std::vector<int> fill(T.off.begin(), T.off.end() - 1);
  for (int i = 0; i < A.rows(); ++i)
    for (int k = A.off[i]; k < A.off[i + 1]; ++k) {
      const int p = fill[A.col[k]]++;
      T.col[p] = i;
      T.val[p] = A.val[k];
    }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Bending, kTensor (docs/solvers.md): per triangle, the shape operator S = (S_uu,
// S_vv, S_uv) in material coordinates is recovered from the (up to) three hinge angles of its
// edges, theta_e = L_e . S, and E_t = 1/2 A_t S^T D S with D = diag(B_weft, B_warp, 2 B_twist).
// With fewer than three hinges (free boundary) S is the least-energy one compatible with the
// known angles; both cases are E_t = 1/2 theta^T C_t theta, C_t = A_t (L D^-1 L^T)^-1. The
// angles are replaced by the linear hinge vectors s_e = sum_k K_ek x_k (|s_e| ~ theta_e), so
// E = 1/2 sum_t sum_ij C_t,ij s_i . s_j = 1/2 x^T (P (x) I3) x, P = sum_t K_t^T C_t K_t.

// update(): a hinge of a triangle whose local estimate the rows made again read (need_local_);
// every hinge in a full build.
bool ClothEnergy::hinge_needed(int h) const {
  return !reuse_rows_ || need_local_[hinge_t_[h][0]] || need_local_[hinge_t_[h][1]];
}

// L_e = 1/2 sum_k K_ek q(p_k), q(p) = (u^2, v^2, 2uv), p relative to the edge's first vertex:
// theta_e for the height field z = 1/2 p^T S p (K annihilates affine fields, so the origin
// does not matter). Next to a rigid (clamped) triangle the rigid side does not curve: its
// opposite vertex takes the chord value along the edge (foot parameter s: s q(p_1)), so the
// hinge angle is that of the free side alone (theta = S_nn h_free / 2). Per needed hinge: L,
// Nn (the edge's in-plane normal n as n n^T: uu, vv, uv) and len.
void ClothEnergy::hinge_vectors(const std::vector<Vec2>& M, const std::vector<char>& rigid,
                                std::vector<Eigen::Vector3d>& L, std::vector<Eigen::Vector3d>& Nn,
                                std::vector<double>& len) const {
  auto q = [](const Vec2& p) {
    return Eigen::Vector3d(p.x() * p.x(), p.y() * p.y(), 2 * p.x() * p.y());
  };
  for (int h = 0; h < num_hinges(); ++h) {
    if (!hinge_needed(h)) continue;
    const auto& v = hinge_v_[h];
    const auto& K = hinge_k_[h];
    const Vec2 o = M[v[0]];
    const Vec2 e = M[v[1]] - o;
    const bool r1 = rigid[hinge_t_[h][0]], r2 = rigid[hinge_t_[h][1]];
    Eigen::Vector3d acc = K[1] * q(e);
    for (int k = 2; k < 4; ++k) {
      const Vec2 p = M[v[k]] - o;
      const bool chord = (k == 2 ? r1 : r2) && !(r1 && r2);
      acc += K[k] * (chord ? Eigen::Vector3d(p.dot(e) / e.squaredNorm() * q(e)) : q(p));
    }
    L[h] = 0.5 * acc;
    len[h] = e.norm();
    const double nu = -e.y() / len[h], nv = e.x() / len[h];
    Nn[h] = Eigen::Vector3d(nu * nu, nv * nv, nu * nv);  // n n^T as (uu, vv, uv)
  }
}

void ClothEnergy::build_tensor_bending(const Cloth& cloth, ThreadPool* pool) {
  const auto& M = cloth.topo.material;
  const FabricParams& fab = cloth.fabric;
  const double bu = std::max(fab.bending_weft, 0.0), bv = std::max(fab.bending_warp, 0.0);
  const double bt = opt_.bending_twist > 0 ? opt_.bending_twist : std::sqrt(bu * bv);
  const double bmax = std::max({bu, bv, bt});
  const int nt = num_triangles(), nh = num_hinges(), n = num_vertices_;
  tri_nh_.assign(nt, 0);
  bend_D_ = Eigen::Vector3d(bu, bv, 2 * bt);
  if (!(bmax > 0) || nh == 0) return;
  // D^-1 (a zero rigidity is floored at 1e-9 of the largest: that mode is then nearly free).
  const Eigen::Vector3d dinv(1.0 / std::max(bu, 1e-9 * bmax), 1.0 / std::max(bv, 1e-9 * bmax),
                             1.0 / (2.0 * std::max(bt, 1e-9 * bmax)));
  std::vector<char> rigid(nt, 0);
  for (int t = 0; t < nt; ++t) {
    const auto& tv = tri_v_[t];
    rigid[t] = opt_.rigid_boundary_hinges && !cloth.is_free(tv[0]) && !cloth.is_free(tv[1]) &&
               !cloth.is_free(tv[2]);
  }
  built_rigid_ = rigid;
  pause_point();
  // update(): only the hinges of the triangles whose local estimates the rows made again read
  // (need_local_) are needed; the others' L, Nn, len and Km rows are left empty (unread).
  if (reuse_rows_) widen_reach();
  std::vector<Eigen::Vector3d> L(nh), Nn(nh);
  std::vector<double> len(nh);
  hinge_vectors(M, rigid, L, Nn, len);
  pause_point();
  // Hinges and deformable edge-neighbours per triangle.
  std::vector<std::array<int, 3>> th(nt, {-1, -1, -1}), tn(nt, {-1, -1, -1});
  for (int h = 0; h < nh; ++h)
    for (int side = 0; side < 2; ++side) {
      const int t = hinge_t_[h][side], o = hinge_t_[h][1 - side];
      if (rigid[t] || tri_nh_[t] >= 3) continue;
      tn[t][tri_nh_[t]] = rigid[o] ? -1 : o;
      th[t][tri_nh_[t]++] = h;
    }
  // Raw per-triangle estimates S_t = G_t theta (rows 3t..3t+2 over hinge columns).
  // Local: S = D^-1 L^T (L D^-1 L^T)^-1 theta over the triangle's k hinges (= L^-1 theta with
  // three hinges: exact for any constant S; with fewer, the least-energy S compatible with the
  // known angles: a free edge resists no curvature on its own).
  // Divergence form: S_t = 1/A_t sum_e beta_e |e| theta_e n_e n_e^T (the distributional Hessian
  // of the piecewise-linear surface, beta = 1/2; 1 next to a rigid triangle).
  // The local estimators first (a 3x3 eigensolve per triangle: ~10 ms at 128^2), on the pool.
  // (update(): only those the rows made again read; the others are left zero, unread.)
  std::vector<Eigen::Matrix3d> mloc(nt, Eigen::Matrix3d::Zero());
  auto local = [&](int t0, int t1) {
    for (int t = t0; t < t1; ++t) {
      if ((t & 255) == 0) pause_point();
      const int k = tri_nh_[t];
      if (k == 0 || (reuse_rows_ && !need_local_[t])) continue;
      Eigen::Matrix3d G = Eigen::Matrix3d::Zero();
      Eigen::Matrix3d Lt = Eigen::Matrix3d::Zero();
      for (int a = 0; a < k; ++a) Lt.row(a) = L[th[t][a]].transpose();
      for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b) G(a, b) = L[th[t][a]].dot(dinv.cwiseProduct(L[th[t][b]]));
      const double scale = std::max(G.trace() / k, 1e-300);
      for (int a = k; a < 3; ++a) G(a, a) = scale;
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(G);
      const Eigen::Vector3d ev = es.eigenvalues();
      Eigen::Vector3d evi;
      for (int c = 0; c < 3; ++c) evi[c] = ev[c] > 1e-12 * ev.cwiseAbs().maxCoeff() ? 1 / ev[c] : 0;
      const Eigen::Matrix3d Gi =
          es.eigenvectors() * evi.asDiagonal() * es.eigenvectors().transpose();
      mloc[t] = dinv.asDiagonal() * Lt.transpose() * Gi;  // S = Mloc theta
    }
  };
  if (pool && nt >= 4096 && !reuse_rows_) {
    pool->parallel_parts(nt, [&](int b, int e, int) { local(b, e); });
  } else {
    local(0, nt);
  }
  pause_point();
  Csr Gloc, Gdiv;  // rows 3t + c, columns hinges (the same pattern)
  Gloc.reset(3 * nt);
  Gdiv.reset(3 * nt);
  for (Csr* G : {&Gloc, &Gdiv}) {
    G->col.reserve(9 * static_cast<size_t>(nt));
    G->val.reserve(9 * static_cast<size_t>(nt));
  }
  for (int t = 0; t < nt; ++t) {
    if ((t & 1023) == 0) pause_point();
    const int k = tri_nh_[t];
    if (k > 0 && (!reuse_rows_ || need_local_[t])) {
      const Eigen::Matrix3d& Mloc = mloc[t];
      for (int c = 0; c < 3; ++c) {
        for (int a = 0; a < k; ++a) {
          const int h = th[t][a];
          const int other = hinge_t_[h][0] == t ? hinge_t_[h][1] : hinge_t_[h][0];
          const double beta = rigid[other] ? 1.0 : 0.5;
          Gloc.push(h, Mloc(c, a));
          Gdiv.push(h, beta * len[h] / tri_area_[t] * Nn[h][c]);
        }
        Gloc.end_row();
        Gdiv.end_row();
      }
    } else {
      for (int c = 0; c < 3; ++c) Gloc.end_row(), Gdiv.end_row();
    }
  }
  // Km: hinge -> its 4 vertices with weights K (S rows over vertices: Gk = Gs Km).
  pause_point();
  Csr Km;
  Km.reset(nh);
  for (int h = 0; h < nh; ++h) {
    for (int k = 0; k < 4 && hinge_needed(h); ++k) Km.push(hinge_v_[h][k], hinge_k_[h][k]);
    Km.end_row();
  }
  Csr Gs, Gk, GkT, P;
  bool fused = false;  // Gk made from the blend's parts directly (blend_rows)
  const auto est = opt_.curvature_estimator;
  if (est == EnergyOptions::Curvature::kLocal) {
    Gs = Gloc;
  } else if (est == EnergyOptions::Curvature::kDivergence) {
    Gs = Gdiv;
  } else {
    // kBlended: S = (I - W) S_loc + W S_div with the mass-conserving neighbour average
    // (W X)_t = 1/A_t (Wb_tt A_t X_t + sum_{t' ~ t} 1/4 A_t' X_t'), Wb symmetric with unit row
    // sums. sum_t A_t S_t = sum_t A_t S_div,t (the distributional Hessian: no zig-zag mode can
    // bend the cloth for free), and S_t = S exactly for constant curvature wherever W removes
    // the divergence form's element-to-element noise (the criss-cross grid: exact).
    Csr W, Gdl = Gdiv;
    for (size_t k = 0; k < Gdl.val.size(); ++k) Gdl.val[k] -= Gloc.val[k];
    W.reset(3 * nt);
    W.col.reserve(12 * static_cast<size_t>(nt));
    W.val.reserve(12 * static_cast<size_t>(nt));
    for (int t = 0; t < nt; ++t)
      for (int c = 0; c < 3; ++c) {
        if (tri_nh_[t] > 0 && (!reuse_rows_ || need_rows_[t])) {
          int nn = 0;
          for (int a = 0; a < 3; ++a)
            if (tn[t][a] >= 0 && tri_nh_[tn[t][a]] > 0) {
              ++nn;
              W.push(3 * tn[t][a] + c, 0.25 * tri_area_[tn[t][a]] / tri_area_[t]);
            }
          W.push(3 * t + c, 1.0 - 0.25 * nn);
        }
        W.end_row();
      }
    if (reuse_rows_) {
      splice_rows(RowBlender(Gloc, W, Gdl, Km, nh, n), need_rows_, old_S_off_, old_S_col_,
                  old_S_val_, Gk);
      fused = true;
    } else if (opt_.curvature_smoothing <= 1) {
      blend_rows(Gloc, W, Gdl, Km, nh, n, Gk, pool);
      fused = true;
    } else {
      Csr WG;
      spgemm(W, Gdl, nh, WG, nullptr, pool);
      for (int pass = 1; pass < opt_.curvature_smoothing; ++pass) {
        Csr next;
        spgemm(W, WG, nh, next, nullptr, pool);
        WG = std::move(next);
      }
      spadd(Gloc, WG, nh, Gs, pool);
    }
  }
  // S rows over vertices Gk = Gs Km, and P = Gk^T (A D) Gk.
  if (!fused) spgemm(Gs, Km, n, Gk, nullptr, pool);
  tensor_ = true;
  if (!opt_.bending_matrix) {
    tri_S_off_ = std::move(Gk.off);
    tri_S_col_ = std::move(Gk.col);
    tri_S_val_ = std::move(Gk.val);
    return;
  }
  transpose(Gk, n, GkT);
  pause_point();
  std::vector<double> ad(3 * nt);
  for (int t = 0; t < nt; ++t)
    for (int c = 0; c < 3; ++c) ad[3 * t + c] = tri_area_[t] * bend_D_[c];
  spgemm(GkT, Gk, n, P, &ad, pool);
  pause_point();
  // CSR with the diagonal always present.
  bend_off_.assign(n + 1, 0);
  bend_diag_.assign(n, 0.0);
  bend_col_.clear();
  bend_val_.clear();
  for (int i = 0; i < n; ++i) {
    bool diag = false;
    for (int k = P.off[i]; k < P.off[i + 1]; ++k) {
      if (!diag && P.col[k] > i) {
        bend_col_.push_back(i);
        bend_val_.push_back(0.0);
        diag = true;
      }
      bend_col_.push_back(P.col[k]);
      bend_val_.push_back(P.val[k]);
      if (P.col[k] == i) {
        bend_diag_[i] = P.val[k];
        diag = true;
      }
    }
    if (!diag) {
      bend_col_.push_back(i);
      bend_val_.push_back(0.0);
    }
    bend_off_[i + 1] = static_cast<int>(bend_col_.size());
  }
  tri_S_off_ = std::move(Gk.off);
  tri_S_col_ = std::move(Gk.col);
  tri_S_val_ = std::move(Gk.val);
}

double ClothEnergy::bending_triangle_energy(int t, const std::vector<Vec3>& x) const {
  if (tri_S_off_.empty()) return 0.0;
  double e = 0;
  for (int c = 0; c < 3; ++c) {
    Vec3 s = Vec3::Zero();
    for (int k = tri_S_off_[3 * t + c]; k < tri_S_off_[3 * t + c + 1]; ++k)
      s += tri_S_val_[k] * x[tri_S_col_[k]];
    e += bend_D_[c] * s.squaredNorm();
  }
  return 0.5 * tri_area_[t] * e;
}

double ClothEnergy::bending_energy(const std::vector<Vec3>& x) const {
  double e = 0;
  if (tensor_ && !has_bending_matrix()) {
    for (int t = 0; t < num_triangles(); ++t) e += bending_triangle_energy(t, x);
    return e;
  }
  if (tensor_bending()) {
    for (int i = 0; i < num_vertices_; ++i) {
      Vec3 g = Vec3::Zero();
      for (int k = bend_off_[i]; k < bend_off_[i + 1]; ++k) g += bend_val_[k] * x[bend_col_[k]];
      e += x[i].dot(g);
    }
    return 0.5 * e;
  }
  for (int h = 0; h < num_hinges(); ++h) e += hinge_energy(h, x);
  return e;
}

void ClothEnergy::add_bending_gradient(const std::vector<Vec3>& x, std::vector<Vec3>& grad) const {
  if (tensor_ && !has_bending_matrix()) {
    // Row by row: grad += A_t D_c V_r^T (V_r x), the same sum P x is assembled from.
    for (int r = 0; r < num_bending_rows(); ++r) {
      Vec3 s = Vec3::Zero();
      for (int k = tri_S_off_[r]; k < tri_S_off_[r + 1]; ++k) s += tri_S_val_[k] * x[tri_S_col_[k]];
      s *= tri_area_[r / 3] * bend_D_[r % 3];
      for (int k = tri_S_off_[r]; k < tri_S_off_[r + 1]; ++k)
        grad[tri_S_col_[k]] += tri_S_val_[k] * s;
    }
    return;
  }
  if (tensor_bending()) {
    for (int i = 0; i < num_vertices_; ++i) {
      Vec3 g = Vec3::Zero();
      for (int k = bend_off_[i]; k < bend_off_[i + 1]; ++k) g += bend_val_[k] * x[bend_col_[k]];
      grad[i] += g;
    }
    return;
  }
  Vec3 g[4];
  for (int h = 0; h < num_hinges(); ++h) {
    hinge_gradient(h, x, g);
    for (int k = 0; k < 4; ++k) grad[hinge_v_[h][k]] += g[k];
  }
}

void ClothEnergy::add_spring(int a, int b, double k, double rest) {
  spring_v_.push_back({a, b});
  spring_rest_.push_back(rest);
  spring_k_.push_back(k);
  build_vertex_lists();
}

void ClothEnergy::build_vertex_lists() {
  // Only vertex_force_hessian() reads them, which an energy of tensor bending without P refuses
  // (XPBD's): none are made for it (~5 M instructions of a cut's re-cook at 128^2).
  if (tensor_ && bend_col_.empty()) {
    for (auto* v : {&vt_off_, &vt_, &vh_off_, &vh_, &vs_off_, &vs_}) v->clear();
    return;
  }
  const int n = num_vertices_;
  auto csr = [n](std::vector<int>& off, std::vector<int>& items, int count, int arity,
                 auto&& vert) {
    off.assign(n + 1, 0);
    for (int e = 0; e < count; ++e)
      for (int s = 0; s < arity; ++s) ++off[vert(e, s) + 1];
    for (int i = 0; i < n; ++i) off[i + 1] += off[i];
    items.assign(off[n], 0);
    std::vector<int> fill(off.begin(), off.end() - 1);
    for (int e = 0; e < count; ++e)
      for (int s = 0; s < arity; ++s) items[fill[vert(e, s)]++] = e * arity + s;
  };
  csr(vt_off_, vt_, num_triangles(), 3, [&](int e, int s) { return tri_v_[e][s]; });
  csr(vh_off_, vh_, num_hinges(), 4, [&](int e, int s) { return hinge_v_[e][s]; });
  csr(vs_off_, vs_, num_springs(), 2, [&](int e, int s) { return spring_v_[e][s]; });
}

// ---------------------------------------------------------------------------------------------
// Membrane: psi = 1/2 ku E_uu^2 + 1/2 kv E_vv^2 + 2 G E_uv^2 per unit rest area (Green strain).

void ClothEnergy::stress(int t, const std::vector<Vec3>& x, Mat32& F, Eigen::Matrix2d& S) const {
  const auto& v = tri_v_[t];
  const auto& D = tri_D_[t];
  F = x[v[0]] * D.row(0) + x[v[1]] * D.row(1) + x[v[2]] * D.row(2);
  const Eigen::Matrix2d E = 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
  S(0, 0) = ku_ * E(0, 0);
  S(1, 1) = kv_ * E(1, 1);
  S(0, 1) = S(1, 0) = 2.0 * kshear_ * E(0, 1);
}

double ClothEnergy::tri_energy(int t, const std::vector<Vec3>& x) const {
  const auto& v = tri_v_[t];
  const auto& D = tri_D_[t];
  const Mat32 F = x[v[0]] * D.row(0) + x[v[1]] * D.row(1) + x[v[2]] * D.row(2);
  const Eigen::Matrix2d E = 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
  return tri_area_[t] * (0.5 * ku_ * E(0, 0) * E(0, 0) + 0.5 * kv_ * E(1, 1) * E(1, 1) +
                         2.0 * kshear_ * E(0, 1) * E(0, 1));
}

void ClothEnergy::tri_gradient(int t, const std::vector<Vec3>& x, Vec3 g[3]) const {
  Mat32 F;
  Eigen::Matrix2d S;
  stress(t, x, F, S);
  const Mat32 P = tri_area_[t] * F * S;
  for (int k = 0; k < 3; ++k) g[k] = P * tri_D_[t].row(k).transpose();
}

void ClothEnergy::tri_hessian(int t, const std::vector<Vec3>& x, Mat9& H, bool project) const {
  Mat32 F;
  Eigen::Matrix2d S;
  stress(t, x, F, S);
  const Eigen::Matrix2d Sp = project ? clamp_psd(S) : S;
  const auto& D = tri_D_[t];
  const double A = tri_area_[t];
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) {
      Mat32 dF = Mat32::Zero();
      dF.row(c) = D.row(k);
      const Eigen::Matrix2d dE = 0.5 * (dF.transpose() * F + F.transpose() * dF);
      Eigen::Matrix2d dS;
      dS(0, 0) = ku_ * dE(0, 0);
      dS(1, 1) = kv_ * dE(1, 1);
      dS(0, 1) = dS(1, 0) = 2.0 * kshear_ * dE(0, 1);
      const Mat32 dP = A * (dF * Sp + F * dS);
      for (int l = 0; l < 3; ++l) H.block<3, 1>(3 * l, 3 * k + c) = dP * D.row(l).transpose();
    }
}

namespace {

// The VBD membrane block of vertex slot a of a triangle, in scalars (the hot path): adds the
// gradient to g and the PSD 3x3 block to h (row-major, symmetric). fu, fv = columns of F.
inline void membrane_block(const Vec3& x0, const Vec3& x1, const Vec3& x2,
                           const Eigen::Matrix<double, 3, 2>& D, int a, double A, double ku,
                           double kv, double kshear, Vec3& g, double h[9]) {
  const Vec3 fu = x0 * D(0, 0) + x1 * D(1, 0) + x2 * D(2, 0);
  const Vec3 fv = x0 * D(0, 1) + x1 * D(1, 1) + x2 * D(2, 1);
  const double suu = ku * 0.5 * (fu.squaredNorm() - 1.0);
  const double svv = kv * 0.5 * (fv.squaredNorm() - 1.0);
  const double suv = kshear * fu.dot(fv);  // 2 G E_uv
  const double du = D(a, 0), dv = D(a, 1);
  g += A * ((suu * du + suv * dv) * fu + (suv * du + svv * dv) * fv);
  // Positive part of S (closed form, see clamp_psd).
  double puu = suu, pvv = svv, puv = suv;
  const double m = 0.5 * (suu + svv), dd = 0.5 * (suu - svv);
  const double r = std::sqrt(dd * dd + suv * suv);
  const double l1 = m + r, l2 = m - r;
  if (l2 < 0) {
    if (l1 <= 0) {
      puu = pvv = puv = 0;
    } else {
      const double c = l1 / (l1 - l2);
      puu = c * (suu - l2);
      pvv = c * (svv - l2);
      puv = c * suv;
    }
  }
  const double dSd = du * du * puu + 2 * du * dv * puv + dv * dv * pvv;
  const Vec3 au = du * fu, av = dv * fv, as = 0.5 * (du * fv + dv * fu);
  const double cu = A * ku, cv = A * kv, cs = 4.0 * A * kshear;
  for (int r0 = 0; r0 < 3; ++r0)
    for (int c0 = r0; c0 < 3; ++c0) {
      const double v = cu * au[r0] * au[c0] + cv * av[r0] * av[c0] + cs * as[r0] * as[c0];
      h[3 * r0 + c0] += v;
    }
  h[0] += A * dSd;
  h[4] += A * dSd;
  h[8] += A * dSd;
}

}  // namespace

void ClothEnergy::tri_vertex_block(int t, int a, const std::vector<Vec3>& x, Vec3& g,
                                   Mat3& H) const {
  // H = A [ (d.S+ d) I + ku au au^T + kv av av^T + 4 G as as^T ], d = D.row(a), S+ = positive
  // part of the second Piola stress, au = d_u f_u, av = d_v f_v, as = (d_u f_v + d_v f_u)/2.
  const auto& v = tri_v_[t];
  g.setZero();
  double h[9] = {};
  membrane_block(x[v[0]], x[v[1]], x[v[2]], tri_D_[t], a, tri_area_[t], ku_, kv_, kshear_, g, h);
  H << h[0], h[1], h[2], h[1], h[4], h[5], h[2], h[5], h[8];
}

// ---------------------------------------------------------------------------------------------
// Bending hinges. kDihedral: E = 1/2 w theta^2; kLinear: E = 1/2 w |sum K_k x_k|^2.
//
// Dihedral angle: e = x1 - x0, N_A = e x (x2 - x0), N_B = (x3 - x0) x e (equal directions when
// flat), theta = atan2((n_B x n_A) . e/|e|, n_A . n_B). Its gradient (Bridson et al. 2003 form)
// with the heights h = |N|/|e| and foot parameters s = (x_opp - x0).e/|e|^2 of the opposite
// vertices: dtheta/dx2 = n_A/h_A = N_A |e|/|N_A|^2 (G_A), dtheta/dx3 = G_B,
// dtheta/dx0 = -(1-s_A) G_A - (1-s_B) G_B, dtheta/dx1 = -s_A G_A - s_B G_B.

namespace {

struct HingeGeo {
  Vec3 e, a, b, NA, NB, GA, GB;
  double L = 0, nA2 = 0, nB2 = 0, sA = 0, sB = 0;
};

bool hinge_geo(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3, HingeGeo& g) {
  g.e = x1 - x0;
  g.a = x2 - x0;
  g.b = x3 - x0;
  g.L = g.e.norm();
  g.NA = g.e.cross(g.a);
  g.NB = g.b.cross(g.e);
  g.nA2 = g.NA.squaredNorm();
  g.nB2 = g.NB.squaredNorm();
  const double L2 = g.L * g.L;
  if (!(g.L > 1e-14) || !(g.nA2 > 1e-12 * L2 * L2) || !(g.nB2 > 1e-12 * L2 * L2)) return false;
  g.GA = g.NA * (g.L / g.nA2);
  g.GB = g.NB * (g.L / g.nB2);
  g.sA = g.a.dot(g.e) / L2;
  g.sB = g.b.dot(g.e) / L2;
  return true;
}

double hinge_theta(const HingeGeo& g) {
  const Vec3 nA = g.NA / std::sqrt(g.nA2), nB = g.NB / std::sqrt(g.nB2);
  return std::atan2(nB.cross(nA).dot(g.e) / g.L, nA.dot(nB));
}

}  // namespace

bool ClothEnergy::hinge_angle(int h, const std::vector<Vec3>& x, double& theta,
                              Vec3 dtheta[4]) const {
  const auto& v = hinge_v_[h];
  HingeGeo g;
  if (!hinge_geo(x[v[0]], x[v[1]], x[v[2]], x[v[3]], g)) {
    theta = 0;
    for (int k = 0; k < 4; ++k) dtheta[k].setZero();
    return false;
  }
  theta = hinge_theta(g);
  dtheta[0] = -(1 - g.sA) * g.GA - (1 - g.sB) * g.GB;
  dtheta[1] = -g.sA * g.GA - g.sB * g.GB;
  dtheta[2] = g.GA;
  dtheta[3] = g.GB;
  return true;
}

double ClothEnergy::hinge_energy(int h, const std::vector<Vec3>& x) const {
  const auto& v = hinge_v_[h];
  if (opt_.bending_model != EnergyOptions::Bending::kDihedral) {
    const auto& K = hinge_k_[h];
    const Vec3 s = K[0] * x[v[0]] + K[1] * x[v[1]] + K[2] * x[v[2]] + K[3] * x[v[3]];
    return 0.5 * hinge_w_[h] * s.squaredNorm();
  }
  HingeGeo g;
  if (!hinge_geo(x[v[0]], x[v[1]], x[v[2]], x[v[3]], g)) return 0.0;
  const double th = hinge_theta(g);
  return 0.5 * hinge_w_[h] * th * th;
}

void ClothEnergy::hinge_gradient(int h, const std::vector<Vec3>& x, Vec3 g[4]) const {
  const auto& v = hinge_v_[h];
  if (opt_.bending_model != EnergyOptions::Bending::kDihedral) {
    const auto& K = hinge_k_[h];
    const Vec3 s = K[0] * x[v[0]] + K[1] * x[v[1]] + K[2] * x[v[2]] + K[3] * x[v[3]];
    for (int k = 0; k < 4; ++k) g[k] = hinge_w_[h] * K[k] * s;
    return;
  }
  double th;
  hinge_angle(h, x, th, g);
  for (int k = 0; k < 4; ++k) g[k] *= hinge_w_[h] * th;
}

void ClothEnergy::hinge_hessian(int h, Mat12& H) const {
  const auto& K = hinge_k_[h];
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      H.block<3, 3>(3 * a, 3 * b) = hinge_w_[h] * K[a] * K[b] * Mat3::Identity();
}

void ClothEnergy::hinge_hessian(int h, const std::vector<Vec3>& x, Mat12& H, bool project) const {
  if (opt_.bending_model != EnergyOptions::Bending::kDihedral) {
    hinge_hessian(h, H);
    return;
  }
  const auto& v = hinge_v_[h];
  HingeGeo g;
  if (!hinge_geo(x[v[0]], x[v[1]], x[v[2]], x[v[3]], g)) {
    H.setZero();
    return;
  }
  const double th = hinge_theta(g);
  Eigen::Matrix<double, 12, 1> d;
  // Flat hinge: the curvature term vanishes and w d d^T is PSD as it is. No eigensolve then:
  // its round-off would couple the out-of-plane direction to the in-plane ones and seed
  // buckling of a planar equilibrium (the hanging sheet) that is exact otherwise.
  d.segment<3>(0) = -(1 - g.sA) * g.GA - (1 - g.sB) * g.GB;
  d.segment<3>(3) = -g.sA * g.GA - g.sB * g.GB;
  d.segment<3>(6) = g.GA;
  d.segment<3>(9) = g.GB;
  if (th == 0.0) {
    H = hinge_w_[h] * d * d.transpose();
    return;
  }
  // Second derivative of theta, one column per coordinate: directional derivatives of the
  // gradient formula (product rule through N_A, N_B, |e|, s_A, s_B).
  const double L = g.L, L2 = L * L;
  const Vec3 eh = g.e / L;
  Mat12 D2;
  for (int j = 0; j < 4; ++j)
    for (int c = 0; c < 3; ++c) {
      const Vec3 u = Vec3::Unit(c);
      const Vec3 de = j == 1 ? u : (j == 0 ? Vec3(-u) : Vec3::Zero());
      const Vec3 da = j == 2 ? u : (j == 0 ? Vec3(-u) : Vec3::Zero());
      const Vec3 db = j == 3 ? u : (j == 0 ? Vec3(-u) : Vec3::Zero());
      const Vec3 dNA = de.cross(g.a) + g.e.cross(da);
      const Vec3 dNB = db.cross(g.e) + g.b.cross(de);
      const double dL = eh.dot(de);
      const Vec3 dGA =
          (dNA * L + g.NA * dL) / g.nA2 - 2 * g.NA * L * g.NA.dot(dNA) / (g.nA2 * g.nA2);
      const Vec3 dGB =
          (dNB * L + g.NB * dL) / g.nB2 - 2 * g.NB * L * g.NB.dot(dNB) / (g.nB2 * g.nB2);
      const double dsA = (da.dot(g.e) + g.a.dot(de)) / L2 - 2 * g.a.dot(g.e) * dL / (L2 * L);
      const double dsB = (db.dot(g.e) + g.b.dot(de)) / L2 - 2 * g.b.dot(g.e) * dL / (L2 * L);
      const int col = 3 * j + c;
      D2.block<3, 1>(0, col) = dsA * g.GA - (1 - g.sA) * dGA + dsB * g.GB - (1 - g.sB) * dGB;
      D2.block<3, 1>(3, col) = -dsA * g.GA - g.sA * dGA - dsB * g.GB - g.sB * dGB;
      D2.block<3, 1>(6, col) = dGA;
      D2.block<3, 1>(9, col) = dGB;
    }
  H = hinge_w_[h] * (d * d.transpose() + th * 0.5 * (D2 + D2.transpose()));
  if (project) {
    Eigen::SelfAdjointEigenSolver<Mat12> es(H);
    const Eigen::Matrix<double, 12, 1> ev = es.eigenvalues().cwiseMax(0.0);
    H = es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose();
  }
}

void ClothEnergy::hinge_vertex_block(int h, int a, const std::vector<Vec3>& x, Vec3& g,
                                     Mat3& H) const {
  const auto& v = hinge_v_[h];
  const double w = hinge_w_[h];
  if (opt_.bending_model != EnergyOptions::Bending::kDihedral) {
    const auto& K = hinge_k_[h];
    const Vec3 s = K[0] * x[v[0]] + K[1] * x[v[1]] + K[2] * x[v[2]] + K[3] * x[v[3]];
    g = w * K[a] * s;
    H = w * K[a] * K[a] * Mat3::Identity();
    return;
  }
  double th;
  Vec3 d[4];
  hinge_angle(h, x, th, d);
  g = w * th * d[a];
  H = w * d[a] * d[a].transpose();
}

// ---------------------------------------------------------------------------------------------
// Springs: E = 1/2 k (|xa - xb| - L)^2.

double ClothEnergy::spring_energy(int s, const std::vector<Vec3>& x) const {
  const double l = (x[spring_v_[s][0]] - x[spring_v_[s][1]]).norm() - spring_rest_[s];
  return 0.5 * spring_k_[s] * l * l;
}

void ClothEnergy::spring_gradient(int s, const std::vector<Vec3>& x, Vec3 g[2]) const {
  const Vec3 d = x[spring_v_[s][0]] - x[spring_v_[s][1]];
  const double l = d.norm();
  const Vec3 f = l > 1e-15 ? Vec3(spring_k_[s] * (l - spring_rest_[s]) * d / l) : Vec3::Zero();
  g[0] = f;
  g[1] = -f;
}

void ClothEnergy::spring_hessian(int s, const std::vector<Vec3>& x, Eigen::Matrix<double, 6, 6>& H,
                                 bool project) const {
  const Vec3 d = x[spring_v_[s][0]] - x[spring_v_[s][1]];
  const double l = std::max(d.norm(), 1e-15);
  const Vec3 n = d / l;
  double c = 1.0 - spring_rest_[s] / l;
  if (project) c = std::max(c, 0.0);
  const Mat3 B = spring_k_[s] * (n * n.transpose() + c * (Mat3::Identity() - n * n.transpose()));
  H.block<3, 3>(0, 0) = B;
  H.block<3, 3>(3, 3) = B;
  H.block<3, 3>(0, 3) = -B;
  H.block<3, 3>(3, 0) = -B;
}

// ---------------------------------------------------------------------------------------------
// External forces and contact.

Vec3 ClothEnergy::external_force(int i, const Vec3& xi, double mass) const {
  Vec3 f = opt_.gravity ? Vec3(mass * opt_.g) : Vec3::Zero();
  if (opt_.pressure > 0 && scene_ && scene_->form) {
    const DressForm& form = *scene_->form;
    if (xi.y() >= form.min_y() && xi.y() <= form.max_y()) {
      const Vec2 c = form.centre_at(xi.y());
      Vec3 r(xi.x() - c.x(), 0, xi.z() - c.y());
      const double rn = r.norm();
      if (rn > 1e-9) f -= opt_.pressure * vertex_area_[i] * r / rn;
    }
  }
  return f;
}

void ClothEnergy::clear_contacts() {
  for (const auto& c : contacts_) contact_index_[c.vertex] = -1;
  contacts_.clear();
}

double ClothEnergy::test_vertex(const Cloth& cloth, const SceneObjects& scene, int i, bool floor,
                                bool form_on, double culled_clear) {
  const auto& x = cloth.state.x;
  const double off = scene.offset;
  const double reach = off + opt_.contact_margin;
  double deepest = 0;
  auto consider = [&](double dist, const Vec3& nrm, const Vec3& surf) {
    if (dist >= reach) return;
    const double pen = off - dist;
    deepest = std::max(deepest, pen);
    const Vec3 p = surf + off * nrm;
    Contact& c = candidate_[i];
    if (c.vertex < 0 || nrm.dot(x[i] - p) < c.n.dot(x[i] - c.p)) c = {i, nrm, p};
    has_candidate_[i] = 1;
  };
  candidate_[i].vertex = -1;
  has_candidate_[i] = 0;
  clearance2_[i] = 0;
  const uint8_t fl = cloth.state.flags[i];
  if (fl & (kFlagKinematic | kFlagNoCollide | kFlagPinned | kFlagPinched)) return 0;
  const Vec3& p = x[i];
  // The clearance: per object a lower bound on the distance from p to where the object's test
  // below would find a contact (each a distance to a set, or a bound with its gradient).
  double clear = culled_clear;
  if (floor) {
    consider(p.y(), Vec3(0, 1, 0), Vec3(p.x(), 0, p.z()));
    clear = std::min(clear, p.y() - reach);
  }
  for (const auto& s : scene.spheres) {
    const Vec3 d = p - s.centre;
    const double dn = d.norm();
    clear = std::min(clear, dn - s.radius - reach);
    if (dn - s.radius >= reach || dn < 1e-12) continue;
    const Vec3 nrm = d / dn;
    consider(dn - s.radius, nrm, s.centre + s.radius * nrm);
  }
  for (const auto& dsc : scene.discs) {
    Vec3 nrm;
    const double sd = disc_distance(p, dsc, &nrm);  // |gradient| = 1: a distance
    clear = std::min(clear, sd - reach);
    if (sd < reach) consider(sd, nrm, p - sd * nrm);
  }
  for (const auto& h : scene.hands) {
    if (!h.tracked || !h.collides) continue;
    const Vec3 ab = h.tip - h.position;
    const double L2 = ab.squaredNorm();
    const double t = L2 > 0 ? std::clamp((p - h.position).dot(ab) / L2, 0.0, 1.0) : 0.0;
    const Vec3 c = h.position + t * ab;
    const Vec3 d = p - c;
    const double dn = d.norm();
    clear = std::min(clear, dn - h.radius - reach);
    if (dn - h.radius >= reach || dn < 1e-12) continue;
    consider(dn - h.radius, d / dn, c + h.radius * d / dn);
  }
  for (const auto& pl : scene.plates) {
    const Vec3 d = p - pl.centre;
    // (A contact needs |dx| <= half_x, |dz| <= half_z, -thickness <= dy < reach.)
    clear = std::min(clear, std::max({std::abs(d.x()) - pl.half_x, std::abs(d.z()) - pl.half_z,
                                      d.y() - reach, -pl.thickness - d.y()}));
    if (std::abs(d.x()) > pl.half_x || std::abs(d.z()) > pl.half_z) continue;
    if (d.y() < -pl.thickness) continue;  // below the plate: untouched
    consider(d.y(), Vec3(0, 1, 0), Vec3(p.x(), pl.centre.y(), p.z()));
  }
  for (const auto& b : scene.boxes) {
    const Vec3 d = p - b.centre;
    const Vec3 q = d.cwiseAbs() - b.half;
    clear = std::min(clear, q.maxCoeff() - reach);
    if (q.maxCoeff() >= reach) continue;
    if ((q.array() > 0).count() > 1) continue;  // near an edge/corner outside: skip
    int ax = 0;
    q.maxCoeff(&ax);
    Vec3 nrm = Vec3::Zero();
    nrm[ax] = d[ax] >= 0 ? 1 : -1;
    Vec3 surf = p;
    surf[ax] = b.centre[ax] + nrm[ax] * b.half[ax];
    consider(q[ax], nrm, surf);
  }
  if (form_on) {
    const DressForm& form = *scene.form;
    Vec3 nrm;  // (+inf outside the form's height range)
    const double sd = form.normal_distance_within(p, reach, &nrm);
    if (sd < reach) consider(sd, nrm, p - sd * nrm);
    // Outside the height range: at least the way into it; inside: DressForm::max_gradient().
    if (sd == std::numeric_limits<double>::infinity())
      clear = std::min(clear, std::max(form.min_y() - p.y(), p.y() - form.max_y()));
    else
      clear = std::min(clear, sd / form.max_gradient() - reach);
  }
  // Stored squared as a float, rounded down (a retest earlier than needed is harmless).
  if (has_candidate_[i] == 0 && clear > 0)
    clearance2_[i] = static_cast<float>(clear * clear * (1 - 1e-6));
  return deepest;
}

double ClothEnergy::retest_contact(const Cloth& cloth, const SceneObjects& scene, int i) {
  return test_vertex(cloth, scene, i, scene.floor, scene.form != nullptr,
                     std::numeric_limits<double>::infinity());
}

void ClothEnergy::list_contacts(int n, ThreadPool* pool) {
  clear_contacts();
  if (pool && pool->size() > 1) {
    // Each block's contacts start after those of the blocks before it.
    constexpr int kContactBlock = 256;
    const int nb = (n + kContactBlock - 1) / kContactBlock;
    block_contacts_.assign(nb + 1, 0);
    pool->parallel_for(nb, [&](int b, int e, int) {
      for (int k = b; k < e; ++k) {
        int c = 0;
        for (int i = k * kContactBlock; i < std::min(n, (k + 1) * kContactBlock); ++i)
          c += has_candidate_[i];
        block_contacts_[k + 1] = c;
      }
    });
    for (int k = 0; k < nb; ++k) block_contacts_[k + 1] += block_contacts_[k];
    contacts_.resize(block_contacts_[nb]);
    pool->parallel_for(nb, [&](int b, int e, int) {
      for (int k = b; k < e; ++k) {
        int c = block_contacts_[k];
        for (int i = k * kContactBlock; i < std::min(n, (k + 1) * kContactBlock); ++i)
          if (has_candidate_[i]) {
            contact_index_[i] = c;
            contacts_[c++] = candidate_[i];
          }
      }
    });
    return;
  }
  for (int i = 0; i < n; ++i)
    if (has_candidate_[i]) {
      contact_index_[i] = static_cast<int>(contacts_.size());
      contacts_.push_back(candidate_[i]);
    }
}

double ClothEnergy::detect_contacts(const Cloth& cloth, const SceneObjects& scene,
                                    ThreadPool* pool) {
  const auto& x = cloth.state.x;
  const int n = cloth.num_vertices();
  const double reach = scene.offset + opt_.contact_margin;
  // Cloth bounds: objects whose bounds do not touch them are skipped entirely.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::max()), hi = -lo;
  const bool par = pool && pool->size() > 1;
  if (par) {
    bounds_part_.assign(2 * pool->size(), lo);
    for (int w = 0; w < pool->size(); ++w) bounds_part_[2 * w + 1] = hi;
    pool->parallel_for(n, [&](int b, int e, int w) {
      Vec3 l = bounds_part_[2 * w], h = bounds_part_[2 * w + 1];
      for (int i = b; i < e; ++i) {
        l = l.cwiseMin(x[i]);
        h = h.cwiseMax(x[i]);
      }
      bounds_part_[2 * w] = l;
      bounds_part_[2 * w + 1] = h;
    });
    for (int w = 0; w < pool->size(); ++w) {
      lo = lo.cwiseMin(bounds_part_[2 * w]);
      hi = hi.cwiseMax(bounds_part_[2 * w + 1]);
    }
  } else {
    for (int i = 0; i < n; ++i) {
      lo = lo.cwiseMin(x[i]);
      hi = hi.cwiseMax(x[i]);
    }
  }
  lo.array() -= reach;
  hi.array() += reach;
  // An object culled is at least the gap between its bounds and the cloth's (grown by reach)
  // from where a test would find a contact: every vertex's clearance is at most that.
  double culled_clear = std::numeric_limits<double>::infinity();
  auto touches = [&](const Vec3& olo, const Vec3& ohi) {
    if (!opt_.cull_by_bounds) return true;
    const bool t = (olo.array() <= hi.array()).all() && (ohi.array() >= lo.array()).all();
    if (!t) {
      ++culled_;
      culled_clear = std::min(culled_clear, std::max((olo - hi).maxCoeff(), (lo - ohi).maxCoeff()));
    }
    return t;
  };
  culled_ = 0;
  // Per vertex, the deepest candidate (into candidate_[i]; vertex -1: none).
  candidate_.resize(n);
  has_candidate_.resize(n);
  clearance2_.resize(n);
  const bool floor = scene.floor && touches(Vec3(-1e9, -1, -1e9), Vec3(1e9, 0, 1e9));
  bool form_on = false;
  if (scene.form) {
    const DressForm& f = *scene.form;
    form_on = touches(Vec3(-1, f.min_y(), -1), Vec3(1, f.max_y(), 1));
  }
  double deepest = 0;
  if (par) {
    deepest_part_.assign(pool->size(), 0.0);
    pool->parallel_for(n, [&](int b, int e, int w) {
      double d = deepest_part_[w];
      for (int i = b; i < e; ++i)
        d = std::max(d, test_vertex(cloth, scene, i, floor, form_on, culled_clear));
      deepest_part_[w] = d;
    });
    for (double d : deepest_part_) deepest = std::max(deepest, d);
  } else {
    for (int i = 0; i < n; ++i)
      deepest = std::max(deepest, test_vertex(cloth, scene, i, floor, form_on, culled_clear));
  }
  list_contacts(n, pool);
  return deepest;
}

namespace {
void project_contact(const Contact& c, Vec3& xi, const std::vector<Vec3>* start, double mu) {
  const double d = c.n.dot(xi - c.p);
  if (d >= 0) return;
  xi -= d * c.n;
  if (start && mu > 0) coulomb_position_friction(xi, (*start)[c.vertex], c.n, -d, mu);
}
}  // namespace

void ClothEnergy::project_contacts(std::vector<Vec3>& x, const std::vector<Vec3>* start,
                                   double mu) const {
  for (const auto& c : contacts_) project_contact(c, x[c.vertex], start, mu);
}

void ClothEnergy::project_tested_contacts(std::vector<Vec3>& x, const std::vector<Vec3>* start,
                                          double mu, int b, int e) const {
  for (int i = b; i < e; ++i)
    if (has_candidate_[i]) project_contact(candidate_[i], x[i], start, mu);
}

void ClothEnergy::set_friction(double mu, double eps, const std::vector<Vec3>& anchor) {
  friction_mu_ = mu;
  friction_eps_ = eps;
  friction_anchor_ = anchor;
  friction_load_.assign(num_vertices_, 0.0);
}

void ClothEnergy::lag_friction_load(const std::vector<Vec3>& x, const std::vector<double>& mass) {
  const double mu = friction_mu_, k = k_contact_;
  friction_mu_ = 0;  // the load is -dE/dx without the friction and the contact terms
  std::vector<Vec3>& g = friction_grad_;
  gradient(x, mass, g);
  friction_mu_ = mu;
  friction_load_.assign(num_vertices_, 0.0);
  for (const auto& c : contacts_) {
    // Touching only: on the plane or within 0.2 mm of it (a position-based solver leaves its
    // contacts on the plane it last projected to, which on a curved form sits up to ~0.1 mm
    // off the plane found now); a vertex hovering further out within the detection margin
    // carries no load, whatever pulls it toward the surface.
    const double d = c.n.dot(x[c.vertex] - c.p);
    if (d > 2e-4) continue;
    const Vec3 gi = d < 0 ? Vec3(g[c.vertex] - k * d * c.n) : g[c.vertex];
    friction_load_[c.vertex] = std::max(0.0, c.n.dot(gi));
  }
}

void ClothEnergy::lag_friction_penalty(const std::vector<Vec3>& x) {
  friction_load_.assign(num_vertices_, 0.0);
  for (const auto& c : contacts_)
    friction_load_[c.vertex] = std::max(0.0, -k_contact_ * c.n.dot(x[c.vertex] - c.p));
}

namespace {
// IPC's smoothed friction: f0 (the potential per unit load) and f1(y)/y (the force's factor).
double friction_f0(double y, double eps) {
  return y < eps ? y * y / eps - y * y * y / (3 * eps * eps) + eps / 3 : y;
}
double friction_f1_over_y(double y, double eps) {
  return y < eps ? 2 / eps - y / (eps * eps) : 1 / y;
}
}  // namespace

Vec3 ClothEnergy::friction_slip(const Contact& c, const Vec3& xi) const {
  const Vec3 r = xi - friction_anchor_[c.vertex];
  return r - c.n.dot(r) * c.n;
}

void ClothEnergy::friction_gradient_hessian(int i, const Vec3& xi, Vec3& g, Mat3* H) const {
  g.setZero();
  if (H) H->setZero();
  const int ci = friction_mu_ > 0 ? contact_index_[i] : -1;
  if (ci < 0 || friction_load_[i] <= 0) return;
  const Vec3& n = contacts_[ci].n;
  const Vec3 u = friction_slip(contacts_[ci], xi);
  const double y = u.norm(), eps = friction_eps_, s = friction_mu_ * friction_load_[i];
  const double a = friction_f1_over_y(y, eps);
  g = s * a * u;
  if (!H) return;
  // d(a u)/dx = a T + a'(y)/y u u^T with a' = -1/eps^2 (y < eps) or -1/y^2: both PSD in the
  // tangent plane (eigenvalue along u: 2 (eps - y)/eps^2 >= 0, or 0 beyond eps).
  const double b = y < eps ? -1 / (eps * eps * std::max(y, 1e-300)) : -1 / (y * y * y);
  const Mat3 T = Mat3::Identity() - n * n.transpose();
  *H = s * (a * T + (y > 0 ? b : 0.0) * u * u.transpose());
}

// ---------------------------------------------------------------------------------------------

double ClothEnergy::energy(const std::vector<Vec3>& x, const std::vector<double>& mass) const {
  double e = 0;
  for (int t = 0; t < num_triangles(); ++t) e += tri_energy(t, x);
  e += bending_energy(x);
  for (int s = 0; s < num_springs(); ++s) e += spring_energy(s, x);
  for (int i = 0; i < num_vertices_; ++i) {
    if (opt_.gravity) e -= mass[i] * opt_.g.dot(x[i]);
    if (opt_.pressure > 0 && scene_ && scene_->form) {
      const DressForm& form = *scene_->form;
      if (x[i].y() >= form.min_y() && x[i].y() <= form.max_y()) {
        const Vec2 c = form.centre_at(x[i].y());
        e += opt_.pressure * vertex_area_[i] * Vec2(x[i].x() - c.x(), x[i].z() - c.y()).norm();
      }
    }
  }
  for (const auto& c : contacts_) {
    const double d = c.n.dot(x[c.vertex] - c.p);
    if (d < 0) e += 0.5 * k_contact_ * d * d;
    if (friction_mu_ > 0 && friction_load_[c.vertex] > 0)
      e += friction_mu_ * friction_load_[c.vertex] *
           friction_f0(friction_slip(c, x[c.vertex]).norm(), friction_eps_);
  }
  return e;
}

void ClothEnergy::gradient(const std::vector<Vec3>& x, const std::vector<double>& mass,
                           std::vector<Vec3>& grad) const {
  grad.resize(num_vertices_);
  for (int i = 0; i < num_vertices_; ++i) grad[i] = -external_force(i, x[i], mass[i]);
  Vec3 g[4];
  for (int t = 0; t < num_triangles(); ++t) {
    tri_gradient(t, x, g);
    for (int k = 0; k < 3; ++k) grad[tri_v_[t][k]] += g[k];
  }
  add_bending_gradient(x, grad);
  for (int s = 0; s < num_springs(); ++s) {
    spring_gradient(s, x, g);
    grad[spring_v_[s][0]] += g[0];
    grad[spring_v_[s][1]] += g[1];
  }
  for (const auto& c : contacts_) {
    const double d = c.n.dot(x[c.vertex] - c.p);
    if (d < 0) grad[c.vertex] += k_contact_ * d * c.n;
    if (friction_mu_ > 0) {
      Vec3 gf;
      friction_gradient_hessian(c.vertex, x[c.vertex], gf, nullptr);
      grad[c.vertex] += gf;
    }
  }
}

void ClothEnergy::vertex_force_hessian(int i, const std::vector<Vec3>& x, double mass, Vec3& f,
                                       Mat3& H) const {
  if (tensor_bending() && !has_bending_matrix())
    throw std::logic_error("ClothEnergy::vertex_force_hessian: built with bending_matrix = false");
  f = external_force(i, x[i], mass);
  {
    Vec3 g = Vec3::Zero();
    double h[9] = {};
    for (int e = vt_off_[i]; e < vt_off_[i + 1]; ++e) {
      const int t = vt_[e] / 3, a = vt_[e] % 3;
      const auto& v = tri_v_[t];
      membrane_block(x[v[0]], x[v[1]], x[v[2]], tri_D_[t], a, tri_area_[t], ku_, kv_, kshear_, g,
                     h);
    }
    f -= g;
    H << h[0], h[1], h[2], h[1], h[4], h[5], h[2], h[5], h[8];
  }
  if (tensor_bending()) {
    // Constant P: g_i = sum_j P_ij x_j, H_ii = P_ii I (exact, PSD).
    Vec3 g = Vec3::Zero();
    for (int k = bend_off_[i]; k < bend_off_[i + 1]; ++k) g += bend_val_[k] * x[bend_col_[k]];
    f -= g;
    H.diagonal().array() += bend_diag_[i];
  } else {
    for (int e = vh_off_[i]; e < vh_off_[i + 1]; ++e) {
      Vec3 g;
      Mat3 Hb;
      hinge_vertex_block(vh_[e] / 4, vh_[e] % 4, x, g, Hb);
      f -= g;
      H += Hb;
    }
  }
  for (int e = vs_off_[i]; e < vs_off_[i + 1]; ++e) {
    const int s = vs_[e] / 2, a = vs_[e] % 2;
    const Vec3 d = x[spring_v_[s][a]] - x[spring_v_[s][1 - a]];
    const double l = std::max(d.norm(), 1e-15);
    const Vec3 n = d / l;
    f -= spring_k_[s] * (l - spring_rest_[s]) * n;
    const double c = std::max(0.0, 1.0 - spring_rest_[s] / l);
    H += spring_k_[s] * (n * n.transpose() + c * (Mat3::Identity() - n * n.transpose()));
  }
  const int ci = contact_index_[i];
  if (ci >= 0) {
    const Contact& c = contacts_[ci];
    const double d = c.n.dot(x[i] - c.p);
    if (d < 0) {
      f -= k_contact_ * d * c.n;
      H += k_contact_ * c.n * c.n.transpose();
    }
    if (friction_mu_ > 0) {
      Vec3 gf;
      Mat3 Hf;
      friction_gradient_hessian(i, x[i], gf, &Hf);
      f -= gf;
      H += Hf;
    }
  }
}

void ClothEnergy::vertex_neighbours(std::vector<int>& offsets, std::vector<int>& nbrs) const {
  if (tensor_ && !has_bending_matrix())
    throw std::logic_error("ClothEnergy::vertex_neighbours: built with bending_matrix = false");
  std::vector<std::vector<int>> adj(num_vertices_);
  auto link = [&](const int* v, int k) {
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b)
        if (a != b) adj[v[a]].push_back(v[b]);
  };
  for (const auto& t : tri_v_) link(t.data(), 3);
  for (const auto& h : hinge_v_) link(h.data(), 4);
  for (const auto& s : spring_v_) link(s.data(), 2);
  // kTensor: P couples every pair of vertices of a triangle's three hinge stencils (2-ring).
  for (int i = 0; i < static_cast<int>(bend_off_.size()) - 1; ++i)
    for (int k = bend_off_[i]; k < bend_off_[i + 1]; ++k)
      if (bend_col_[k] != i) adj[i].push_back(bend_col_[k]);
  offsets.assign(num_vertices_ + 1, 0);
  nbrs.clear();
  for (int i = 0; i < num_vertices_; ++i) {
    auto& a = adj[i];
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    nbrs.insert(nbrs.end(), a.begin(), a.end());
    offsets[i + 1] = static_cast<int>(nbrs.size());
  }
}

}  // namespace drape::sim
