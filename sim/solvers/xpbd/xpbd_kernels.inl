// The body of XPBD's hot loops (sim/solvers/xpbd/xpbd_kernels.hpp), included once per instruction
// set by sim/solvers/xpbd/xpbd_kernels.cpp (portable) and sim/solvers/xpbd/xpbd_kernels_avx2.cpp
// (AVX2+FMA) inside a namespace of their own. Values are GCC/Clang vector-extension vectors, one
// element per lane: four doubles or eight floats, which the compiler maps to one AVX register or to
// two SSE2 ones. Each kernel is written once over a lane type (Dbl4, Flt8, Flt16 below) and
// instantiated for each.

#if defined(__GNUC__) && !defined(__clang__)
// The helpers below take and return vectors by value; GCC notes that this ABI differs between
// units with and without AVX. They are inlined and never called across units.
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
// m ? a : b, lane by lane (m: a lane-wise comparison, all 0 or all 1 bits).
template <class V, class M>
inline V sel(M m, V a, V b) {
  return reinterpret_cast<V>((reinterpret_cast<M>(a) & m) | (reinterpret_cast<M>(b) & ~m));
}
template <class V>
struct LanesOf {
  V X, Y, Z, W;
};
using D4 = double __attribute__((vector_size(32)));
using M4 = long long __attribute__((vector_size(32)));  // a lane-wise comparison: all 0 or 1 bits

