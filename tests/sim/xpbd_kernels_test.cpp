// XPBD's hot loops (sim/xpbd_kernels.hpp): the AVX2 build agrees with the portable one, and a
// triangle projection does what the constraint says.
#include "sim/xpbd_kernels.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace drape::sim::xpbd {
namespace {

constexpr double kIh2 = 1e4, kIhb = 5e3;  // 1 / h^2 for the triangles and bending blocks

struct Problem {
  std::vector<P4> x;
  std::vector<double> w;
  std::vector<Tri> tris;
  std::vector<int> off{0}, colv;
  std::vector<double> val, ik, ai;
};

// Random but well-posed data: positions in the unit cube, some vertices fixed (w = 0),
// triangles and bending blocks over distinct vertices with compliances that keep every
// denominator away from zero, and a symmetric positive definite "inverse" per block.
Problem make_problem(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1), s(-5, 5);
  const int n = 300;
  Problem p;
  p.x.resize(n);
  p.w.resize(n);
  for (int i = 0; i < n; ++i) {
    p.x[i] = P4{{u(rng), u(rng), u(rng), 0}};
    p.w[i] = i % 7 == 0 ? 0.0 : 0.5 + u(rng);
  }
  std::uniform_int_distribution<int> vi(0, n - 1);
  auto distinct = [&](int k) {
    std::vector<int> v;
    while (static_cast<int>(v.size()) < k) {
      const int c = vi(rng);
      if (std::find(v.begin(), v.end(), c) == v.end()) v.push_back(c);
    }
    return v;
  };
  for (int t = 0; t < 200; ++t) {
    Tri T{};
    const auto v = distinct(3);
    for (int a = 0; a < 3; ++a) {
      T.v[a] = v[a];
      T.ia[a] = 0.1 + u(rng);
    }
    for (double& d : T.D) d = s(rng);
    p.tris.push_back(T);
  }
  std::uniform_int_distribution<int> len(3, 12);
  for (int r = 0; r < 100; ++r) {
    for (int c : distinct(len(rng))) {
      p.colv.push_back(c);
      for (int a = 0; a < 3; ++a) p.val.push_back(s(rng));
    }
    p.off.push_back(static_cast<int>(p.colv.size()));
    for (int a = 0; a < 3; ++a) p.ik.push_back(0.1 + u(rng));
  }
  // Each block's inverse system matrix as the solver builds it: A = sum_j w_j v_j v_j^T +
  // diag(ihb ik).
  for (size_t r = 0; r + 1 < p.off.size(); ++r) {
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

double max_diff(const std::vector<P4>& a, const std::vector<P4>& b) {
  double m = 0;
  for (size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 4; ++c) m = std::max(m, std::abs(a[i].c[c] - b[i].c[c]));
  return m;
}

TEST(XpbdKernels, SimdBuildAgreesWithThePortableOne) {
  const Kernels& fast = kernels(true);
  const Kernels& ref = kernels(false);
  EXPECT_STREQ(ref.name, "portable");
  if (fast.tris == ref.tris)
    GTEST_SKIP() << "this CPU (or DRAPE_XPBD_SIMD=0) has only the portable kernels";
  for (bool keep : {false, true}) {
    Problem a = make_problem(7), b = make_problem(7);
    const double ih2 = kIh2, ihb = kIhb;
    std::vector<double> lt_a(3 * a.tris.size(), 0.0), lt_b = lt_a;
    std::vector<double> lr_a(9 * (a.off.size() - 1), 0.0), lr_b = lr_a;
    const Problem orig = make_problem(7);
    for (int it = 0; it < 3; ++it) {
      const RowBlocks ra{a.off.data(), a.colv.data(), a.val.data(), a.ik.data(), a.ai.data()};
      const RowBlocks rb{b.off.data(), b.colv.data(), b.val.data(), b.ik.data(), b.ai.data()};
      const int nt = static_cast<int>(a.tris.size()), nr = static_cast<int>(a.off.size()) - 1;
      fast.tris(a.tris.data(), 0, nt, a.w.data(), a.x.data(), ih2, keep ? lt_a.data() : nullptr);
      ref.tris(b.tris.data(), 0, nt, b.w.data(), b.x.data(), ih2, keep ? lt_b.data() : nullptr);
      fast.rows(ra, 0, nr, a.w.data(), a.x.data(), ihb, keep ? lr_a.data() : nullptr);
      ref.rows(rb, 0, nr, b.w.data(), b.x.data(), ihb, keep ? lr_b.data() : nullptr);
    }
    const double move = max_diff(a.x, orig.x);
    const double d = max_diff(a.x, b.x);
    std::printf("%s vs portable (multipliers %s): positions moved up to %.3e, differ by %.3e\n",
                fast.name, keep ? "kept" : "reset", move, d);
    EXPECT_GT(move, 1e-3);  // the projections did move the vertices
    EXPECT_LT(d, 1e-12);    // round-off (FMA contraction) only
    for (size_t i = 0; i < a.x.size(); ++i) {
      EXPECT_EQ(a.x[i].c[3], 0.0);  // the padding lane stays 0
      if (a.w[i] == 0) {            // fixed vertices do not move
        for (int c = 0; c < 3; ++c) EXPECT_EQ(a.x[i].c[c], orig.x[i].c[c]);
      }
    }
    if (keep) {
      double dl = 0;
      for (size_t k = 0; k < lt_a.size(); ++k) dl = std::max(dl, std::abs(lt_a[k] - lt_b[k]));
      for (size_t k = 0; k < lr_a.size(); ++k) dl = std::max(dl, std::abs(lr_a[k] - lr_b[k]));
      EXPECT_LT(dl, 1e-9);
    }
  }
}

// A unit right triangle (rest edges along u and v) stretched by 10 % along u, vertex 0 fixed:
// with zero compliance one projection is a Newton step on E_uu = (|fu|^2 - 1) / 2 = 0.105 with
// S_uu = 1 (only vertex 1 carries fu), so fu scales by 1 + dl with dl = -0.105 / 1.21 exactly;
// E_vv and E_uv are 0 and stay so.
TEST(XpbdKernels, OneProjectionRemovesTheStretchOfATriangle) {
  for (const Kernels* k : {&kernels(false), &kernels(true)}) {
    std::vector<P4> x{P4{{0, 0, 0, 0}}, P4{{1.1, 0, 0, 0}}, P4{{0, 1, 0, 0}}};
    const std::vector<double> w{0.0, 1.0, 1.0};
    Tri T{};
    T.v[0] = 0;
    T.v[1] = 1;
    T.v[2] = 2;
    // fu = x1 - x0, fv = x2 - x0.
    const double D[6] = {-1, -1, 1, 0, 0, 1};
    std::copy(D, D + 6, T.D);
    const double eu0 = 0.5 * (1.1 * 1.1 - 1);
    k->tris(&T, 0, 1, w.data(), x.data(), 1.0, nullptr);  // ia = 0: no compliance
    const double fu[3] = {x[1].c[0] - x[0].c[0], x[1].c[1] - x[0].c[1], x[1].c[2] - x[0].c[2]};
    const double eu = 0.5 * (fu[0] * fu[0] + fu[1] * fu[1] + fu[2] * fu[2] - 1);
    std::printf("%s: E_uu %.4f -> %.2e, vertex 1 at x = %.5f\n", k->name, eu0, eu, x[1].c[0]);
    EXPECT_NEAR(x[1].c[0], 1.1 * (1 - eu0 / 1.21), 1e-14);
    EXPECT_LT(std::abs(eu), 0.05 * eu0);  // what is left is second order: |dl fu|^2 / 2
    EXPECT_EQ(x[0].c[0], 0.0);
    EXPECT_EQ(x[1].c[1], 0.0);
    EXPECT_EQ(x[2].c[0], 0.0);
    EXPECT_EQ(x[2].c[1], 1.0);
  }
}

}  // namespace
}  // namespace drape::sim::xpbd
