#include "sim/rest/coarse_correction.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "sim/core/stopwatch.hpp"

namespace drape::sim {

namespace {
using SpMat = Eigen::SparseMatrix<double>;

// Index of entry (i, j) in a CSR pattern with sorted columns (the entry must exist).
int csr_index(const std::vector<int>& off, const std::vector<int>& col, int i, int j) {
  const int* b = col.data() + off[i];
  const int* e = col.data() + off[i + 1];
  return static_cast<int>(std::lower_bound(b, e, j) - col.data());
}

// The tensor bending's rows come in groups of up to three (a triangle's uu, vv, uv) over the
// same columns: the size of the group that starts at row r.
int bending_row_group(const std::vector<int>& off, const std::vector<int>& col, int r) {
  const int rows = static_cast<int>(off.size()) - 1;
  const int len = off[r + 1] - off[r];
  int g = 1;
  while (g < 3 && r + g < rows && off[r + g + 1] - off[r + g] == len &&
         std::equal(col.begin() + off[r], col.begin() + off[r + 1], col.begin() + off[r + g]))
    ++g;
  return g;
}
}  // namespace

struct CoarseCorrection::Impl {
  // What the lattice was built for.
  uint64_t version = 0;
  int n = -1, factor = 0;
  std::vector<int> group;
  // Prolongation, CSR over fine vertices: node and bilinear weight (rows of fixed vertices
  // empty).
  std::vector<int> p_off, p_node;
  std::vector<double> p_w;
  int m = 0;              // coarse nodes
  bool factored = false;  // chol holds the last assembled matrix (fit() spoils it)
  // With rotations the fine block pattern is the energy's: which energy it was built for.
  const ClothEnergy* fine_energy = nullptr;
  size_t fine_elements = 0;
  static size_t elements_of(const ClothEnergy& e) {
    return static_cast<size_t>(e.num_triangles()) + e.num_hinges() + e.num_springs() +
           e.bending_columns().size() + e.bending_row_columns().size();
  }
  int nb = 3;  // unknowns per node: 3 (translation) or 6 (and a rotation, CoarseOptions)
  // With rotations: entry p's 3 x 6 prolongation block w [T, -T [x_i - c_n]x / s] (T the
  // vertex's projector, s the lattice spacing that gives the rotation a length's units) and
  // the nodes' centres.
  using G36 = Eigen::Matrix<double, 3, 6>;
  std::vector<G36> G;
  std::vector<Vec3> centre;
  std::vector<double> wsum;
  double spacing = 1;
  // Coarse block pattern, CSR over nodes (sorted columns), and for block k the value index of
  // its entry (3 I, 3 J + c) in the compressed column 3 J + c (rows 3 I .. 3 I + 2 follow it).
  std::vector<int> b_off, b_col, b_val;
  SpMat H;
  // CHOLMOD's supernodal LL^T (as the Newton solver's): 128^2 with nodes every 4 edges, 3267
  // unknowns, factorises in 25-30 ms against 44-48 ms for Eigen's SimplicialLDLT (measured).
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> chol;
  Eigen::VectorXd rhs, d;
  std::vector<Vec3> grad, xt, dx;
  // Scratch of the bending rows' restriction: their nodes, block indices, coefficients.
  std::vector<int> un, ublk;
  std::vector<double> uc, us;
  std::vector<Mat3> uC;
  // Per vertex: the projector its coarse motion goes through (I, or I - n n^T for a vertex in
  // contact, which slides on its plane).
  std::vector<Mat3> T;
  std::vector<uint8_t> tangential;

