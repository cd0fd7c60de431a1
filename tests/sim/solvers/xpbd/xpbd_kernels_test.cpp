// XPBD's hot loops (sim/solvers/xpbd/xpbd_kernels.hpp): the packed kernels (four doubles, or eight
// or sixteen floats per pack, one element per lane) do what projecting the elements one after the
// other does, the SIMD builds (AVX2, AVX-512) agree with the portable one, and a triangle
// projection does what the constraint says.
#include "sim/solvers/xpbd/xpbd_kernels.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <random>
#include <string>
#include <vector>

// ctest runs these tests again with DRAPE_XPBD_SIMD=0 and =avx2 (the builds that CPUs without
// AVX2 or without AVX-512 run): the test executable caps the library's choice before any solver
// is made, as `drape --simd` does.
[[maybe_unused]] const bool kSimdCapped = [] {
  if (const char* e = std::getenv("DRAPE_XPBD_SIMD"))
    if (auto limit = drape::sim::xpbd::parse_simd_limit(e)) drape::sim::xpbd::limit_simd(*limit);
  return true;
}();

namespace drape::sim::xpbd {
namespace {

constexpr double kIh2 = 1e4, kIhb = 5e3;  // 1 / h^2 for the triangles and bending blocks

// One colour of elements: no two share a vertex (what the kernels require of a range).
struct Problem {
  int n = 0;  // vertices; index n is the scratch vertex of padding lanes
  std::vector<Eigen::Vector3d> x;
  std::vector<double> w;
  std::vector<Tri> tris;
  std::vector<int> off{0}, colv;
  std::vector<double> val, ik, ai;  // ai: 6 per block (upper triangle of A^-1)
};

// Random but well-posed data: positions in the unit cube, some vertices fixed (w = 0), 203
// triangles and 101 bending blocks of 3 to 7 vertices (counts not multiples of four or eight:
// the last pack is padded) over vertices no two elements share, elements that ignore
// translations (as real ones), compliances that keep every denominator away from zero, and each
// block's inverse system matrix as the solver builds it.
Problem make_problem(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1), s(-5, 5);
  const int ntri = 203, nblk = 101;
  std::uniform_int_distribution<int> len(3, 7);
  std::vector<int> lens(nblk);
  for (int& l : lens) l = len(rng);
  Problem p;
  p.n = 3 * ntri + std::accumulate(lens.begin(), lens.end(), 0);
  std::vector<int> perm(p.n);
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  p.x.resize(p.n);
  p.w.resize(p.n);
  for (int i = 0; i < p.n; ++i) {
    p.x[i] = Eigen::Vector3d(u(rng), u(rng), u(rng));
    p.w[i] = i % 7 == 0 ? 0.0 : 0.5 + u(rng);
  }
  int next = 0;
  for (int t = 0; t < ntri; ++t) {
    Tri T{};
    for (int a = 0; a < 3; ++a) {
      T.v[a] = perm[next++];
      T.ia[a] = 0.1 + u(rng);
    }
    for (double& d : T.D) d = s(rng);
    T.D[0] = -T.D[2] - T.D[4];  // sum_k D_k = 0, as for every triangle: F ignores translations
    T.D[1] = -T.D[3] - T.D[5];
    p.tris.push_back(T);
  }
  // One triangle with all its vertices fixed: the kernels must leave it (and its multipliers)
  // alone.
  for (int a = 0; a < 3; ++a) p.w[p.tris[5].v[a]] = 0;
  for (int r = 0; r < nblk; ++r) {
    double mean[3] = {0, 0, 0};
    for (int i = 0; i < lens[r]; ++i) {
      p.colv.push_back(perm[next++]);
      for (int a = 0; a < 3; ++a) {
        p.val.push_back(s(rng));
        mean[a] += p.val.back() / lens[r];
      }
    }
    // Rows that annihilate constants (as the tensor bending's: P 1 = 0).
    for (int i = 0; i < lens[r]; ++i)
      for (int a = 0; a < 3; ++a) p.val[p.val.size() - 3 * (i + 1) + a] -= mean[a];
    p.off.push_back(static_cast<int>(p.colv.size()));
    for (int a = 0; a < 3; ++a) p.ik.push_back(0.1 + u(rng));
  }
  for (int r = 0; r < nblk; ++r) {
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    for (int k = p.off[r]; k < p.off[r + 1]; ++k) {
      const Eigen::Vector3d v(p.val[3 * k], p.val[3 * k + 1], p.val[3 * k + 2]);
      A += p.w[p.colv[k]] * v * v.transpose();
    }
    for (int a = 0; a < 3; ++a) A(a, a) += kIhb * p.ik[3 * r + a];
    const Eigen::Matrix3d Ai = A.inverse();
    const double blk[6] = {Ai(0, 0), Ai(0, 1), Ai(0, 2), Ai(1, 1), Ai(1, 2), Ai(2, 2)};
    p.ai.insert(p.ai.end(), blk, blk + 6);
  }
  return p;
}

// The projections written plainly, one element after the other (what the lanes must equal).
void reference_tris(Problem& p, double ih2, double* lambda) {
  for (size_t k = 0; k < p.tris.size(); ++k) {
    const Tri& T = p.tris[k];
    const double wq[3] = {p.w[T.v[0]], p.w[T.v[1]], p.w[T.v[2]]};
    if (wq[0] + wq[1] + wq[2] == 0) continue;
    const double* D = T.D;
    Eigen::Vector3d fu = Eigen::Vector3d::Zero(), fv = Eigen::Vector3d::Zero();
    double Suu = 0, Svv = 0, Suv = 0;
    for (int q = 0; q < 3; ++q) {
      fu += D[2 * q] * p.x[T.v[q]];
      fv += D[2 * q + 1] * p.x[T.v[q]];
      Suu += wq[q] * D[2 * q] * D[2 * q];
      Svv += wq[q] * D[2 * q + 1] * D[2 * q + 1];
      Suv += wq[q] * D[2 * q] * D[2 * q + 1];
    }
    double* L = lambda ? lambda + 3 * k : nullptr;
    Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
    auto stretch = [&](int c, Eigen::Vector3d& f, Eigen::Vector3d& g, double Sff,
                       Eigen::Vector3d& acc) {
      const double alpha = ih2 * T.ia[c], f2 = f.squaredNorm(), denom = alpha + Sff * f2;
      if (denom < 1e-20) return;
      const double lam = L ? L[c] : 0.0;
      const double dl = (-0.5 * (f2 - 1) - alpha * lam) / denom;
      if (L) L[c] = lam + dl;
      acc += dl * f;
      g += (dl * Suv) * f;
      f *= 1 + dl * Sff;
    };
    stretch(0, fu, fv, Suu, a);
    stretch(1, fv, fu, Svv, b);
    const double alpha = ih2 * T.ia[2], uv = fu.dot(fv);
    const double denom =
        alpha + 0.25 * (Suu * fv.squaredNorm() + 2 * Suv * uv + Svv * fu.squaredNorm());
    if (denom >= 1e-20) {
      const double lam = L ? L[2] : 0.0;
      const double dl = (-0.5 * uv - alpha * lam) / denom;
      if (L) L[2] = lam + dl;
      a += (0.5 * dl) * fv;
      b += (0.5 * dl) * fu;
    }
    for (int q = 0; q < 3; ++q) p.x[T.v[q]] += wq[q] * (D[2 * q] * a + D[2 * q + 1] * b);
  }
}

void reference_rows(Problem& p, double ihb, double* lambda) {
  for (size_t r = 0; r + 1 < p.off.size(); ++r) {
    Eigen::Vector3d C[3] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                            Eigen::Vector3d::Zero()};
    for (int k = p.off[r]; k < p.off[r + 1]; ++k)
      for (int a = 0; a < 3; ++a) C[a] += p.val[3 * k + a] * p.x[p.colv[k]];
    if (lambda)
      for (int a = 0; a < 3; ++a)
        C[a] += ihb * p.ik[3 * r + a] * Eigen::Map<Eigen::Vector3d>(lambda + 9 * r + 3 * a);
    const double* ai = &p.ai[6 * r];
    Eigen::Matrix3d Ai;
    Ai << ai[0], ai[1], ai[2], ai[1], ai[3], ai[4], ai[2], ai[4], ai[5];
    Eigen::Vector3d d[3];
    for (int a = 0; a < 3; ++a) d[a] = -(Ai(a, 0) * C[0] + Ai(a, 1) * C[1] + Ai(a, 2) * C[2]);
    if (lambda)
      for (int a = 0; a < 3; ++a) Eigen::Map<Eigen::Vector3d>(lambda + 9 * r + 3 * a) += d[a];
    for (int k = p.off[r]; k < p.off[r + 1]; ++k) {
      const double* v = &p.val[3 * k];
      p.x[p.colv[k]] += p.w[p.colv[k]] * (v[0] * d[0] + v[1] * d[1] + v[2] * d[2]);
    }
  }
}

