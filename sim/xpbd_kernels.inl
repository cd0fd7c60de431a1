// The body of XPBD's hot loops (sim/xpbd_kernels.hpp), included once per instruction set by
// sim/xpbd_kernels.cpp (portable) and sim/xpbd_kernels_avx2.cpp (AVX2+FMA) inside a namespace
// of their own. Values are GCC/Clang vector-extension vectors of four doubles, one element per
// lane: the compiler maps one to an AVX register, or to two SSE2 registers.

#if defined(__GNUC__) && !defined(__clang__)
// The helpers below take and return vectors by value; GCC notes that this ABI differs between
// units with and without AVX. They are inlined and never called across units.
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
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
inline D4 splat(double s) {
  return D4{s, s, s, s};
}
inline D4 sel(M4 m, D4 a, D4 b) {  // m ? a : b, lane by lane
  return reinterpret_cast<D4>((reinterpret_cast<M4>(a) & m) | (reinterpret_cast<M4>(b) & ~m));
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
struct Lanes {
  D4 X, Y, Z, W;
};
#if defined(__AVX__)
inline Lanes gather(const P4* x, const int32_t* v) {
  Lanes g;
  transpose(ld(x[v[0]]), ld(x[v[1]]), ld(x[v[2]]), ld(x[v[3]]), g.X, g.Y, g.Z, g.W);
  return g;
}
#else
// Without AVX a 256-bit shuffle is lowered through memory: element by element is faster.
inline Lanes gather(const P4* x, const int32_t* v) {
  const double *a = x[v[0]].c, *b = x[v[1]].c, *c = x[v[2]].c, *d = x[v[3]].c;
  return Lanes{D4{a[0], b[0], c[0], d[0]}, D4{a[1], b[1], c[1], d[1]}, D4{a[2], b[2], c[2], d[2]},
               D4{a[3], b[3], c[3], d[3]}};
}
#endif
// Writes the lanes back. Lanes sharing a vertex (only the scratch vertex of padding, which no
// projection moves) write the same value.
inline void scatter(P4* x, const int32_t* v, const Lanes& g) {
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

// The three strain constraints of a triangle (E_uu, E_vv, E_uv) are projected one after the
// other as in classic XPBD, but in the space of F = (fu, fv): every gradient is
// w_q (D_uq a + D_vq b) for vectors a, b, so each projection changes F by a closed form
// (S_uu, S_vv, S_uv below) and the vertices are moved once, by the sum. Each lane is one
// triangle; a lane whose denominator vanishes (all vertices fixed, padding) changes nothing.
void project_tris(const TriPack* packs, int b, int e, P4* x, double ih2, double* lambda) {
  const D4 zero = splat(0), one = splat(1), half = splat(0.5), tiny = splat(1e-20);
  for (int p = b; p < e; ++p) {
    const TriPack& T = packs[p];
    Lanes g[3];
    D4 Du[3], Dv[3];
    for (int q = 0; q < 3; ++q) {
      g[q] = gather(x, T.v[q]);
      Du[q] = ld(T.D[2 * q]);
      Dv[q] = ld(T.D[2 * q + 1]);
    }
    D4 fux = g[0].X * Du[0] + g[1].X * Du[1] + g[2].X * Du[2];
    D4 fuy = g[0].Y * Du[0] + g[1].Y * Du[1] + g[2].Y * Du[2];
    D4 fuz = g[0].Z * Du[0] + g[1].Z * Du[1] + g[2].Z * Du[2];
    D4 fvx = g[0].X * Dv[0] + g[1].X * Dv[1] + g[2].X * Dv[2];
    D4 fvy = g[0].Y * Dv[0] + g[1].Y * Dv[1] + g[2].Y * Dv[2];
    D4 fvz = g[0].Z * Dv[0] + g[1].Z * Dv[1] + g[2].Z * Dv[2];
    const D4 Suu = g[0].W * Du[0] * Du[0] + g[1].W * Du[1] * Du[1] + g[2].W * Du[2] * Du[2];
    const D4 Svv = g[0].W * Dv[0] * Dv[0] + g[1].W * Dv[1] * Dv[1] + g[2].W * Dv[2] * Dv[2];
    const D4 Suv = g[0].W * Du[0] * Dv[0] + g[1].W * Du[1] * Dv[1] + g[2].W * Du[2] * Dv[2];
    const M4 live = (g[0].W + g[1].W + g[2].W) > zero;
    D4 lam[3] = {zero, zero, zero};
    if (lambda)
      for (int l = 0; l < 4; ++l)
        if (T.k[l] >= 0)
          for (int c = 0; c < 3; ++c) lam[c][l] = lambda[3 * T.k[l] + c];
    // dl = (num - alpha lam) / denom where the lane is live and denom is not ~0, else 0.
    auto solve = [&](D4 alpha, D4 num, D4 denom, int c) {
      const M4 ok = (denom >= tiny) & live;
      const D4 dl = sel(ok, (num - alpha * lam[c]) / sel(ok, denom, one), zero);
      lam[c] += dl;
      return dl;
    };
    D4 ax = zero, ay = zero, az = zero, bx = zero, by = zero, bz = zero;
    // E_uu = (|fu|^2 - 1) / 2 with gradient D_uq fu: a += dl fu, fv += dl S_uv fu,
    // fu *= 1 + dl S_uu.
    {
      const D4 alpha = ih2 * ld(T.ia[0]);
      const D4 f2 = fux * fux + fuy * fuy + fuz * fuz;
      const D4 dl = solve(alpha, -half * (f2 - one), alpha + Suu * f2, 0);
      ax += dl * fux, ay += dl * fuy, az += dl * fuz;
      const D4 cross = dl * Suv, grow = one + dl * Suu;
      fvx += cross * fux, fvy += cross * fuy, fvz += cross * fuz;
      fux *= grow, fuy *= grow, fuz *= grow;
    }
    // E_vv = (|fv|^2 - 1) / 2 with gradient D_vq fv: the same with u and v swapped.
    {
      const D4 alpha = ih2 * ld(T.ia[1]);
      const D4 f2 = fvx * fvx + fvy * fvy + fvz * fvz;
      const D4 dl = solve(alpha, -half * (f2 - one), alpha + Svv * f2, 1);
      bx += dl * fvx, by += dl * fvy, bz += dl * fvz;
      const D4 cross = dl * Suv, grow = one + dl * Svv;
      fux += cross * fvx, fuy += cross * fvy, fuz += cross * fvz;
      fvx *= grow, fvy *= grow, fvz *= grow;
    }
    // E_uv = fu . fv / 2, gradient (D_uq fv + D_vq fu) / 2.
    {
      const D4 alpha = ih2 * ld(T.ia[2]);
      const D4 uv = fux * fvx + fuy * fvy + fuz * fvz;
      const D4 uu = fux * fux + fuy * fuy + fuz * fuz;
      const D4 vv = fvx * fvx + fvy * fvy + fvz * fvz;
      const D4 denom = alpha + 0.25 * (Suu * vv + 2.0 * Suv * uv + Svv * uu);
      const D4 dl = half * solve(alpha, -half * uv, denom, 2);
      ax += dl * fvx, ay += dl * fvy, az += dl * fvz;
      bx += dl * fux, by += dl * fuy, bz += dl * fuz;
    }
    if (lambda)
      for (int l = 0; l < 4; ++l)
        if (T.k[l] >= 0)
          for (int c = 0; c < 3; ++c) lambda[3 * T.k[l] + c] = lam[c][l];
    for (int q = 0; q < 3; ++q) {
      Lanes& v = g[q];
      v.X += v.W * (Du[q] * ax + Dv[q] * bx);
      v.Y += v.W * (Du[q] * ay + Dv[q] * by);
      v.Z += v.W * (Du[q] * az + Dv[q] * bz);
      scatter(x, T.v[q], v);
    }
  }
}

// Bending block (one per lane): C_a = sum_j v_aj x_j (a = 0, 1, 2); A dl = -C - alpha l with
// A^-1 cached (all 0 for a lane that does nothing).
void project_rows(const RowPacks& rp, int b, int e, P4* x, double ihb, double* lambda) {
  const D4 zero = splat(0);
  for (int p = b; p < e; ++p) {
    // C_a = (cax, cay, caz): named values, not arrays, so that they stay in registers.
    D4 c0x = zero, c0y = zero, c0z = zero, c1x = zero, c1y = zero, c1z = zero, c2x = zero,
       c2y = zero, c2z = zero;
    const int k0 = rp.off[p], k1 = rp.off[p + 1];
    for (int k = k0; k < k1; ++k) {
      const Lanes g = gather(x, rp.colv + 4 * k);
      const double* val = rp.val + 12 * k;
      const D4 v0 = ld(val), v1 = ld(val + 4), v2 = ld(val + 8);
      c0x += v0 * g.X, c0y += v0 * g.Y, c0z += v0 * g.Z;
      c1x += v1 * g.X, c1y += v1 * g.Y, c1z += v1 * g.Z;
      c2x += v2 * g.X, c2y += v2 * g.Y, c2z += v2 * g.Z;
    }
    const int32_t* blk = rp.blk + 4 * p;
    D4 lam[9];  // [3 a + c] (only with lambda)
    if (lambda) {
      for (int j = 0; j < 9; ++j) {
        lam[j] = zero;
        for (int l = 0; l < 4; ++l)
          if (blk[l] >= 0) lam[j][l] = lambda[9 * blk[l] + j];
      }
      const D4 al0 = ihb * ld(rp.ik + 12 * p), al1 = ihb * ld(rp.ik + 12 * p + 4),
               al2 = ihb * ld(rp.ik + 12 * p + 8);
      c0x += al0 * lam[0], c0y += al0 * lam[1], c0z += al0 * lam[2];
      c1x += al1 * lam[3], c1y += al1 * lam[4], c1z += al1 * lam[5];
      c2x += al2 * lam[6], c2y += al2 * lam[7], c2z += al2 * lam[8];
    }
    // dl_a = -sum_b Ai_ab (C_b + alpha_b l_b).
    const double* A = rp.ai + 24 * p;
    const D4 a00 = ld(A), a01 = ld(A + 4), a02 = ld(A + 8), a11 = ld(A + 12), a12 = ld(A + 16),
             a22 = ld(A + 20);
    const D4 d0x = -(a00 * c0x + a01 * c1x + a02 * c2x), d0y = -(a00 * c0y + a01 * c1y + a02 * c2y),
             d0z = -(a00 * c0z + a01 * c1z + a02 * c2z);
    const D4 d1x = -(a01 * c0x + a11 * c1x + a12 * c2x), d1y = -(a01 * c0y + a11 * c1y + a12 * c2y),
             d1z = -(a01 * c0z + a11 * c1z + a12 * c2z);
    const D4 d2x = -(a02 * c0x + a12 * c1x + a22 * c2x), d2y = -(a02 * c0y + a12 * c1y + a22 * c2y),
             d2z = -(a02 * c0z + a12 * c1z + a22 * c2z);
    if (lambda) {
      const D4 d[9] = {d0x, d0y, d0z, d1x, d1y, d1z, d2x, d2y, d2z};
      for (int l = 0; l < 4; ++l)
        if (blk[l] >= 0)
          for (int j = 0; j < 9; ++j) lambda[9 * blk[l] + j] = lam[j][l] + d[j][l];
    }
    for (int k = k0; k < k1; ++k) {
      const int32_t* v = rp.colv + 4 * k;
      Lanes g = gather(x, v);
      const double* val = rp.val + 12 * k;
      const D4 v0 = ld(val), v1 = ld(val + 4), v2 = ld(val + 8);
      g.X += g.W * (v0 * d0x + v1 * d1x + v2 * d2x);
      g.Y += g.W * (v0 * d0y + v1 * d1y + v2 * d2y);
      g.Z += g.W * (v0 * d0z + v1 * d1z + v2 * d2z);
      scatter(x, v, g);
    }
  }
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

// ---- Single precision: eight elements per pack (XpbdOptions::single_precision) ----
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
inline F8 splat8(float s) {
  return F8{s, s, s, s, s, s, s, s};
}
inline F8 sel8(M8 m, F8 a, F8 b) {  // m ? a : b, lane by lane
  return reinterpret_cast<F8>((reinterpret_cast<M8>(a) & m) | (reinterpret_cast<M8>(b) & ~m));
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

struct Lanes8 {
  F8 X, Y, Z, W;
};
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

// project_tris in single precision, F formed from the edges: (x1 - x0) D_1 + (x2 - x0) D_2
// (D_0 = -D_1 - D_2).
void project_tris8(const TriPack8* packs, int b, int e, P4f* x, double ih2d, double* lambda) {
  const F8 zero = splat8(0), one = splat8(1), half = splat8(0.5f), tiny = splat8(1e-20f);
  const float ih2 = static_cast<float>(ih2d);
  for (int p = b; p < e; ++p) {
    const TriPack8& T = packs[p];
    Lanes8 g[3];
    F8 Du[3], Dv[3];
    for (int q = 0; q < 3; ++q) {
      g[q] = gather8(x, T.v[q]);
      Du[q] = ld8(T.D[2 * q]);
      Dv[q] = ld8(T.D[2 * q + 1]);
    }
    const F8 e1x = g[1].X - g[0].X, e1y = g[1].Y - g[0].Y, e1z = g[1].Z - g[0].Z;
    const F8 e2x = g[2].X - g[0].X, e2y = g[2].Y - g[0].Y, e2z = g[2].Z - g[0].Z;
    F8 fux = e1x * Du[1] + e2x * Du[2], fuy = e1y * Du[1] + e2y * Du[2],
       fuz = e1z * Du[1] + e2z * Du[2];
    F8 fvx = e1x * Dv[1] + e2x * Dv[2], fvy = e1y * Dv[1] + e2y * Dv[2],
       fvz = e1z * Dv[1] + e2z * Dv[2];
    const F8 Suu = g[0].W * Du[0] * Du[0] + g[1].W * Du[1] * Du[1] + g[2].W * Du[2] * Du[2];
    const F8 Svv = g[0].W * Dv[0] * Dv[0] + g[1].W * Dv[1] * Dv[1] + g[2].W * Dv[2] * Dv[2];
    const F8 Suv = g[0].W * Du[0] * Dv[0] + g[1].W * Du[1] * Dv[1] + g[2].W * Du[2] * Dv[2];
    const M8 live = (g[0].W + g[1].W + g[2].W) > zero;
    F8 lam[3] = {zero, zero, zero};
    if (lambda)
      for (int l = 0; l < 8; ++l)
        if (T.k[l] >= 0)
          for (int c = 0; c < 3; ++c) lam[c][l] = static_cast<float>(lambda[3 * T.k[l] + c]);
    auto solve = [&](F8 alpha, F8 num, F8 denom, int c) {
      const M8 ok = (denom >= tiny) & live;
      const F8 dl = sel8(ok, (num - alpha * lam[c]) / sel8(ok, denom, one), zero);
      lam[c] += dl;
      return dl;
    };
    F8 ax = zero, ay = zero, az = zero, bx = zero, by = zero, bz = zero;
    {
      const F8 alpha = ih2 * ld8(T.ia[0]);
      const F8 f2 = fux * fux + fuy * fuy + fuz * fuz;
      const F8 dl = solve(alpha, -half * (f2 - one), alpha + Suu * f2, 0);
      ax += dl * fux, ay += dl * fuy, az += dl * fuz;
      const F8 cross = dl * Suv, grow = one + dl * Suu;
      fvx += cross * fux, fvy += cross * fuy, fvz += cross * fuz;
      fux *= grow, fuy *= grow, fuz *= grow;
    }
    {
      const F8 alpha = ih2 * ld8(T.ia[1]);
      const F8 f2 = fvx * fvx + fvy * fvy + fvz * fvz;
      const F8 dl = solve(alpha, -half * (f2 - one), alpha + Svv * f2, 1);
      bx += dl * fvx, by += dl * fvy, bz += dl * fvz;
      const F8 cross = dl * Suv, grow = one + dl * Svv;
      fux += cross * fvx, fuy += cross * fvy, fuz += cross * fvz;
      fvx *= grow, fvy *= grow, fvz *= grow;
    }
    {
      const F8 alpha = ih2 * ld8(T.ia[2]);
      const F8 uv = fux * fvx + fuy * fvy + fuz * fvz;
      const F8 uu = fux * fux + fuy * fuy + fuz * fuz;
      const F8 vv = fvx * fvx + fvy * fvy + fvz * fvz;
      const F8 denom = alpha + 0.25f * (Suu * vv + 2.0f * Suv * uv + Svv * uu);
      const F8 dl = half * solve(alpha, -half * uv, denom, 2);
      ax += dl * fvx, ay += dl * fvy, az += dl * fvz;
      bx += dl * fux, by += dl * fuy, bz += dl * fuz;
    }
    if (lambda)
      for (int l = 0; l < 8; ++l)
        if (T.k[l] >= 0)
          for (int c = 0; c < 3; ++c) lambda[3 * T.k[l] + c] = lam[c][l];
    for (int q = 0; q < 3; ++q) {
      Lanes8& v = g[q];
      v.X += v.W * (Du[q] * ax + Dv[q] * bx);
      v.Y += v.W * (Du[q] * ay + Dv[q] * by);
      v.Z += v.W * (Du[q] * az + Dv[q] * bz);
      scatter8(x, T.v[q], v);
    }
  }
}

// project_rows in single precision (positions relative to the packing origin; a stencil read
// relative to its own first vertex was measured no more accurate - the floats' resolution of
// each position is the same either way - and spilled registers).
void project_rows8(const RowPacksT<float>& rp, int b, int e, P4f* x, double ihbd, double* lambda) {
  const F8 zero = splat8(0);
  const float ihb = static_cast<float>(ihbd);
  for (int p = b; p < e; ++p) {
    const int k0 = rp.off[p], k1 = rp.off[p + 1];
    F8 c0x = zero, c0y = zero, c0z = zero, c1x = zero, c1y = zero, c1z = zero, c2x = zero,
       c2y = zero, c2z = zero;
    for (int k = k0; k < k1; ++k) {
      const Lanes8 g = gather8(x, rp.colv + 8 * k);
      const float* val = rp.val + 24 * k;
      const F8 v0 = ld8(val), v1 = ld8(val + 8), v2 = ld8(val + 16);
      c0x += v0 * g.X, c0y += v0 * g.Y, c0z += v0 * g.Z;
      c1x += v1 * g.X, c1y += v1 * g.Y, c1z += v1 * g.Z;
      c2x += v2 * g.X, c2y += v2 * g.Y, c2z += v2 * g.Z;
    }
    const int32_t* blk = rp.blk + 8 * p;
    F8 lam[9];
    if (lambda) {
      for (int j = 0; j < 9; ++j) {
        lam[j] = zero;
        for (int l = 0; l < 8; ++l)
          if (blk[l] >= 0) lam[j][l] = static_cast<float>(lambda[9 * blk[l] + j]);
      }
      const F8 al0 = ihb * ld8(rp.ik + 24 * p), al1 = ihb * ld8(rp.ik + 24 * p + 8),
               al2 = ihb * ld8(rp.ik + 24 * p + 16);
      c0x += al0 * lam[0], c0y += al0 * lam[1], c0z += al0 * lam[2];
      c1x += al1 * lam[3], c1y += al1 * lam[4], c1z += al1 * lam[5];
      c2x += al2 * lam[6], c2y += al2 * lam[7], c2z += al2 * lam[8];
    }
    const float* A = rp.ai + 48 * p;
    const F8 a00 = ld8(A), a01 = ld8(A + 8), a02 = ld8(A + 16), a11 = ld8(A + 24),
             a12 = ld8(A + 32), a22 = ld8(A + 40);
    const F8 d0x = -(a00 * c0x + a01 * c1x + a02 * c2x), d0y = -(a00 * c0y + a01 * c1y + a02 * c2y),
             d0z = -(a00 * c0z + a01 * c1z + a02 * c2z);
    const F8 d1x = -(a01 * c0x + a11 * c1x + a12 * c2x), d1y = -(a01 * c0y + a11 * c1y + a12 * c2y),
             d1z = -(a01 * c0z + a11 * c1z + a12 * c2z);
    const F8 d2x = -(a02 * c0x + a12 * c1x + a22 * c2x), d2y = -(a02 * c0y + a12 * c1y + a22 * c2y),
             d2z = -(a02 * c0z + a12 * c1z + a22 * c2z);
    if (lambda) {
      const F8 d[9] = {d0x, d0y, d0z, d1x, d1y, d1z, d2x, d2y, d2z};
      for (int l = 0; l < 8; ++l)
        if (blk[l] >= 0)
          for (int j = 0; j < 9; ++j) lambda[9 * blk[l] + j] = lam[j][l] + d[j][l];
    }
    for (int k = k0; k < k1; ++k) {
      const int32_t* v = rp.colv + 8 * k;
      Lanes8 g = gather8(x, v);
      const float* val = rp.val + 24 * k;
      const F8 v0 = ld8(val), v1 = ld8(val + 8), v2 = ld8(val + 16);
      g.X += g.W * (v0 * d0x + v1 * d1x + v2 * d2x);
      g.Y += g.W * (v0 * d0y + v1 * d1y + v2 * d2y);
      g.Z += g.W * (v0 * d0z + v1 * d1z + v2 * d2z);
      scatter8(x, v, g);
    }
  }
}

void pack8(const double* x, const double* w, const double* origin, P4f* p, int b, int e) {
  for (int i = b; i < e; ++i) {
    for (int c = 0; c < 3; ++c) p[i].c[c] = static_cast<float>(x[3 * i + c] - origin[c]);
    p[i].c[3] = static_cast<float>(w[i]);
  }
}

void unpack8(const P4f* p, const double* origin, double* x, int b, int e) {
  for (int i = b; i < e; ++i)
    for (int c = 0; c < 3; ++c) {
      const double x0 = x[3 * i + c];
      const float packed = static_cast<float>(x0 - origin[c]);  // what pack8 stored
      x[3 * i + c] = x0 + (static_cast<double>(p[i].c[c]) - static_cast<double>(packed));
    }
}