  int block(int I, int J) const { return csr_index(b_off, b_col, I, J); }
  void add(int I, int J, double s, const Mat3& B) {
    double* v = H.valuePtr();
    const int k = block(I, J);
    for (int c = 0; c < 3; ++c) {
      double* col = v + b_val[3 * k + c];
      col[0] += s * B(0, c);
      col[1] += s * B(1, c);
      col[2] += s * B(2, c);
    }
  }
  void add_identity(int I, int J, double s) {
    const int k = block(I, J);
    for (int c = 0; c < 3; ++c) H.valuePtr()[b_val[3 * k + c] + c] += s;
  }
  // Fine block (a, b) into every coarse pair of their prolongation rows.
  void add_fine(int a, int b, const Mat3& B0) {
    Mat3 B = B0;
    if (tangential[a]) B = T[a] * B;
    if (tangential[b]) B = B * T[b];
    for (int p = p_off[a]; p < p_off[a + 1]; ++p)
      for (int q = p_off[b]; q < p_off[b + 1]; ++q) add(p_node[p], p_node[q], p_w[p] * p_w[q], B);
  }
  bool moves(int i) const { return p_off[i + 1] > p_off[i]; }
  // Hinges (when the energy has them) and springs: fn(vertices, count, projected Hessian).
  template <class Fn>
  static void hinges_and_springs(const ClothEnergy& energy, const std::vector<Vec3>& x, Fn&& fn) {
    if (!energy.tensor_bending()) {
      Mat12 H12;
      for (int h = 0; h < energy.num_hinges(); ++h) {
        energy.hinge_hessian(h, x, H12, true);
        fn(energy.hinge(h).data(), 4, H12);
      }
    }
    Eigen::Matrix<double, 6, 6> H6;
    for (int s = 0; s < energy.num_springs(); ++s) {
      energy.spring_hessian(s, x, H6, true);
      fn(energy.spring(s).data(), 2, H6);
    }
  }
  // A contact vertex's own block: the penalty's normal stiffness when it is not projected but
  // inside its plane, and friction's tangential one (when set).
  Mat3 contact_block(const ClothEnergy& energy, const Contact& c,
                     const std::vector<Vec3>& x) const {
    const int i = c.vertex;
    Mat3 B = Mat3::Zero();
    if (!tangential[i] && c.n.dot(x[i] - c.p) < 0)
      B += energy.contact_stiffness() * c.n * c.n.transpose();
    if (energy.friction_on()) {
      Vec3 gf;
      Mat3 Hf;
      energy.friction_gradient_hessian(i, x[i], gf, &Hf);
      B += Hf;
    }
    return B;
  }
  // An element's (3k x 3k) Hessian over its k vertices: first restricted to the element's own
  // nodes (a vertex's slot s gets coefficient blocks w T), then each node pair added once (a
  // triangle inside one lattice cell touches 4 nodes: 16 block additions instead of up to 81).
  template <class M>
  void add_element(const int32_t* v, int k, const M& He) {
    int nodes[16], nn = 0;
    int slot_of[4][4];  // [vertex a][its p-th node] -> local node
    for (int a = 0; a < k; ++a) {
      int q = 0;
      for (int p = p_off[v[a]]; p < p_off[v[a] + 1]; ++p, ++q) {
        const int I = p_node[p];
        int l = 0;
        while (l < nn && nodes[l] != I) ++l;
        if (l == nn) nodes[nn++] = I;
        slot_of[a][q] = l;
      }
    }
    if (nn == 0) return;
    Eigen::Matrix<double, 48, 48> L;
    L.topLeftCorner(3 * nn, 3 * nn).setZero();
    for (int a = 0; a < k; ++a) {
      if (!moves(v[a])) continue;
      for (int b = 0; b < k; ++b) {
        if (!moves(v[b])) continue;
        Mat3 B = He.template block<3, 3>(3 * a, 3 * b);
        if (tangential[v[a]]) B = T[v[a]] * B;
        if (tangential[v[b]]) B = B * T[v[b]];
        int qa = 0;
        for (int p = p_off[v[a]]; p < p_off[v[a] + 1]; ++p, ++qa) {
          int qb = 0;
          for (int q = p_off[v[b]]; q < p_off[v[b] + 1]; ++q, ++qb)
            L.block<3, 3>(3 * slot_of[a][qa], 3 * slot_of[b][qb]) += (p_w[p] * p_w[q]) * B;
        }
      }
    }
    for (int i = 0; i < nn; ++i)
      for (int j = 0; j < nn; ++j) add(nodes[i], nodes[j], 1.0, L.block<3, 3>(3 * i, 3 * j));
  }