// The problem packed for the kernels, projected `iters` times.
struct Packed {
  std::vector<P4> xp;
  std::vector<TriPack> tp;
  RowPackData rp;
};
Packed pack_problem(const Problem& p) {
  Packed k;
  k.xp.resize(p.n + 1);
  for (int i = 0; i < p.n; ++i) k.xp[i] = P4{{p.x[i][0], p.x[i][1], p.x[i][2], p.w[i]}};
  k.xp[p.n] = P4{{0, 0, 0, 0}};
  pack_triangles(p.tris.data(), 0, static_cast<int>(p.tris.size()), p.n, k.tp);
  const int nb = static_cast<int>(p.off.size()) - 1;
  std::vector<int> pack_col;
  k.rp.assign(p.off.data(), p.colv.data(), p.val.data(), p.ik.data(), {0, nb}, p.n, 1, nullptr,
              pack_col);
  for (int r = 0; r < nb; ++r)
    for (int m = 0; m < 6; ++m) k.rp.ai_of(r, m) = p.ai[6 * r + m];
  return k;
}

double max_diff(const std::vector<P4>& a, const std::vector<Eigen::Vector3d>& b) {
  double m = 0;
  for (size_t i = 0; i < b.size(); ++i)
    for (int c = 0; c < 3; ++c) m = std::max(m, std::abs(a[i].c[c] - b[i][c]));
  return m;
}