inline D4 ld(const double* p) {  // any alignment (the packs' arrays are std::vector<double>)
  D4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline D4 ld(const P4& p) {  // 32-byte aligned
  return *reinterpret_cast<const D4*>(p.c);
}
inline void st(P4& p, D4 v) {
  *reinterpret_cast<D4*>(p.c) = v;
}

// 4x4 transpose: rows r0..r3 in, columns out (its own inverse).
inline void transpose(D4 r0, D4 r1, D4 r2, D4 r3, D4& a, D4& b, D4& c, D4& d) {
  const D4 t0 = __builtin_shufflevector(r0, r1, 0, 4, 2, 6);  // x0 x1 z0 z1
  const D4 t1 = __builtin_shufflevector(r0, r1, 1, 5, 3, 7);  // y0 y1 w0 w1
  const D4 t2 = __builtin_shufflevector(r2, r3, 0, 4, 2, 6);  // x2 x3 z2 z3
  const D4 t3 = __builtin_shufflevector(r2, r3, 1, 5, 3, 7);  // y2 y3 w2 w3
  a = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
  b = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
  c = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
  d = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
}

// The four vertices v[0..3] (one per lane) as x, y, z and inverse mass w.
using Lanes = LanesOf<D4>;
#if defined(__AVX__)
inline Lanes xpbd_gather(const P4* x, const int32_t* v) {
  Lanes g;
  transpose(ld(x[v[0]]), ld(x[v[1]]), ld(x[v[2]]), ld(x[v[3]]), g.X, g.Y, g.Z, g.W);
  return g;
}
#else
// Without AVX a 256-bit shuffle is lowered through memory: element by element is faster.
inline Lanes xpbd_gather(const P4* x, const int32_t* v) {
  const double *a = x[v[0]].c, *b = x[v[1]].c, *c = x[v[2]].c, *d = x[v[3]].c;
  return Lanes{D4{a[0], b[0], c[0], d[0]}, D4{a[1], b[1], c[1], d[1]}, D4{a[2], b[2], c[2], d[2]},
               D4{a[3], b[3], c[3], d[3]}};
}
#endif
// Writes the lanes back. Lanes sharing a vertex (only the scratch vertex of padding, which no
// projection moves) write the same value.
inline void xpbd_scatter(P4* x, const int32_t* v, const Lanes& g) {
#if defined(__AVX__)
  D4 r0, r1, r2, r3;
  transpose(g.X, g.Y, g.Z, g.W, r0, r1, r2, r3);
  st(x[v[0]], r0);
  st(x[v[1]], r1);
  st(x[v[2]], r2);
  st(x[v[3]], r3);
#else
  for (int l = 0; l < 4; ++l) {  // (the fourth lane, w, is never changed)
    double* p = x[v[l]].c;
    p[0] = g.X[l];
    p[1] = g.Y[l];
    p[2] = g.Z[l];
  }
#endif
}

// Single precision: eight elements per pack (XpbdOptions::single_precision).
using F8 = float __attribute__((vector_size(32)));
using F4 = float __attribute__((vector_size(16)));
using M8 = int __attribute__((vector_size(32)));

inline F8 ld8(const float* p) {
  F8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline F4 ld4(const P4f& p) {  // 16-byte aligned
  return *reinterpret_cast<const F4*>(p.c);
}
inline void st4(P4f& p, F4 v) {
  *reinterpret_cast<F4*>(p.c) = v;
}

// Four rows, each [vertex l | vertex l + 4] as (x, y, z, w | x, y, z, w), to the columns
// X = (x0 .. x7), Y, Z, W: a 4x4 transpose inside each 128-bit half (its own inverse). With
// AVX these are in-lane shuffles; without, each half is one SSE register.
inline void transpose8(F8 a, F8 b, F8 c, F8 d, F8& X, F8& Y, F8& Z, F8& W) {
  const F8 t0 = __builtin_shufflevector(a, b, 0, 8, 1, 9, 4, 12, 5, 13);
  const F8 t1 = __builtin_shufflevector(a, b, 2, 10, 3, 11, 6, 14, 7, 15);
  const F8 t2 = __builtin_shufflevector(c, d, 0, 8, 1, 9, 4, 12, 5, 13);
  const F8 t3 = __builtin_shufflevector(c, d, 2, 10, 3, 11, 6, 14, 7, 15);
  X = __builtin_shufflevector(t0, t2, 0, 1, 8, 9, 4, 5, 12, 13);
  Y = __builtin_shufflevector(t0, t2, 2, 3, 10, 11, 6, 7, 14, 15);
  Z = __builtin_shufflevector(t1, t3, 0, 1, 8, 9, 4, 5, 12, 13);
  W = __builtin_shufflevector(t1, t3, 2, 3, 10, 11, 6, 7, 14, 15);
}

using Lanes8 = LanesOf<F8>;
inline F8 join(F4 a, F4 b) {
  return __builtin_shufflevector(a, b, 0, 1, 2, 3, 4, 5, 6, 7);
}
inline Lanes8 gather8(const P4f* x, const int32_t* v) {
  Lanes8 g;
  transpose8(join(ld4(x[v[0]]), ld4(x[v[4]])), join(ld4(x[v[1]]), ld4(x[v[5]])),
             join(ld4(x[v[2]]), ld4(x[v[6]])), join(ld4(x[v[3]]), ld4(x[v[7]])), g.X, g.Y, g.Z,
             g.W);
  return g;
}
// Lanes sharing a vertex (only padding's scratch vertex, which no projection moves) write the
// same value.
inline void scatter8(P4f* x, const int32_t* v, const Lanes8& g) {
  F8 a, b, c, d;
  transpose8(g.X, g.Y, g.Z, g.W, a, b, c, d);
  st4(x[v[0]], __builtin_shufflevector(a, a, 0, 1, 2, 3));
  st4(x[v[4]], __builtin_shufflevector(a, a, 4, 5, 6, 7));
  st4(x[v[1]], __builtin_shufflevector(b, b, 0, 1, 2, 3));
  st4(x[v[5]], __builtin_shufflevector(b, b, 4, 5, 6, 7));
  st4(x[v[2]], __builtin_shufflevector(c, c, 0, 1, 2, 3));
  st4(x[v[6]], __builtin_shufflevector(c, c, 4, 5, 6, 7));
  st4(x[v[3]], __builtin_shufflevector(d, d, 0, 1, 2, 3));
  st4(x[v[7]], __builtin_shufflevector(d, d, 4, 5, 6, 7));
}

// Sixteen floats per pack (the AVX-512 build's width; the other builds compile the same code,
// which GCC lowers to two AVX or four SSE registers per vector).
using F16 = float __attribute__((vector_size(64)));
// GCC does not inline the sixteen-lane gather and scatter on its own (they are long): a call
// spills every accumulator of the bending kernel.
#define XPBD_INLINE inline __attribute__((always_inline))

XPBD_INLINE F16 ld16(const float* p) {
  F16 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
// transpose8 on four 128-bit quarters: rows [v_l | v_l+4 | v_l+8 | v_l+12] to X = (x0 .. x15),
// Y, Z, W (its own inverse).
XPBD_INLINE void transpose16(F16 a, F16 b, F16 c, F16 d, F16& X, F16& Y, F16& Z, F16& W) {
  const F16 t0 =
      __builtin_shufflevector(a, b, 0, 16, 1, 17, 4, 20, 5, 21, 8, 24, 9, 25, 12, 28, 13, 29);
  const F16 t1 =
      __builtin_shufflevector(a, b, 2, 18, 3, 19, 6, 22, 7, 23, 10, 26, 11, 27, 14, 30, 15, 31);
  const F16 t2 =
      __builtin_shufflevector(c, d, 0, 16, 1, 17, 4, 20, 5, 21, 8, 24, 9, 25, 12, 28, 13, 29);
  const F16 t3 =
      __builtin_shufflevector(c, d, 2, 18, 3, 19, 6, 22, 7, 23, 10, 26, 11, 27, 14, 30, 15, 31);
  X = __builtin_shufflevector(t0, t2, 0, 1, 16, 17, 4, 5, 20, 21, 8, 9, 24, 25, 12, 13, 28, 29);
  Y = __builtin_shufflevector(t0, t2, 2, 3, 18, 19, 6, 7, 22, 23, 10, 11, 26, 27, 14, 15, 30, 31);
  Z = __builtin_shufflevector(t1, t3, 0, 1, 16, 17, 4, 5, 20, 21, 8, 9, 24, 25, 12, 13, 28, 29);
  W = __builtin_shufflevector(t1, t3, 2, 3, 18, 19, 6, 7, 22, 23, 10, 11, 26, 27, 14, 15, 30, 31);
}
using Lanes16 = LanesOf<F16>;
XPBD_INLINE F16 join4(F4 a, F4 b, F4 c, F4 d) {
  return __builtin_shufflevector(join(a, b), join(c, d), 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12,
                                 13, 14, 15);
}
#if defined(__AVX512F__)
// Four vertices into the four quarters of one register: a load and three inserts from memory
// (which, unlike a shuffle of registers, do not need the shuffle port).
XPBD_INLINE F16 load4x4(const P4f& a, const P4f& b, const P4f& c, const P4f& d) {
  __m512 r = _mm512_zextps128_ps512(_mm_load_ps(a.c));
  r = _mm512_insertf32x4(r, _mm_load_ps(b.c), 1);
  r = _mm512_insertf32x4(r, _mm_load_ps(c.c), 2);
  r = _mm512_insertf32x4(r, _mm_load_ps(d.c), 3);
  return reinterpret_cast<F16>(r);
}
#else
XPBD_INLINE F16 load4x4(const P4f& a, const P4f& b, const P4f& c, const P4f& d) {
  return join4(ld4(a), ld4(b), ld4(c), ld4(d));
}
#endif
XPBD_INLINE Lanes16 gather16(const P4f* x, const int32_t* v) {
  Lanes16 g;
  transpose16(load4x4(x[v[0]], x[v[4]], x[v[8]], x[v[12]]),
              load4x4(x[v[1]], x[v[5]], x[v[9]], x[v[13]]),
              load4x4(x[v[2]], x[v[6]], x[v[10]], x[v[14]]),
              load4x4(x[v[3]], x[v[7]], x[v[11]], x[v[15]]), g.X, g.Y, g.Z, g.W);
  return g;
}
// Quarter q of a (four floats).
template <int q>
XPBD_INLINE F4 quarter(F16 a) {
  return __builtin_shufflevector(a, a, 4 * q, 4 * q + 1, 4 * q + 2, 4 * q + 3);
}
// As scatter8: lanes sharing a vertex (only padding's scratch vertex) write the same value.
XPBD_INLINE void scatter16(P4f* x, const int32_t* v, const Lanes16& g) {
  F16 r[4];
  transpose16(g.X, g.Y, g.Z, g.W, r[0], r[1], r[2], r[3]);
  for (int l = 0; l < 4; ++l) {
#if defined(__AVX512F__)
    const __m512 q = reinterpret_cast<__m512>(r[l]);
    _mm_store_ps(x[v[l]].c, _mm512_castps512_ps128(q));
    _mm_store_ps(x[v[l + 4]].c, _mm512_extractf32x4_ps(q, 1));
    _mm_store_ps(x[v[l + 8]].c, _mm512_extractf32x4_ps(q, 2));
    _mm_store_ps(x[v[l + 12]].c, _mm512_extractf32x4_ps(q, 3));
#else
    st4(x[v[l]], quarter<0>(r[l]));
    st4(x[v[l + 4]], quarter<1>(r[l]));
    st4(x[v[l + 8]], quarter<2>(r[l]));
    st4(x[v[l + 12]], quarter<3>(r[l]));
#endif
  }
}

// The lane types: vector, scalar, lanes, padded position, packs, loads, gather and scatter.
struct Dbl4 {
  static constexpr bool kAnchored = false;  // absolute positions
  using V = D4;
  using S = double;
  static constexpr int L = 4;
  using PX = P4;
  using TriPackType = TriPack;
  static V load(const double* p) { return ld(p); }
  static Lanes gather(const P4* x, const int32_t* v) { return xpbd_gather(x, v); }
  static void scatter(P4* x, const int32_t* v, const Lanes& g) { xpbd_scatter(x, v, g); }
};
struct Flt8 {
  static constexpr bool kAnchored = true;  // displacements from anchors (Kernels::tris8)
  using V = F8;
  using S = float;
  static constexpr int L = 8;
  using PX = P4f;
  using TriPackType = TriPack8;
  static V load(const float* p) { return ld8(p); }
  static Lanes8 gather(const P4f* x, const int32_t* v) { return gather8(x, v); }
  static void scatter(P4f* x, const int32_t* v, const Lanes8& g) { scatter8(x, v, g); }
};
struct Flt16 {
  static constexpr bool kAnchored = true;
  using V = F16;
  using S = float;
  static constexpr int L = 16;
  using PX = P4f;
  using TriPackType = TriPack16;
  XPBD_INLINE static V load(const float* p) { return ld16(p); }
  XPBD_INLINE static Lanes16 gather(const P4f* x, const int32_t* v) { return gather16(x, v); }
  XPBD_INLINE static void scatter(P4f* x, const int32_t* v, const Lanes16& g) {
    scatter16(x, v, g);
  }
};

// The three strain constraints of a triangle (E_uu, E_vv, E_uv) are projected one after the
// other as in classic XPBD, but in the space of F = (fu, fv): every gradient is
// w_q (D_uq a + D_vq b) for vectors a, b, so each projection changes F by a closed form
// (S_uu, S_vv, S_uv below) and the vertices are moved once, by the sum. Each lane is one
// triangle; a lane whose denominator vanishes (all vertices fixed, padding) changes nothing.
// F is formed from the edges, (x1 - x0) D_1 + (x2 - x0) D_2 (D_0 = -D_1 - D_2); in single
// precision from the displacements' edges plus F at the anchors.
template <class T>
void tris_impl(const typename T::TriPackType* packs, const typename T::S* fa, int b, int e,
               typename T::PX* x, double ih2d, double* lambda) {
  using V = typename T::V;
  using S = typename T::S;
  constexpr int L = T::L;
  const V zero = V{} + S(0), one = zero + S(1), half = zero + S(0.5), tiny = zero + S(1e-20);
  const S ih2 = static_cast<S>(ih2d);
  for (int p = b; p < e; ++p) {
    const auto& P = packs[p];
    LanesOf<V> g[3];
    V Du[3], Dv[3];
    for (int q = 0; q < 3; ++q) {
      g[q] = T::gather(x, P.v[q]);
      Du[q] = T::load(P.D[2 * q]);
      Dv[q] = T::load(P.D[2 * q + 1]);
    }
    const V e1x = g[1].X - g[0].X, e1y = g[1].Y - g[0].Y, e1z = g[1].Z - g[0].Z;
    const V e2x = g[2].X - g[0].X, e2y = g[2].Y - g[0].Y, e2z = g[2].Z - g[0].Z;
    V fux = e1x * Du[1] + e2x * Du[2], fuy = e1y * Du[1] + e2y * Du[2],
      fuz = e1z * Du[1] + e2z * Du[2];
    V fvx = e1x * Dv[1] + e2x * Dv[2], fvy = e1y * Dv[1] + e2y * Dv[2],
      fvz = e1z * Dv[1] + e2z * Dv[2];
    if constexpr (T::kAnchored) {  // + F at the anchors
      const S* A = fa + 6 * L * p;
      fux += T::load(A), fuy += T::load(A + L), fuz += T::load(A + 2 * L);
      fvx += T::load(A + 3 * L), fvy += T::load(A + 4 * L), fvz += T::load(A + 5 * L);
    }
    const V Suu = g[0].W * Du[0] * Du[0] + g[1].W * Du[1] * Du[1] + g[2].W * Du[2] * Du[2];
    const V Svv = g[0].W * Dv[0] * Dv[0] + g[1].W * Dv[1] * Dv[1] + g[2].W * Dv[2] * Dv[2];
    const V Suv = g[0].W * Du[0] * Dv[0] + g[1].W * Du[1] * Dv[1] + g[2].W * Du[2] * Dv[2];
    const auto live = (g[0].W + g[1].W + g[2].W) > zero;
    V lam[3] = {zero, zero, zero};
    if (lambda)
      for (int l = 0; l < L; ++l)
        if (P.k[l] >= 0)
          for (int c = 0; c < 3; ++c) lam[c][l] = static_cast<S>(lambda[3 * P.k[l] + c]);
    // dl = (num - alpha lam) / denom where the lane is live and denom is not ~0, else 0.
    auto solve = [&](V alpha, V num, V denom, int c) {
      const auto ok = (denom >= tiny) & live;
      const V dl = sel(ok, (num - alpha * lam[c]) / sel(ok, denom, one), zero);
      lam[c] += dl;
      return dl;
    };
    V ax = zero, ay = zero, az = zero, bx = zero, by = zero, bz = zero;
    // E_uu = (|fu|^2 - 1) / 2 with gradient D_uq fu: a += dl fu, fv += dl S_uv fu,
    // fu *= 1 + dl S_uu.
    {
      const V alpha = ih2 * T::load(P.ia[0]);
      const V f2 = fux * fux + fuy * fuy + fuz * fuz;
      const V dl = solve(alpha, -half * (f2 - one), alpha + Suu * f2, 0);
      ax += dl * fux, ay += dl * fuy, az += dl * fuz;
      const V cross = dl * Suv, grow = one + dl * Suu;
      fvx += cross * fux, fvy += cross * fuy, fvz += cross * fuz;
      fux *= grow, fuy *= grow, fuz *= grow;
    }
    // E_vv = (|fv|^2 - 1) / 2 with gradient D_vq fv: the same with u and v swapped.
    {
      const V alpha = ih2 * T::load(P.ia[1]);
      const V f2 = fvx * fvx + fvy * fvy + fvz * fvz;
      const V dl = solve(alpha, -half * (f2 - one), alpha + Svv * f2, 1);
      bx += dl * fvx, by += dl * fvy, bz += dl * fvz;
      const V cross = dl * Suv, grow = one + dl * Svv;
      fux += cross * fvx, fuy += cross * fvy, fuz += cross * fvz;
      fvx *= grow, fvy *= grow, fvz *= grow;
    }
    // E_uv = fu . fv / 2, gradient (D_uq fv + D_vq fu) / 2.
    {
      const V alpha = ih2 * T::load(P.ia[2]);
      const V uv = fux * fvx + fuy * fvy + fuz * fvz;
      const V uu = fux * fux + fuy * fuy + fuz * fuz;
      const V vv = fvx * fvx + fvy * fvy + fvz * fvz;
      const V denom = alpha + S(0.25) * (Suu * vv + S(2) * Suv * uv + Svv * uu);
      const V dl = half * solve(alpha, -half * uv, denom, 2);
      ax += dl * fvx, ay += dl * fvy, az += dl * fvz;
      bx += dl * fux, by += dl * fuy, bz += dl * fuz;
    }
    if (lambda)
      for (int l = 0; l < L; ++l)
        if (P.k[l] >= 0)
          for (int c = 0; c < 3; ++c) lambda[3 * P.k[l] + c] = lam[c][l];
    for (int q = 0; q < 3; ++q) {
      LanesOf<V>& v = g[q];
      v.X += v.W * (Du[q] * ax + Dv[q] * bx);
      v.Y += v.W * (Du[q] * ay + Dv[q] * by);
      v.Z += v.W * (Du[q] * az + Dv[q] * bz);
      T::scatter(x, P.v[q], v);
    }
  }
}

// Bending block (one per lane): C_a = sum_j v_aj x_j (a = 0, 1, 2); A dl = -C - alpha l with
// A^-1 cached (all 0 for a lane that does nothing). In single precision C starts from its value
// at the anchors and sums the displacements.
template <class T>
void rows_impl(const RowPacksT<typename T::S>& rp, const typename T::S* ca, int b, int e,
               typename T::PX* x, double ihbd, double* lambda) {
  using V = typename T::V;
  using S = typename T::S;
  constexpr int L = T::L;
  const V zero = V{} + S(0);
  const S ihb = static_cast<S>(ihbd);
  for (int p = b; p < e; ++p) {
    // C_a = (cax, cay, caz): named values, not arrays, so that they stay in registers.
    V c0x = zero, c0y = zero, c0z = zero, c1x = zero, c1y = zero, c1z = zero, c2x = zero,
      c2y = zero, c2z = zero;
    if constexpr (T::kAnchored) {  // C at the anchors
      const S* A = ca + 9 * L * p;
      c0x = T::load(A), c0y = T::load(A + L), c0z = T::load(A + 2 * L);
      c1x = T::load(A + 3 * L), c1y = T::load(A + 4 * L), c1z = T::load(A + 5 * L);
      c2x = T::load(A + 6 * L), c2y = T::load(A + 7 * L), c2z = T::load(A + 8 * L);
    }
    const int k0 = rp.off[p], k1 = rp.off[p + 1];
    for (int k = k0; k < k1; ++k) {
      const auto g = T::gather(x, rp.colv + L * k);
      const S* val = rp.val + 3 * L * k;
      const V v0 = T::load(val), v1 = T::load(val + L), v2 = T::load(val + 2 * L);
      c0x += v0 * g.X, c0y += v0 * g.Y, c0z += v0 * g.Z;
      c1x += v1 * g.X, c1y += v1 * g.Y, c1z += v1 * g.Z;
      c2x += v2 * g.X, c2y += v2 * g.Y, c2z += v2 * g.Z;
    }
    const int32_t* blk = rp.blk + L * p;
    V lam[9];  // [3 a + c] (only with lambda)
    if (lambda) {
      for (int j = 0; j < 9; ++j) {
        lam[j] = zero;
        for (int l = 0; l < L; ++l)
          if (blk[l] >= 0) lam[j][l] = static_cast<S>(lambda[9 * blk[l] + j]);
      }
      const S* ik = rp.ik + 3 * L * p;
      const V al0 = ihb * T::load(ik), al1 = ihb * T::load(ik + L), al2 = ihb * T::load(ik + 2 * L);
      c0x += al0 * lam[0], c0y += al0 * lam[1], c0z += al0 * lam[2];
      c1x += al1 * lam[3], c1y += al1 * lam[4], c1z += al1 * lam[5];
      c2x += al2 * lam[6], c2y += al2 * lam[7], c2z += al2 * lam[8];
    }
    // dl_a = -sum_b Ai_ab (C_b + alpha_b l_b).
    const S* A = rp.ai + 6 * L * p;
    const V a00 = T::load(A), a01 = T::load(A + L), a02 = T::load(A + 2 * L),
            a11 = T::load(A + 3 * L), a12 = T::load(A + 4 * L), a22 = T::load(A + 5 * L);
    const V d0x = -(a00 * c0x + a01 * c1x + a02 * c2x), d0y = -(a00 * c0y + a01 * c1y + a02 * c2y),
            d0z = -(a00 * c0z + a01 * c1z + a02 * c2z);
    const V d1x = -(a01 * c0x + a11 * c1x + a12 * c2x), d1y = -(a01 * c0y + a11 * c1y + a12 * c2y),
            d1z = -(a01 * c0z + a11 * c1z + a12 * c2z);
    const V d2x = -(a02 * c0x + a12 * c1x + a22 * c2x), d2y = -(a02 * c0y + a12 * c1y + a22 * c2y),
            d2z = -(a02 * c0z + a12 * c1z + a22 * c2z);
    if (lambda) {
      const V d[9] = {d0x, d0y, d0z, d1x, d1y, d1z, d2x, d2y, d2z};
      for (int l = 0; l < L; ++l)
        if (blk[l] >= 0)
          for (int j = 0; j < 9; ++j) lambda[9 * blk[l] + j] = lam[j][l] + d[j][l];
    }
    for (int k = k0; k < k1; ++k) {
      const int32_t* v = rp.colv + L * k;
      auto g = T::gather(x, v);
      const S* val = rp.val + 3 * L * k;
      const V v0 = T::load(val), v1 = T::load(val + L), v2 = T::load(val + 2 * L);
      g.X += g.W * (v0 * d0x + v1 * d1x + v2 * d2x);
      g.Y += g.W * (v0 * d0y + v1 * d1y + v2 * d2y);
      g.Z += g.W * (v0 * d0z + v1 * d1z + v2 * d2z);
      T::scatter(x, v, g);
    }
  }
}

void project_tris(const TriPack* packs, int b, int e, P4* x, double ih2, double* lambda) {
  tris_impl<Dbl4>(packs, nullptr, b, e, x, ih2, lambda);
}
void project_rows(const RowPacks& rp, int b, int e, P4* x, double ihb, double* lambda) {
  rows_impl<Dbl4>(rp, nullptr, b, e, x, ihb, lambda);
}
void project_tris8(const TriPack8* packs, const float* fa, int b, int e, P4f* x, double ih2,
                   double* lambda) {
  tris_impl<Flt8>(packs, fa, b, e, x, ih2, lambda);
}
void project_rows8(const RowPacksT<float>& rp, const float* ca, int b, int e, P4f* x, double ihb,
                   double* lambda) {
  rows_impl<Flt8>(rp, ca, b, e, x, ihb, lambda);
}
void project_tris16(const TriPack16* packs, const float* fa, int b, int e, P4f* x, double ih2,
                    double* lambda) {
  tris_impl<Flt16>(packs, fa, b, e, x, ih2, lambda);
}
void project_rows16(const RowPacksT<float>& rp, const float* ca, int b, int e, P4f* x, double ihb,
                    double* lambda) {
  rows_impl<Flt16>(rp, ca, b, e, x, ihb, lambda);
}

void pack(const double* x, const double* w, P4* p, int b, int e) {
  for (int i = b; i < e; ++i) {
    p[i].c[0] = x[3 * i];
    p[i].c[1] = x[3 * i + 1];
    p[i].c[2] = x[3 * i + 2];
    p[i].c[3] = w[i];
  }
}

void unpack(const P4* p, double* x, int b, int e) {
  for (int i = b; i < e; ++i)
    for (int c = 0; c < 3; ++c) x[3 * i + c] = p[i].c[c];
}

void pack8(const double* x, const double* w, const double* a, P4f* p, int b, int e) {
  for (int i = b; i < e; ++i) {
    for (int c = 0; c < 3; ++c) p[i].c[c] = static_cast<float>(x[3 * i + c] - a[3 * i + c]);
    p[i].c[3] = static_cast<float>(w[i]);
  }
}

// The solver's per-vertex steps (Kernels::predict, velocities, motion), without contraction
// into fused multiply-adds: the solver's own loops, built for any x86-64, have none, and a block
// must come out the same whichever of the two runs it.
#if defined(__GNUC__) && !defined(__clang__)
#define DRAPE_NO_CONTRACT __attribute__((optimize("fp-contract=off")))
#else
#define DRAPE_NO_CONTRACT
#endif
DRAPE_NO_CONTRACT void predict(double* x, double* x_prev, const double* v, const double* w,
                               const double* mass, double scale, double h, const double* g, int b,
                               int e) {
  for (int i = b; i < e; ++i) {
    const double m = mass[i];
    const double c = h * h / (scale * m);
    const bool free = w[i] > 0;
    for (int k = 0; k < 3; ++k) {
      const double x0 = x[3 * i + k];
      x_prev[3 * i + k] = x0;
      const double x1 = x0 + (h * v[3 * i + k] + c * (m * g[k]));
      x[3 * i + k] = free ? x1 : x0;
    }
  }
}

DRAPE_NO_CONTRACT void velocities(const double* x, const double* x_prev, double* v, const double* w,
                                  const uint8_t* flags, uint8_t frozen, double damp, double h,
                                  int b, int e) {
  const double dh = damp / h;  // (a division per block, not three per vertex)
  for (int i = b; i < e; ++i) {
    const bool free = w[i] > 0, still = (flags[i] & frozen) != 0;
    for (int k = 0; k < 3; ++k) {
      const double vk = dh * (x[3 * i + k] - x_prev[3 * i + k]);
      v[3 * i + k] = free ? vk : still ? 0.0 : v[3 * i + k];
    }
  }
}

DRAPE_NO_CONTRACT int motion(const double* v, const double* w, const double* mass, double slow2,
                             int b, int e, double* out) {
  double mx = 0, mv2 = 0, capped = 0, ms = 0;
  int free = 0;
  for (int i = b; i < e; ++i) {
    const bool f = w[i] > 0;
    const double vx = v[3 * i], vy = v[3 * i + 1], vz = v[3 * i + 2];
    const double v2 = vx * vx + vy * vy + vz * vz, m = mass[i];
    // (Adding 0 for a vertex not free leaves each sum as it was.)
    mx = std::max(mx, f ? v2 : 0.0);
    mv2 += f ? m * v2 : 0.0;
    capped += f ? m * std::min(v2, slow2) : 0.0;
    ms += f ? m : 0.0;
    free += f;
  }
  out[0] = mx;
  out[1] = mv2;
  out[2] = capped;
  out[3] = ms;
  return free;
}

void unpack8(const P4f* p, const double* a, double* x, int b, int e) {
  for (int i = b; i < e; ++i)
    for (int c = 0; c < 3; ++c) {
      const double x0 = x[3 * i + c];
      const float packed = static_cast<float>(x0 - a[3 * i + c]);  // what pack8 stored
      x[3 * i + c] = x0 + (static_cast<double>(p[i].c[c]) - static_cast<double>(packed));
    }
}

template <int L>
void anchor_triangles_impl(const TriPackT<float, L>* packs, int b, int e, const double* a,
                           float* fa) {
  for (int p = b; p < e; ++p) {
    const TriPackT<float, L>& T = packs[p];
    double e1[3][L], e2[3][L];
    for (int l = 0; l < L; ++l)
      for (int c = 0; c < 3; ++c) {
        const double a0 = a[3 * T.v[0][l] + c];
        e1[c][l] = a[3 * T.v[1][l] + c] - a0;
        e2[c][l] = a[3 * T.v[2][l] + c] - a0;
      }
    float* out = fa + 6 * L * p;
    for (int c = 0; c < 3; ++c)
      for (int l = 0; l < L; ++l) {
        out[L * c + l] = static_cast<float>(e1[c][l] * T.D[2][l] + e2[c][l] * T.D[4][l]);
        out[L * (3 + c) + l] = static_cast<float>(e1[c][l] * T.D[3][l] + e2[c][l] * T.D[5][l]);
      }
  }
}

template <int L>
void anchor_rows_impl(const RowPacksT<float>& rp, int b, int e, const double* a, float* ca) {
  for (int p = b; p < e; ++p) {
    double c[9][L] = {};
    for (int k = rp.off[p]; k < rp.off[p + 1]; ++k) {
      double ax[3][L];  // the lanes' anchors, then L lanes at a time (vectorised)
      for (int l = 0; l < L; ++l)
        for (int d = 0; d < 3; ++d) ax[d][l] = a[3 * rp.colv[L * k + l] + d];
      for (int r = 0; r < 3; ++r)
        for (int d = 0; d < 3; ++d)
          for (int l = 0; l < L; ++l)
            c[3 * r + d][l] += static_cast<double>(rp.val[3 * L * k + L * r + l]) * ax[d][l];
    }
    for (int j = 0; j < 9; ++j)
      for (int l = 0; l < L; ++l) ca[9 * L * p + L * j + l] = static_cast<float>(c[j][l]);
  }
}

void anchor_triangles(const TriPack8* packs, int b, int e, const double* a, float* fa) {
  anchor_triangles_impl<8>(packs, b, e, a, fa);
}
void anchor_rows(const RowPacksT<float>& rp, int b, int e, const double* a, float* ca) {
  anchor_rows_impl<8>(rp, b, e, a, ca);
}
void anchor_triangles16(const TriPack16* packs, int b, int e, const double* a, float* fa) {
  anchor_triangles_impl<16>(packs, b, e, a, fa);
}
void anchor_rows16(const RowPacksT<float>& rp, int b, int e, const double* a, float* ca) {
  anchor_rows_impl<16>(rp, b, e, a, ca);
}

// This build's kernels, named, with its preferred single-precision triangle pack width.
constexpr Kernels make_kernels(const char* name, int tri_lanes) {
  return Kernels{name,
                 tri_lanes,
                 &project_tris,
                 &project_rows,
                 &pack,
                 &unpack,
                 &project_tris8,
                 &project_rows8,
                 &pack8,
                 &unpack8,
                 &predict,
                 &velocities,
                 &motion,
                 &anchor_triangles,
                 &anchor_rows,
                 &project_tris16,
                 &project_rows16,
                 &anchor_triangles16,
                 &anchor_rows16};
}