  void build(const Cloth& cloth, const ClothEnergy& energy, const std::vector<int>& grp, int f,
             int blocksize) {
    const auto& mat = cloth.topo.material;
    // One pass over the elements, before anything is changed (a rejected call leaves the last
    // lattice as it was): no element may join two groups, which are coarsened apart (fixed
    // vertices, -1, may be anywhere); and the farthest apart (per material axis) two vertices
    // of one element lie, which bounds the nodes that can couple.
    double reach = 0;
    auto element = [&](const int* v, int k) {
      int g = -1;
      Vec2 lo = mat[v[0]], hi = lo;
      for (int a = 0; a < k; ++a) {
        lo = lo.cwiseMin(mat[v[a]]);
        hi = hi.cwiseMax(mat[v[a]]);
        const int ga = grp[v[a]];
        if (ga < 0) continue;
        if (g >= 0 && ga != g)
          throw std::invalid_argument("CoarseCorrection: an element joins vertex groups " +
                                      std::to_string(g) + " and " + std::to_string(ga));
        g = ga;
      }
      reach = std::max(reach, (hi - lo).maxCoeff());
    };
    const int nv = cloth.num_vertices();
    for (int t = 0; t < energy.num_triangles(); ++t) element(energy.tri(t).data(), 3);
    for (int h = 0; h < energy.num_hinges(); ++h) element(energy.hinge(h).data(), 4);
    for (int s = 0; s < energy.num_springs(); ++s) element(energy.spring(s).data(), 2);
    if (energy.tensor_bending() && energy.has_bending_matrix()) {
      const auto& off = energy.bending_offsets();
      const auto& col = energy.bending_columns();
      for (int i = 0; i < nv; ++i)
        for (int k = off[i]; k < off[i + 1]; ++k) {
          const int v[2] = {i, col[k]};
          element(v, 2);
        }
    } else if (energy.tensor_bending()) {
      const auto& off = energy.bending_row_offsets();
      const auto& col = energy.bending_row_columns();
      for (int r = 0; r + 1 < static_cast<int>(off.size()); ++r)
        if (off[r + 1] > off[r]) element(col.data() + off[r], off[r + 1] - off[r]);
    }
    n = nv;
    version = cloth.topology_version;
    factor = f;
    group = grp;
    nb = blocksize;
    double u0 = 0, v0 = 0, u1 = 0, v1 = 0;
    bool any = false;
    for (int i = 0; i < n; ++i)
      if (group[i] >= 0) {
        u0 = any ? std::min(u0, mat[i].x()) : mat[i].x();
        v0 = any ? std::min(v0, mat[i].y()) : mat[i].y();
        u1 = any ? std::max(u1, mat[i].x()) : mat[i].x();
        v1 = any ? std::max(v1, mat[i].y()) : mat[i].y();
        any = true;
      }
    // The lattice spacing: `f` nominal edges; a cloth without a nominal spacing (imported,
    // remeshed) uses its mean material edge; at most 4096 cells per axis whatever the input.
    double edge = nominal_edge(cloth);
    if (!(edge > 0)) edge = 1.0;
    const double Hs = std::max(std::max(1, f) * edge, std::max(u1 - u0, v1 - v0) / 4096);
    spacing = Hs;
    std::unordered_map<uint64_t, int> index;
    std::vector<std::array<int, 3>> nodes;  // group, iu, iv
    auto key = [](int g, int iu, int iv) {
      return (static_cast<uint64_t>(static_cast<uint32_t>(g)) << 42) ^
             (static_cast<uint64_t>(static_cast<uint32_t>(iu) & 0x1fffff) << 21) ^
             static_cast<uint64_t>(static_cast<uint32_t>(iv) & 0x1fffff);
    };
    // Lattice coordinate and weight along one axis; a vertex within 1e-7 cells of a lattice
    // line lies on it (a grid whose spacing divides the lattice's gets exact weights).
    auto split = [](double fcoord, int& i, double& a) {
      const double r = std::round(fcoord);
      if (std::abs(fcoord - r) < 1e-7) fcoord = r;
      i = static_cast<int>(std::floor(fcoord));
      a = fcoord - i;
    };
    p_off.assign(n + 1, 0);
    p_node.clear();
    p_w.clear();
    for (int i = 0; i < n; ++i) {
      p_off[i] = static_cast<int>(p_node.size());
      if (group[i] < 0) continue;
      int iu, iv;
      double au, av;
      split((mat[i].x() - u0) / Hs, iu, au);
      split((mat[i].y() - v0) / Hs, iv, av);
      const double wu[2] = {1 - au, au}, wv[2] = {1 - av, av};
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a) {
          const double w = wu[a] * wv[b];
          if (w <= 0) continue;
          auto [it, fresh] =
              index.emplace(key(group[i], iu + a, iv + b), static_cast<int>(nodes.size()));
          if (fresh) nodes.push_back({group[i], iu + a, iv + b});
          p_node.push_back(it->second);
          p_w.push_back(w);
        }
    }
    p_off[n] = static_cast<int>(p_node.size());
    m = static_cast<int>(nodes.size());
    const int cells = 1 + static_cast<int>(std::ceil(std::max(u1 - u0, v1 - v0) / Hs));
    const int R = std::min(1 + static_cast<int>(std::ceil(reach / Hs - 1e-9)), cells);
    b_off.assign(m + 1, 0);
    b_col.clear();
    std::vector<int> cols;
    for (int I = 0; I < m; ++I) {
      b_off[I] = static_cast<int>(b_col.size());
      cols.clear();
      const auto [g, iu, iv] = nodes[I];
      for (int dv = -R; dv <= R; ++dv)
        for (int du = -R; du <= R; ++du) {
          auto it = index.find(key(g, iu + du, iv + dv));
          if (it != index.end()) cols.push_back(it->second);
        }
      std::sort(cols.begin(), cols.end());
      b_col.insert(b_col.end(), cols.begin(), cols.end());
    }
    b_off[m] = static_cast<int>(b_col.size());
    // The scalar pattern: every block full (both triangles; the factorisation reads the lower).
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(b_col.size() * nb * nb);
    for (int I = 0; I < m; ++I)
      for (int k = b_off[I]; k < b_off[I + 1]; ++k)
        for (int r = 0; r < nb; ++r)
          for (int c = 0; c < nb; ++c) trip.emplace_back(nb * I + r, nb * b_col[k] + c, 0.0);
    H.resize(nb * m, nb * m);
    H.setFromTriplets(trip.begin(), trip.end());
    H.makeCompressed();
    b_val.resize(nb * b_col.size());
    const int* outer = H.outerIndexPtr();
    const int* inner = H.innerIndexPtr();
    for (int I = 0; I < m; ++I)
      for (int k = b_off[I]; k < b_off[I + 1]; ++k)
        for (int c = 0; c < nb; ++c) {
          const int cc = nb * b_col[k] + c;
          b_val[nb * k + c] = static_cast<int>(
              std::lower_bound(inner + outer[cc], inner + outer[cc + 1], nb * I) - inner);
        }
    chol.cholmod().print = 0;
    chol.analyzePattern(H);
    rhs.resize(nb * m);
    d.resize(nb * m);
    if (nb == 6) {
      G.resize(p_node.size());
      centre.resize(m);
      wsum.assign(m, 0.0);
      for (int i = 0; i < n; ++i)
        for (int p = p_off[i]; p < p_off[i + 1]; ++p) wsum[p_node[p]] += p_w[p];
      build_fine(energy);
      fine_energy = &energy;
      fine_elements = elements_of(energy);
    }
    T.assign(n, Mat3::Identity());
    tangential.assign(n, 0);
  }