TEST(XpbdKernels, PacksProjectLikeOneElementAfterTheOther) {
  for (const Kernels* K : all_kernels())
    for (bool keep : {false, true}) {
      Problem ref = make_problem(7);
      const Problem orig = ref;
      Packed pk = pack_problem(ref);
      EXPECT_EQ(pk.tp.size(), 51u);  // 203 triangles: 50 full packs and one of three
      EXPECT_EQ(pk.rp.packs(), 26);  // 101 blocks
      std::vector<double> lt_ref(3 * ref.tris.size(), 0.0), lt = lt_ref;
      std::vector<double> lr_ref(9 * (ref.off.size() - 1), 0.0), lr = lr_ref;
      for (int it = 0; it < 3; ++it) {
        reference_tris(ref, kIh2, keep ? lt_ref.data() : nullptr);
        reference_rows(ref, kIhb, keep ? lr_ref.data() : nullptr);
        K->tris(pk.tp.data(), 0, static_cast<int>(pk.tp.size()), pk.xp.data(), kIh2,
                keep ? lt.data() : nullptr);
        K->rows(pk.rp.view(), 0, pk.rp.packs(), pk.xp.data(), kIhb, keep ? lr.data() : nullptr);
      }
      double move = 0;
      for (int i = 0; i < ref.n; ++i) move = std::max(move, (ref.x[i] - orig.x[i]).norm());
      const double d = max_diff(pk.xp, ref.x);
      double dl = 0;
      for (size_t k = 0; k < lt.size(); ++k) dl = std::max(dl, std::abs(lt[k] - lt_ref[k]));
      for (size_t k = 0; k < lr.size(); ++k) dl = std::max(dl, std::abs(lr[k] - lr_ref[k]));
      std::printf(
          "%s kernels (multipliers %s): positions moved up to %.3e, differ from one element "
          "after the other by %.3e; multipliers by %.3e\n",
          K->name, keep ? "kept" : "reset", move, d, dl);
      EXPECT_GT(move, 1e-3);  // the projections did move the vertices
      EXPECT_LT(d, 1e-12);    // round-off (FMA contraction, order of sums) only
      if (keep) {
        EXPECT_LT(dl, 1e-9);
        for (int c = 0; c < 3; ++c) EXPECT_EQ(lt[3 * 5 + c], 0.0);  // the fixed triangle
      }
      for (int i = 0; i <= ref.n; ++i) {
        const double wi = i < ref.n ? ref.w[i] : 0.0;
        EXPECT_EQ(pk.xp[i].c[3], wi);  // the inverse-mass lane is read, never written
        if (wi == 0 && i < ref.n) {    // fixed vertices do not move
          for (int c = 0; c < 3; ++c) EXPECT_EQ(pk.xp[i].c[c], orig.x[i][c]);
        }
      }
      for (int c = 0; c < 3; ++c) EXPECT_EQ(pk.xp[ref.n].c[c], 0.0);  // the scratch vertex
    }
}

// kernels() returns the last (widest) of all_kernels(), which starts with the portable build;
// DRAPE_XPBD_SIMD=0 leaves only that one, DRAPE_XPBD_SIMD=avx2 stops below AVX-512 (ctest runs
// this test with both too: simd_off.*, simd_avx2.*).
// Bending blocks of several colours packed in eights: on a pool of two threads the same arrays
// as on one, and every block in its colour's packs with its own columns and values, the padding
// on its share's scratch vertex.
TEST(XpbdKernels, BendingPacksHoldEveryBlockOfEveryColourOnAPoolAsOnOneThread) {
  constexpr int L = 8, kScratch = 500, kShares = 3;
  std::mt19937 rng(7);
  const std::vector<int> col{0, 37, 70, 71, 100};  // four colours, one of a single block
  const int nb = col.back();
  std::vector<int> boff{0}, bcol;
  std::vector<double> bval, bik;
  for (int r = 0; r < nb; ++r) {
    const int len = 3 + static_cast<int>(rng() % 10);
    for (int i = 0; i < len; ++i) {
      bcol.push_back(static_cast<int>(rng() % kScratch));
      for (int a = 0; a < 3; ++a) bval.push_back(std::ldexp(double(rng() % 1000) - 500, -7));
    }
    boff.push_back(static_cast<int>(bcol.size()));
    for (int a = 0; a < 3; ++a) bik.push_back(1.0 + r + 0.25 * a);
  }
  RowPackData8 one, two;
  std::vector<int> col_one, col_two;
  one.assign(boff.data(), bcol.data(), bval.data(), bik.data(), col, kScratch, kShares, nullptr,
             col_one);
  drape::sim::ThreadPool pool(2);
  two.assign(boff.data(), bcol.data(), bval.data(), bik.data(), col, kScratch, kShares, &pool,
             col_two);
  EXPECT_EQ(one.off, two.off);
  EXPECT_EQ(one.colv, two.colv);
  EXPECT_EQ(one.val, two.val);
  EXPECT_EQ(one.ik, two.ik);
  EXPECT_EQ(one.blk, two.blk);
  EXPECT_EQ(one.ai, two.ai);
  EXPECT_EQ(one.slot, two.slot);
  EXPECT_EQ(col_one, col_two);
  // Each colour's packs: ceil(size / 8), in order.
  ASSERT_EQ(col_one.size(), col.size());
  for (size_t c = 0; c + 1 < col.size(); ++c)
    EXPECT_EQ(col_one[c + 1] - col_one[c], (col[c + 1] - col[c] + L - 1) / L) << "colour " << c;
  for (size_t c = 0; c + 1 < col.size(); ++c) {
    const int cnt = col_one[c + 1] - col_one[c];
    for (int p = col_one[c]; p < col_one[c + 1]; ++p) {
      const int pad = kScratch + share_of(p - col_one[c], cnt, kShares);
      int longest = 0;  // the pack's entries: its longest block's
      for (int r = col[c] + L * (p - col_one[c]);
           r < std::min(col[c + 1], col[c] + L * (p + 1 - col_one[c])); ++r)
        longest = std::max(longest, boff[r + 1] - boff[r]);
      EXPECT_EQ(two.off[p + 1] - two.off[p], longest) << "pack " << p;
      for (int l = 0; l < L; ++l) {
        const int r = col[c] + L * (p - col_one[c]) + l;
        const bool real = r < col[c + 1];
        ASSERT_EQ(two.blk[L * p + l], real ? r : -1) << "pack " << p << " lane " << l;
        if (real) {
          EXPECT_EQ(two.slot[r], L * p + l);
          for (int a = 0; a < 3; ++a)
            EXPECT_EQ(two.ik[3 * L * p + L * a + l], static_cast<float>(bik[3 * r + a]));
        }
        const int len = real ? boff[r + 1] - boff[r] : 0;
        for (int i = two.off[p]; i < two.off[p + 1]; ++i) {
          const int e = i - two.off[p];
          const bool entry = e < len;
          EXPECT_EQ(two.colv[L * i + l], entry ? bcol[boff[r] + e] : pad)
              << "pack " << p << " lane " << l << " entry " << e;
          for (int a = 0; a < 3; ++a)
            EXPECT_EQ(two.val[3 * L * i + L * a + l],
                      entry ? static_cast<float>(bval[3 * (boff[r] + e) + a]) : 0.0f);
        }
      }
    }
  }
}

TEST(XpbdKernels, TheFastestBuildTheCpuRunsIsChosen) {
  const std::vector<const Kernels*> builds = all_kernels();
  ASSERT_FALSE(builds.empty());
  EXPECT_STREQ(builds.front()->name, "portable");
  EXPECT_EQ(builds.front(), &kernels(false));
  EXPECT_EQ(builds.back(), &kernels(true));
  const char* env = std::getenv("DRAPE_XPBD_SIMD");
  const std::string cap = env ? env : "";
  if (cap == "0") {
    EXPECT_EQ(builds.size(), 1u);
  }
  for (size_t k = 1; k < builds.size(); ++k) {
    EXPECT_STRNE(builds[k]->name, builds[k - 1]->name);
    if (cap == "avx2") {
      EXPECT_STREQ(builds[k]->name, "avx2");
    }
  }
  // Triangle widths: sixteen only from the AVX-512 build.
  for (const Kernels* K : builds)
    EXPECT_EQ(K->tri_lanes, std::string(K->name) == "avx512" ? 16 : 8) << K->name;
  std::printf("builds this CPU runs:");
  for (const Kernels* K : builds) std::printf(" %s", K->name);
  std::printf("; chosen: %s\n", kernels(true).name);
}