  // P^T H P at x, with the contact projection of the current contacts.
  void assemble(const ClothEnergy& energy, const std::vector<Vec3>& x, double contact_reach) {
    std::fill(tangential.begin(), tangential.end(), 0);
    for (const Contact& c : energy.contacts())
      if (moves(c.vertex) && c.n.dot(x[c.vertex] - c.p) < contact_reach) {
        tangential[c.vertex] = 1;
        T[c.vertex] = Mat3::Identity() - c.n * c.n.transpose();
      }
    std::fill(H.valuePtr(), H.valuePtr() + H.nonZeros(), 0.0);
    if (nb == 6) {
      assemble6(energy, x);
      return;
    }
    Mat9 H9;
    for (int t = 0; t < energy.num_triangles(); ++t) {
      const auto& v = energy.tri(t);
      if (!moves(v[0]) && !moves(v[1]) && !moves(v[2])) continue;
      energy.tri_hessian(t, x, H9, true);
      add_element(v.data(), 3, H9);
    }
    if (energy.tensor_bending()) {
      if (energy.has_bending_matrix()) {
        // E = 1/2 sum_ij P_ij x_i . x_j: P (x) I3.
        const auto& off = energy.bending_offsets();
        const auto& col = energy.bending_columns();
        const auto& val = energy.bending_values();
        for (int i = 0; i < n; ++i)
          for (int k = off[i]; k < off[i + 1]; ++k) {
            const int j = col[k];
            if (tangential[i] || tangential[j]) {
              add_fine(i, j, val[k] * Mat3::Identity());
              continue;
            }
            for (int p = p_off[i]; p < p_off[i + 1]; ++p)
              for (int q = p_off[j]; q < p_off[j + 1]; ++q)
                add_identity(p_node[p], p_node[q], val[k] * p_w[p] * p_w[q]);
          }
      } else {
        // E = 1/2 sum_r k_r |sum_k c_k x_k|^2: the row restricted to the nodes (3x3 blocks
        // C_I = sum c_k w_kI T_k), then k_r C_I^T C_J. A triangle's three rows (uu, vv, uv)
        // share their columns, so their nodes are gathered once.
        const auto& off = energy.bending_row_offsets();
        const auto& col = energy.bending_row_columns();
        const auto& val = energy.bending_row_values();
        const int rows = static_cast<int>(off.size()) - 1;
        for (int r = 0; r < rows;) {
          const int g = bending_row_group(off, col, r);
          const int len = off[r + 1] - off[r];
          // The nodes of the columns, ascending, and each (column, node) entry's local index.
          un.clear();
          bool plain = true;  // no column is projected: every C_I is c_I I3
          for (int k = 0; k < len; ++k) {
            const int j = col[off[r] + k];
            plain = plain && !tangential[j];
            for (int p = p_off[j]; p < p_off[j + 1]; ++p) un.push_back(p_node[p]);
          }
          if (un.empty()) {
            r += g;
            continue;
          }
          std::sort(un.begin(), un.end());
          un.erase(std::unique(un.begin(), un.end()), un.end());
          const int nu = static_cast<int>(un.size());
          // Block index of every (I, J) pair of the nodes: one merge walk per row of the pattern.
          ublk.resize(nu * nu);
          for (int a = 0; a < nu; ++a) {
            int ptr = b_off[un[a]];
            for (int b = 0; b < nu; ++b) {
              while (b_col[ptr] < un[b]) ++ptr;
              ublk[a * nu + b] = ptr;
            }
          }
          if (plain) {
            // The group's rows summed into one scalar nu x nu matrix, then scattered once.
            us.assign(nu * nu, 0.0);
            for (int rr = r; rr < r + g; ++rr) {
              const double kr = energy.bending_row_stiffness(rr);
              uc.assign(nu, 0.0);
              for (int k = 0; k < len; ++k) {
                const int j = col[off[r] + k];
                for (int p = p_off[j]; p < p_off[j + 1]; ++p) {
                  const int l = static_cast<int>(std::lower_bound(un.begin(), un.end(), p_node[p]) -
                                                 un.begin());
                  uc[l] += val[off[rr] + k] * p_w[p];
                }
              }
              for (int a = 0; a < nu; ++a) {
                const double ka = kr * uc[a];
                for (int b = 0; b < nu; ++b) us[a * nu + b] += ka * uc[b];
              }
            }
            double* hv = H.valuePtr();
            for (int ab = 0; ab < nu * nu; ++ab) {
              const double sab = us[ab];
              const int kb = ublk[ab];
              hv[b_val[3 * kb]] += sab;
              hv[b_val[3 * kb + 1] + 1] += sab;
              hv[b_val[3 * kb + 2] + 2] += sab;
            }
          } else {
            for (int rr = r; rr < r + g; ++rr) {
              const double kr = energy.bending_row_stiffness(rr);
              uC.assign(nu, Mat3::Zero());
              for (int k = 0; k < len; ++k) {
                const int j = col[off[r] + k];
                for (int p = p_off[j]; p < p_off[j + 1]; ++p) {
                  const int l = static_cast<int>(std::lower_bound(un.begin(), un.end(), p_node[p]) -
                                                 un.begin());
                  const double c = val[off[rr] + k] * p_w[p];
                  if (tangential[j])
                    uC[l] += c * T[j];
                  else
                    uC[l].diagonal().array() += c;
                }
              }
              for (int a = 0; a < nu; ++a)
                for (int b = 0; b < nu; ++b) add(un[a], un[b], kr, uC[a].transpose() * uC[b]);
            }
          }
          r += g;
        }
      }
    }
    hinges_and_springs(energy, x,
                       [&](const int32_t* v, int k, const auto& He) { add_element(v, k, He); });
    for (const Contact& c : energy.contacts())
      if (moves(c.vertex)) add_fine(c.vertex, c.vertex, contact_block(energy, c, x));
    shift();
  }