TEST(XpbdKernels, SimdBuildAgreesWithThePortableOne) {
  const std::vector<const Kernels*> builds = all_kernels();
  // (With only the portable build, on a CPU without AVX2 or with DRAPE_XPBD_SIMD=0, there is
  // nothing to compare: TheFastestBuildTheCpuRunsIsChosen checks that case.)
  const Kernels& ref = *builds[0];
  EXPECT_EQ(&ref, &kernels(false));
  const Problem p = make_problem(11);
  for (size_t k = 1; k < builds.size(); ++k) {
    const Kernels& fast = *builds[k];
    Packed a = pack_problem(p), b = pack_problem(p);
    for (int it = 0; it < 3; ++it) {
      fast.tris(a.tp.data(), 0, static_cast<int>(a.tp.size()), a.xp.data(), kIh2, nullptr);
      ref.tris(b.tp.data(), 0, static_cast<int>(b.tp.size()), b.xp.data(), kIh2, nullptr);
      fast.rows(a.rp.view(), 0, a.rp.packs(), a.xp.data(), kIhb, nullptr);
      ref.rows(b.rp.view(), 0, b.rp.packs(), b.xp.data(), kIhb, nullptr);
    }
    double d = 0;
    for (size_t i = 0; i < a.xp.size(); ++i)
      for (int c = 0; c < 4; ++c) d = std::max(d, std::abs(a.xp[i].c[c] - b.xp[i].c[c]));
    std::printf("%s vs portable: positions differ by %.3e\n", fast.name, d);
    EXPECT_LT(d, 1e-12);
  }
}

// The problem in single precision: positions moved to `offset` (metres away from the origin,
// as a cloth on a dress form is), anchored at the positions they start from (as at a frame's
// start), with the elements' terms at the anchors.
template <int L>
struct PackedF {
  std::vector<double> x;  // the double state (3 per vertex) that unpack8 updates
  std::vector<double> a;  // the anchors
  std::vector<P4f> xp;
  std::vector<TriPackT<float, L>> tp;
  RowPackDataT<float, L> rp;
  std::vector<float> fa, ca;
  // The kernels of this width.
  void tris(const Kernels& K, double* lambda) {
    if constexpr (L == 16)
      K.tris16(tp.data(), fa.data(), 0, static_cast<int>(tp.size()), xp.data(), kIh2, lambda);
    else
      K.tris8(tp.data(), fa.data(), 0, static_cast<int>(tp.size()), xp.data(), kIh2, lambda);
  }
  void rows(const Kernels& K, double* lambda) {
    if constexpr (L == 16)
      K.rows16(rp.view(), ca.data(), 0, rp.packs(), xp.data(), kIhb, lambda);
    else
      K.rows8(rp.view(), ca.data(), 0, rp.packs(), xp.data(), kIhb, lambda);
  }
};
template <int L>
PackedF<L> pack_problem_f(const Problem& p, const Kernels& K, const double* offset) {
  PackedF<L> k;
  k.x.resize(3 * p.n);
  for (int i = 0; i < p.n; ++i)
    for (int c = 0; c < 3; ++c) k.x[3 * i + c] = p.x[i][c] + offset[c];
  k.a = k.x;
  k.a.resize(3 * (p.n + 1), 0.0);  // the scratch vertex's anchor
  k.xp.assign(p.n + 1, P4f{{0, 0, 0, 0}});
  K.pack8(k.x.data(), p.w.data(), k.a.data(), k.xp.data(), 0, p.n);
  pack_triangles<float, L>(p.tris.data(), 0, static_cast<int>(p.tris.size()), p.n, k.tp);
  const int nb = static_cast<int>(p.off.size()) - 1;
  std::vector<int> pack_col;
  k.rp.assign(p.off.data(), p.colv.data(), p.val.data(), p.ik.data(), {0, nb}, p.n, 1, nullptr,
              pack_col);
  for (int r = 0; r < nb; ++r)
    for (int m = 0; m < 6; ++m) k.rp.ai_of(r, m) = static_cast<float>(p.ai[6 * r + m]);
  k.fa.resize(6 * L * k.tp.size());
  k.ca.resize(9 * L * static_cast<size_t>(k.rp.packs()));
  if constexpr (L == 16) {
    K.anchor_triangles16(k.tp.data(), 0, static_cast<int>(k.tp.size()), k.a.data(), k.fa.data());
    K.anchor_rows16(k.rp.view(), 0, k.rp.packs(), k.a.data(), k.ca.data());
  } else {
    K.anchor_triangles(k.tp.data(), 0, static_cast<int>(k.tp.size()), k.a.data(), k.fa.data());
    K.anchor_rows(k.rp.view(), 0, k.rp.packs(), k.a.data(), k.ca.data());
  }
  return k;
}