  // ---- Nodes with rotations (nb == 6) ----
  void add6(int I, int J, const double* M, int ld) {  // M: 6 x 6 column-major, leading dim ld
    double* v = H.valuePtr();
    const int k = block(I, J);
    for (int c = 0; c < 6; ++c) {
      double* col = v + b_val[6 * k + c];
      const double* mc = M + c * ld;
      for (int r = 0; r < 6; ++r) col[r] += mc[r];
    }
  }
  // The prolongation blocks at x: node centres, then w T [I, -[x_i - c]x / s].
  void prolong6(const std::vector<Vec3>& x) {
    std::fill(centre.begin(), centre.end(), Vec3::Zero());
    for (int i = 0; i < n; ++i)
      for (int p = p_off[i]; p < p_off[i + 1]; ++p) centre[p_node[p]] += p_w[p] * x[i];
    for (int I = 0; I < m; ++I) centre[I] /= wsum[I];
    for (int i = 0; i < n; ++i)
      for (int p = p_off[i]; p < p_off[i + 1]; ++p) {
        const Vec3 r = (x[i] - centre[p_node[p]]) / spacing;
        Mat3 S;  // -[r]x
        S << 0, r.z(), -r.y(), -r.z(), 0, r.x(), r.y(), -r.x(), 0;
        G36& g = G[p];
        if (tangential[i]) {
          g.leftCols<3>() = p_w[p] * T[i];
          g.rightCols<3>() = p_w[p] * (T[i] * S);
        } else {
          g.leftCols<3>() = p_w[p] * Mat3::Identity();
          g.rightCols<3>() = p_w[p] * S;
        }
      }
  }
  // The fine Hessian as 3x3 blocks over vertex pairs that share an element (CSR, sorted),
  // then P^T F P through Y = F P row by row: ~8x fewer flops than restricting every element's
  // (and bending row's) Hessian to its nodes separately.
  std::vector<int> f_off, f_col, tri_fb, bm_fb;
  std::vector<Mat3> F;
  std::vector<int> y_node;
  std::vector<G36> y_val;
  int fblock(int i, int j) const { return csr_index(f_off, f_col, i, j); }
  void build_fine(const ClothEnergy& energy) {
    std::vector<std::vector<int>> rows(n);
    auto link = [&](const int* v, int k) {
      for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b) rows[v[a]].push_back(v[b]);
    };
    for (int t = 0; t < energy.num_triangles(); ++t) link(energy.tri(t).data(), 3);
    for (int h = 0; h < energy.num_hinges(); ++h) link(energy.hinge(h).data(), 4);
    for (int sp = 0; sp < energy.num_springs(); ++sp) link(energy.spring(sp).data(), 2);
    if (energy.tensor_bending() && energy.has_bending_matrix()) {
      const auto& off = energy.bending_offsets();
      const auto& col = energy.bending_columns();
      for (int i = 0; i < n; ++i)
        for (int k = off[i]; k < off[i + 1]; ++k) rows[i].push_back(col[k]);
    } else if (energy.tensor_bending()) {
      const auto& off = energy.bending_row_offsets();
      const auto& col = energy.bending_row_columns();
      for (int r = 0; r + 1 < static_cast<int>(off.size()); ++r)
        link(col.data() + off[r], off[r + 1] - off[r]);
    }
    f_off.assign(n + 1, 0);
    f_col.clear();
    for (int i = 0; i < n; ++i) {
      rows[i].push_back(i);
      std::sort(rows[i].begin(), rows[i].end());
      rows[i].erase(std::unique(rows[i].begin(), rows[i].end()), rows[i].end());
      f_off[i] = static_cast<int>(f_col.size());
      f_col.insert(f_col.end(), rows[i].begin(), rows[i].end());
    }
    f_off[n] = static_cast<int>(f_col.size());
    F.resize(f_col.size());
    tri_fb.resize(9 * energy.num_triangles());
    for (int t = 0; t < energy.num_triangles(); ++t)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          tri_fb[9 * t + 3 * a + b] = fblock(energy.tri(t)[a], energy.tri(t)[b]);
    bm_fb.clear();
    if (energy.tensor_bending() && energy.has_bending_matrix()) {
      const auto& off = energy.bending_offsets();
      const auto& col = energy.bending_columns();
      bm_fb.resize(col.size());
      for (int i = 0; i < n; ++i)
        for (int k = off[i]; k < off[i + 1]; ++k) bm_fb[k] = fblock(i, col[k]);
    }
  }
  template <class M>
  void add_fine_element(const int32_t* v, int k, const M& He) {
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b) F[fblock(v[a], v[b])] += He.template block<3, 3>(3 * a, 3 * b);
  }
  void assemble6(const ClothEnergy& energy, const std::vector<Vec3>& x) {
    prolong6(x);
    std::fill(F.begin(), F.end(), Mat3::Zero());
    Mat9 H9;
    for (int t = 0; t < energy.num_triangles(); ++t) {
      const auto& v = energy.tri(t);
      if (!moves(v[0]) && !moves(v[1]) && !moves(v[2])) continue;
      energy.tri_hessian(t, x, H9, true);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) F[tri_fb[9 * t + 3 * a + b]] += H9.block<3, 3>(3 * a, 3 * b);
    }
    if (energy.tensor_bending()) {
      if (energy.has_bending_matrix()) {
        const auto& val = energy.bending_values();
        for (size_t k = 0; k < bm_fb.size(); ++k) F[bm_fb[k]].diagonal().array() += val[k];
      } else {
        // Rows sharing their columns (a triangle's uu, vv, uv): their scalar products summed.
        const auto& off = energy.bending_row_offsets();
        const auto& col = energy.bending_row_columns();
        const auto& val = energy.bending_row_values();
        const int rows = static_cast<int>(off.size()) - 1;
        for (int r = 0; r < rows;) {
          const int g = bending_row_group(off, col, r);
          const int len = off[r + 1] - off[r];
          for (int a = 0; a < len; ++a) {
            const int ja = col[off[r] + a];
            if (!moves(ja)) continue;
            for (int b = 0; b < len; ++b) {
              double sab = 0;
              for (int rr = r; rr < r + g; ++rr)
                sab += energy.bending_row_stiffness(rr) * val[off[rr] + a] * val[off[rr] + b];
              F[fblock(ja, col[off[r] + b])].diagonal().array() += sab;
            }
          }
          r += g;
        }
      }
    }
    hinges_and_springs(
        energy, x, [&](const int32_t* v, int k, const auto& He) { add_fine_element(v, k, He); });
    for (const Contact& c : energy.contacts())
      if (moves(c.vertex)) F[fblock(c.vertex, c.vertex)] += contact_block(energy, c, x);
    // P^T F P: row i of Y = F P gathered over its nodes, then G_ip^T Y_i into node row I.
    Eigen::Matrix<double, 6, 6> M;
    for (int i = 0; i < n; ++i) {
      if (!moves(i)) continue;
      y_node.clear();
      y_val.clear();
      for (int k = f_off[i]; k < f_off[i + 1]; ++k) {
        const int j = f_col[k];
        for (int q = p_off[j]; q < p_off[j + 1]; ++q) {
          const int J = p_node[q];
          size_t l = 0;
          while (l < y_node.size() && y_node[l] != J) ++l;
          if (l == y_node.size()) {
            y_node.push_back(J);
            y_val.push_back(G36::Zero());
          }
          y_val[l].noalias() += F[k] * G[q];
        }
      }
      for (int p = p_off[i]; p < p_off[i + 1]; ++p) {
        const int I = p_node[p];
        for (size_t l = 0; l < y_node.size(); ++l) {
          M.noalias() = G[p].transpose() * y_val[l];
          add6(I, y_node[l], M.data(), 6);
        }
      }
    }
    shift();
  }
  void add_fine6(int a, int b, const Mat3& B) {
    for (int p = p_off[a]; p < p_off[a + 1]; ++p)
      for (int q = p_off[b]; q < p_off[b + 1]; ++q) {
        const Eigen::Matrix<double, 6, 6> Mab = G[p].transpose() * B * G[q];
        add6(p_node[p], p_node[q], Mab.data(), 6);
      }
  }
  // A node without stiffness in some direction (its vertices all slide on one plane, or lie on
  // one line for a rotation): a shift of 1e-9 of the mean diagonal keeps the matrix definite
  // without changing any other step.
  void shift() {
    double mean = 0;
    for (int k = 0; k < nb * m; ++k) mean += H.coeff(k, k);
    mean = mean > 0 ? mean / (nb * m) : 1.0;
    double* v = H.valuePtr();
    for (int I = 0; I < m; ++I) {
      const int k = block(I, I);
      for (int c = 0; c < nb; ++c) v[b_val[nb * k + c] + c] += 1e-9 * mean;
    }
  }
  // r = -P^T g and dx = P d for either kind of node.
  void restrict_neg(const std::vector<Vec3>& g) {
    rhs.setZero();
    for (int i = 0; i < n; ++i)
      for (int p = p_off[i]; p < p_off[i + 1]; ++p) {
        if (nb == 6)
          rhs.segment<6>(6 * p_node[p]) -= G[p].transpose() * g[i];
        else
          rhs.segment<3>(3 * p_node[p]) -= p_w[p] * (tangential[i] ? Vec3(T[i] * g[i]) : g[i]);
      }
  }
  void prolong(std::vector<Vec3>& out) const {
    out.assign(n, Vec3::Zero());
    for (int i = 0; i < n; ++i) {
      if (nb == 6) {
        for (int p = p_off[i]; p < p_off[i + 1]; ++p) out[i] += G[p] * d.segment<6>(6 * p_node[p]);
        continue;
      }
      for (int p = p_off[i]; p < p_off[i + 1]; ++p) out[i] += p_w[p] * d.segment<3>(3 * p_node[p]);
      if (tangential[i]) out[i] = T[i] * out[i];
    }
  }
};