// The single-precision kernels (eight or sixteen elements per pack, floats for the displacements
// from the anchors, the state kept in double by unpack8) do what the double reference does, to
// float round-off of the displacements, with the cloth a metre and more from the coordinate
// origin; every build, both widths.
template <int L>
void check_single_precision_against_double() {
  const double offset[3] = {-0.7, 1.3, 0.45};  // a cloth at a dress form's chest
  for (const Kernels* K : all_kernels())
    for (bool keep : {false, true}) {
      Problem ref = make_problem(7);
      const Problem orig = ref;
      PackedF<L> pk = pack_problem_f<L>(ref, *K, offset);
      // 203 triangles: 25 full packs of eight and one of three (12 of sixteen and one of
      // eleven); 101 blocks: 12 full packs and one of five (6 and one of five).
      EXPECT_EQ(pk.tp.size(), L == 8 ? 26u : 13u);
      EXPECT_EQ(pk.rp.packs(), L == 8 ? 13 : 7);
      std::vector<double> lt_ref(3 * ref.tris.size(), 0.0), lt = lt_ref;
      std::vector<double> lr_ref(9 * (ref.off.size() - 1), 0.0), lr = lr_ref;
      for (int it = 0; it < 3; ++it) {
        reference_tris(ref, kIh2, keep ? lt_ref.data() : nullptr);
        reference_rows(ref, kIhb, keep ? lr_ref.data() : nullptr);
        K->pack8(pk.x.data(), ref.w.data(), pk.a.data(), pk.xp.data(), 0, ref.n);
        pk.tris(*K, keep ? lt.data() : nullptr);
        pk.rows(*K, keep ? lr.data() : nullptr);
        K->unpack8(pk.xp.data(), pk.a.data(), pk.x.data(), 0, ref.n);
      }
      double move = 0, d = 0;
      for (int i = 0; i < ref.n; ++i) {
        move = std::max(move, (ref.x[i] - orig.x[i]).norm());
        for (int c = 0; c < 3; ++c)
          d = std::max(d, std::abs(pk.x[3 * i + c] - offset[c] - ref.x[i][c]));
      }
      double dl = 0, lmax = 0;
      for (size_t k = 0; k < lt.size(); ++k) {
        dl = std::max(dl, std::abs(lt[k] - lt_ref[k]));
        lmax = std::max(lmax, std::abs(lt_ref[k]));
      }
      for (size_t k = 0; k < lr.size(); ++k) {
        dl = std::max(dl, std::abs(lr[k] - lr_ref[k]));
        lmax = std::max(lmax, std::abs(lr_ref[k]));
      }
      std::printf(
          "%s single-precision kernels, %d lanes (multipliers %s): positions moved up to %.3e, "
          "differ from the double reference by %.3e; multipliers by %.3e of up to %.3e\n",
          K->name, L, keep ? "kept" : "reset", move, d, dl, lmax);
      EXPECT_GT(move, 1e-3);
      // Float round-off of the displacements (measured 3.8e-8 m; the moves here reach 0.4 m,
      // a frame's on a cloth a few mm).
      EXPECT_LT(d, 3e-7);
      if (keep) {
        EXPECT_LT(dl, 1e-6 * lmax);                                 // measured 1.2e-7
        for (int c = 0; c < 3; ++c) EXPECT_EQ(lt[3 * 5 + c], 0.0);  // the fixed triangle
      }
      for (int i = 0; i < ref.n; ++i) {
        if (ref.w[i] != 0) continue;  // fixed vertices keep their double positions exactly
        for (int c = 0; c < 3; ++c) EXPECT_EQ(pk.x[3 * i + c], orig.x[i][c] + offset[c]);
      }
      for (int c = 0; c < 4; ++c) EXPECT_EQ(pk.xp[ref.n].c[c], 0.0f);  // the scratch vertex
    }
}
TEST(XpbdKernels, SinglePrecisionPacksProjectLikeTheDoubleReference) {
  check_single_precision_against_double<8>();
}
TEST(XpbdKernels, SixteenLanePacksProjectLikeTheDoubleReference) {
  check_single_precision_against_double<16>();
}

// The two widths run the same arithmetic lane by lane: sixteen-lane packs move the vertices as
// eight-lane packs of the same elements do, in every build.
TEST(XpbdKernels, SixteenLanePacksAgreeWithEightLanePacks) {
  const Problem p = make_problem(5);
  const double offset[3] = {0.3, 1.1, -0.2};
  for (const Kernels* K : all_kernels()) {
    PackedF<8> a = pack_problem_f<8>(p, *K, offset);
    PackedF<16> b = pack_problem_f<16>(p, *K, offset);
    double dfa = 0;  // the anchor terms, element by element
    for (size_t t = 0; t < p.tris.size(); ++t)
      for (int j = 0; j < 6; ++j)
        dfa = std::max(dfa, double(std::abs(a.fa[48 * (t / 8) + 8 * j + t % 8] -
                                            b.fa[96 * (t / 16) + 16 * j + t % 16])));
    EXPECT_EQ(dfa, 0.0) << K->name;
    for (int it = 0; it < 3; ++it) {
      a.tris(*K, nullptr);
      b.tris(*K, nullptr);
      a.rows(*K, nullptr);
      b.rows(*K, nullptr);
    }
    double d = 0;
    for (size_t i = 0; i < a.xp.size(); ++i)
      for (int c = 0; c < 4; ++c) d = std::max(d, double(std::abs(a.xp[i].c[c] - b.xp[i].c[c])));
    std::printf("%s: sixteen-lane packs vs eight-lane packs: positions differ by %.3e\n", K->name,
                d);
    EXPECT_LT(d, 3e-7);  // float round-off at most (FMA contraction may differ by width)
  }
}

// pack8 then unpack8 with nothing moved in between gives back every double bit for bit: the
// float copy's resolution does not leak into the state.
TEST(XpbdKernels, SinglePrecisionRoundTripKeepsTheDoublePositions) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-2, 2);
  const int n = 1000;
  std::vector<double> x(3 * n), w(n, 1.0), y;
  for (double& v : x) v = u(rng);
  y = x;
  std::vector<double> a(3 * n);  // anchors: up to 5 mm away
  for (int i = 0; i < 3 * n; ++i) a[i] = x[i] + 0.005 * std::sin(i);
  for (const Kernels* K : all_kernels()) {
    std::vector<P4f> p(n);
    K->pack8(y.data(), w.data(), a.data(), p.data(), 0, n);
    K->unpack8(p.data(), a.data(), y.data(), 0, n);
    for (int i = 0; i < 3 * n; ++i) ASSERT_EQ(y[i], x[i]) << K->name << " coordinate " << i;
  }
}

TEST(XpbdKernels, SinglePrecisionSimdBuildAgreesWithThePortableOne) {
  const std::vector<const Kernels*> builds = all_kernels();
  // (With only the portable build, on a CPU without AVX2 or with DRAPE_XPBD_SIMD=0, there is
  // nothing to compare: TheFastestBuildTheCpuRunsIsChosen checks that case.)
  const Kernels& ref = *builds[0];
  EXPECT_EQ(&ref, &kernels(false));
  const Problem p = make_problem(11);
  const double offset[3] = {0, 1.2, 0};
  for (size_t k = 1; k < builds.size(); ++k) {
    const Kernels& fast = *builds[k];
    PackedF<8> a = pack_problem_f<8>(p, fast, offset), b = pack_problem_f<8>(p, ref, offset);
    PackedF<16> a16 = pack_problem_f<16>(p, fast, offset), b16 = pack_problem_f<16>(p, ref, offset);
    for (int it = 0; it < 3; ++it) {
      a.tris(fast, nullptr);
      b.tris(ref, nullptr);
      a.rows(fast, nullptr);
      b.rows(ref, nullptr);
      a16.tris(fast, nullptr);
      b16.tris(ref, nullptr);
      a16.rows(fast, nullptr);
      b16.rows(ref, nullptr);
    }
    double d = 0, d16 = 0;
    for (size_t i = 0; i < a.xp.size(); ++i)
      for (int c = 0; c < 4; ++c) {
        d = std::max(d, double(std::abs(a.xp[i].c[c] - b.xp[i].c[c])));
        d16 = std::max(d16, double(std::abs(a16.xp[i].c[c] - b16.xp[i].c[c])));
      }
    std::printf(
        "%s vs portable, single precision: positions differ by %.3e (8 lanes), %.3e (16 lanes)\n",
        fast.name, d, d16);
    EXPECT_LT(d, 3e-7);  // float round-off (FMA contraction) only: measured 3.0e-8
    EXPECT_LT(d16, 3e-7);
  }
}

// A unit right triangle (rest edges along u and v) stretched by 10 % along u, vertex 0 fixed:
// with zero compliance one projection is a Newton step on E_uu = (|fu|^2 - 1) / 2 = 0.105 with
// S_uu = 1 (only vertex 1 carries fu), so fu scales by 1 + dl with dl = -0.105 / 1.21 exactly;
// E_vv and E_uv are 0 and stay so.
TEST(XpbdKernels, OneProjectionRemovesTheStretchOfATriangle) {
  for (const Kernels* k : all_kernels()) {
    // Vertices 0..2 (w = 0, 1, 1) and the scratch vertex 3 of the three padding lanes.
    std::vector<P4> x{P4{{0, 0, 0, 0}}, P4{{1.1, 0, 0, 1}}, P4{{0, 1, 0, 1}}, P4{{0, 0, 0, 0}}};
    Tri T{};
    T.v[0] = 0;
    T.v[1] = 1;
    T.v[2] = 2;
    // fu = x1 - x0, fv = x2 - x0.
    const double D[6] = {-1, -1, 1, 0, 0, 1};
    std::copy(D, D + 6, T.D);
    std::vector<TriPack> packs;
    pack_triangles(&T, 0, 1, 3, packs);
    ASSERT_EQ(packs.size(), 1u);
    const double eu0 = 0.5 * (1.1 * 1.1 - 1);
    k->tris(packs.data(), 0, 1, x.data(), 1.0, nullptr);  // ia = 0: no compliance
    const double fu[3] = {x[1].c[0] - x[0].c[0], x[1].c[1] - x[0].c[1], x[1].c[2] - x[0].c[2]};
    const double eu = 0.5 * (fu[0] * fu[0] + fu[1] * fu[1] + fu[2] * fu[2] - 1);
    std::printf("%s: E_uu %.4f -> %.2e, vertex 1 at x = %.5f\n", k->name, eu0, eu, x[1].c[0]);
    EXPECT_NEAR(x[1].c[0], 1.1 * (1 - eu0 / 1.21), 1e-14);
    EXPECT_LT(std::abs(eu), 0.05 * eu0);  // what is left is second order: |dl fu|^2 / 2
    EXPECT_EQ(x[0].c[0], 0.0);
    EXPECT_EQ(x[1].c[1], 0.0);
    EXPECT_EQ(x[2].c[0], 0.0);
    EXPECT_EQ(x[2].c[1], 1.0);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(x[3].c[c], 0.0);  // padding moved nothing
  }
}