double nominal_edge(const Cloth& cloth) {
  if (cloth.topo.spacing > 0) return cloth.topo.spacing;
  const auto& mat = cloth.topo.material;
  double sum = 0;
  int cnt = 0;
  for (const auto& t : cloth.topo.triangles)
    for (int a = 0; a < 3; ++a, ++cnt) sum += (mat[t[a]] - mat[t[(a + 1) % 3]]).norm();
  return cnt > 0 && sum > 0 ? sum / cnt : 0.0;
}

CoarseCorrection::CoarseCorrection(CoarseOptions opt)
    : opt_(opt), impl_(std::make_unique<Impl>()) {}
CoarseCorrection::~CoarseCorrection() = default;

CoarseStats CoarseCorrection::apply(const Cloth& cloth, const ClothEnergy& energy,
                                    const std::vector<int>& group, std::vector<Vec3>& x,
                                    bool reuse) {
  const auto t0 = std::chrono::steady_clock::now();
  CoarseStats st;
  Impl& P = *impl_;
  const int n = cloth.num_vertices();
  const auto& mass = cloth.state.mass;
  const int nb = opt_.rotations ? 6 : 3;
  if (P.n != n || P.version != cloth.topology_version || P.factor != opt_.factor || P.nb != nb ||
      P.group != group ||
      (nb == 6 && (P.fine_energy != &energy || P.fine_elements != Impl::elements_of(energy)))) {
    P.build(cloth, energy, group, opt_.factor, nb);
    P.factored = false;
    st.rebuilt = true;
    st.build_ms = ms_since(t0);
  }
  st.nodes = P.m;
  if (P.m == 0) return st;

  if (!reuse || !P.factored) {
    P.factored = false;
    const auto ta = std::chrono::steady_clock::now();
    P.assemble(energy, x, opt_.contact_reach);
    st.assemble_ms = ms_since(ta);
    const auto tf = std::chrono::steady_clock::now();
    P.chol.factorize(P.H);
    st.factor_ms = ms_since(tf);
    if (P.chol.info() != Eigen::Success) {
      st.total_ms = ms_since(t0);
      return st;
    }
    P.factored = true;
  } else {
    st.reused = true;
  }

  // -P^T grad E, the coarse step, and its prolongation.
  energy.gradient(x, mass, P.grad);
  P.restrict_neg(P.grad);
  st.residual = P.rhs.lpNorm<Eigen::Infinity>();
  P.d = P.chol.solve(P.rhs);
  const double slope = -P.rhs.dot(P.d);  // grad E . P d
  if (!(slope < 0) || !P.d.allFinite()) {
    st.total_ms = ms_since(t0);
    return st;
  }
  P.prolong(P.dx);

  // Backtracking (Armijo) on E.
  st.energy_before = energy.energy(x, mass);
  P.xt.resize(n);
  double alpha = 1.0;
  for (int ls = 0; ls <= opt_.line_search_steps; ++ls, alpha *= 0.5) {
    for (int i = 0; i < n; ++i) P.xt[i] = x[i] + alpha * P.dx[i];
    const double e = energy.energy(P.xt, mass);
    if (e <= st.energy_before + 1e-4 * alpha * slope) {
      st.applied = true;
      st.energy_after = e;
      st.alpha = alpha;
      double mm = 0;
      for (int i = 0; i < n; ++i) mm = std::max(mm, alpha * P.dx[i].norm());
      st.max_move = mm;
      x.swap(P.xt);
      break;
    }
  }
  st.total_ms = ms_since(t0);
  return st;
}

bool CoarseCorrection::fit(const std::vector<Vec3>& f, std::vector<Vec3>& fitted) {
  Impl& P = *impl_;
  if (P.m == 0 || static_cast<int>(f.size()) != P.n) return false;
  P.factored = false;
  // (Uses the coarse matrix's storage; apply() assembles it anew every time.)
  std::fill(P.H.valuePtr(), P.H.valuePtr() + P.H.nonZeros(), 0.0);
  for (int i = 0; i < P.n; ++i) {
    if (!P.moves(i)) continue;
    if (P.nb == 6)
      P.add_fine6(i, i, Mat3::Identity());
    else
      P.add_fine(i, i, Mat3::Identity());
  }
  std::vector<Vec3> neg(f.size());
  for (size_t i = 0; i < f.size(); ++i) neg[i] = -f[i];
  P.restrict_neg(neg);
  P.shift();
  P.chol.factorize(P.H);
  if (P.chol.info() != Eigen::Success) return false;
  P.d = P.chol.solve(P.rhs);
  P.prolong(fitted);
  return true;
}

}  // namespace drape::sim