// The solver's per-vertex steps (Kernels::predict, velocities, motion) in every build give what
// the solver's own loops give (written below as they are in solver_xpbd.cpp, with Eigen
// vectors), bit for bit: free, fixed (w = 0) and frozen vertices, settling scale 3.
TEST(XpbdKernels, PredictionVelocitiesAndMotionSumsAreTheSolversOwnBitForBit) {
  using Vec3 = Eigen::Vector3d;
  const int n = 203;  // not a multiple of any vector width
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> x(n), v(n);
  std::vector<double> w(n), mass(n);
  std::vector<uint8_t> flags(n, 0);
  const uint8_t kFrozen = 1u << 5;
  for (int i = 0; i < n; ++i) {
    // (Positions near 0, about as large as a substep's move: a round-off in the move shows.)
    x[i] = Vec3(1e-3 * u(rng), 1e-3 * u(rng), 1e-3 * u(rng));
    v[i] = Vec3(u(rng), u(rng), u(rng));
    mass[i] = 1e-4 * (1.5 + u(rng));
    w[i] = i % 7 == 0 ? 0.0 : 1.0 / mass[i];
    if (i % 11 == 0) flags[i] = kFrozen;
  }
  const double scale = 3.0, h = 1.0 / 900, damp = 0.999;
  const Vec3 g(0, -9.81, 0);
  // The solver's loops.
  std::vector<Vec3> xr = x, xpr(n), vr = v;
  for (int i = 0; i < n; ++i) {
    xpr[i] = xr[i];
    if (!(w[i] > 0)) continue;
    const double m = mass[i];
    const Vec3 f(m * g);
    xr[i] += h * vr[i] + (h * h / (scale * m)) * f;
  }
  const std::vector<Vec3> predicted = xr;
  // (Then moved as the constraints would, for the velocities.)
  for (int i = 0; i < n; ++i) xr[i] += Vec3(1e-4 * u(rng), 1e-4 * u(rng), 1e-4 * u(rng));
  const std::vector<Vec3> moved = xr;
  for (int i = 0; i < n; ++i) {
    if (w[i] > 0)
      vr[i] = (damp / h) * (xr[i] - xpr[i]);
    else if (flags[i] & kFrozen)
      vr[i].setZero();
  }
  for (const Kernels* K : all_kernels()) {
    std::vector<Vec3> xk = x, xpk(n, Vec3::Constant(7)), vk = v;
    K->predict(xk[0].data(), xpk[0].data(), vk[0].data(), w.data(), mass.data(), scale, h, g.data(),
               0, n);
    int pred_same = 0;
    for (int i = 0; i < n; ++i) pred_same += xk[i] == predicted[i] && xpk[i] == xpr[i];
    EXPECT_EQ(pred_same, n) << K->name;
    K->velocities(moved[0].data(), xpr[0].data(), vk[0].data(), w.data(), flags.data(), kFrozen,
                  damp, h, 0, n);
    int vel_same = 0;
    for (int i = 0; i < n; ++i) vel_same += vk[i] == vr[i];
    EXPECT_EQ(vel_same, n) << K->name;
    // The motion sums, as the solver's loop sums them (Eigen's squaredNorm).
    const double slow2 = 0.25;
    double ref[4] = {0, 0, 0, 0};
    int free = 0;
    for (int i = 0; i < n; ++i) {
      if (!(w[i] > 0)) continue;
      ++free;
      const double v2 = vr[i].squaredNorm(), m = mass[i];
      ref[0] = std::max(ref[0], v2);
      ref[1] += m * v2;
      ref[2] += m * std::min(v2, slow2);
      ref[3] += m;
    }
    double sums[4];
    EXPECT_EQ(K->motion(vk[0].data(), w.data(), mass.data(), slow2, 0, n, sums), free) << K->name;
    for (int j = 0; j < 4; ++j) EXPECT_EQ(sums[j], ref[j]) << K->name << " sum " << j;
  }
}

}  // namespace
}  // namespace drape::sim::xpbd
