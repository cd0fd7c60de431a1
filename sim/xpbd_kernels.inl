// The body of XPBD's hot loops (sim/xpbd_kernels.hpp), included once per instruction set by
// sim/xpbd_kernels.cpp (portable) and sim/xpbd_kernels_avx2.cpp (AVX2+FMA) inside a namespace
// of their own. Positions are GCC/Clang vector-extension values of four doubles (lane 3 = 0):
// the compiler maps them to one AVX register or two SSE2 registers.

#if defined(DRAPE_XPBD_VECTOR_EXT)
#if defined(__GNUC__) && !defined(__clang__)
// The helpers below take and return V4 by value; GCC notes that this ABI differs between units
// with and without AVX. They are inlined and never called across units.
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
using V4 = double __attribute__((vector_size(32)));
inline V4 load(const P4& p) {
  return *reinterpret_cast<const V4*>(p.c);
}
inline void store(P4& p, V4 v) {
  *reinterpret_cast<V4*>(p.c) = v;
}
inline double dot(V4 a, V4 b) {
  const V4 m = a * b;
  return m[0] + m[1] + m[2];
}
inline V4 make(double x, double y, double z) {
  return V4{x, y, z, 0};
}
inline double lane(V4 a, int c) {
  return a[c];
}
#else
// Without AVX a 256-bit vector type is split into SSE halves through memory (measured: twice as
// slow as scalar code), and an array member defeats scalar replacement (ten times as slow):
// three named doubles.
struct V4 {
  double x = 0, y = 0, z = 0;
  V4& operator+=(const V4& o) {
    x += o.x;
    y += o.y;
    z += o.z;
    return *this;
  }
  V4& operator*=(double s) {
    x *= s;
    y *= s;
    z *= s;
    return *this;
  }
};
inline V4 operator+(V4 a, const V4& b) {
  return a += b;
}
inline V4 operator*(double s, V4 a) {
  return a *= s;
}
inline V4 operator*(V4 a, double s) {
  return a *= s;
}
inline V4 operator-(V4 a) {
  return a *= -1.0;
}
inline V4 load(const P4& p) {
  return V4{p.c[0], p.c[1], p.c[2]};
}
inline void store(P4& p, const V4& v) {
  p.c[0] = v.x;
  p.c[1] = v.y;
  p.c[2] = v.z;
}
inline double dot(const V4& a, const V4& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline V4 make(double x, double y, double z) {
  return V4{x, y, z};
}
inline double lane(const V4& a, int c) {
  return c == 0 ? a.x : c == 1 ? a.y : a.z;
}
#endif

// The three strain constraints of a triangle (E_uu, E_vv, E_uv) are projected one after the
// other as in classic XPBD, but in the space of F = (fu, fv): every gradient is
// w_q (D_uq a + D_vq b) for vectors a, b, so each projection changes F by a closed form
// (S_uu, S_vv, S_uv below) and the vertices are moved once, by the sum.
void project_tris(const Tri* tris, int b, int e, const double* w, P4* x, double ih2,
                  double* lambda) {
  for (int k = b; k < e; ++k) {
    const Tri& T = tris[k];
    const double wq[3] = {w[T.v[0]], w[T.v[1]], w[T.v[2]]};
    if (wq[0] + wq[1] + wq[2] == 0) continue;
    const V4 p0 = load(x[T.v[0]]), p1 = load(x[T.v[1]]), p2 = load(x[T.v[2]]);
    const double* D = T.D;
    V4 fu = p0 * D[0] + p1 * D[2] + p2 * D[4];
    V4 fv = p0 * D[1] + p1 * D[3] + p2 * D[5];
    double Suu = 0, Svv = 0, Suv = 0;
    for (int q = 0; q < 3; ++q) {
      Suu += wq[q] * D[2 * q] * D[2 * q];
      Svv += wq[q] * D[2 * q + 1] * D[2 * q + 1];
      Suv += wq[q] * D[2 * q] * D[2 * q + 1];
    }
    V4 a{}, bb{};
    double* L = lambda ? lambda + 3 * k : nullptr;
    // E_uu = (|fu|^2 - 1) / 2 with gradient D_uq fu (c = 0; f = fu, g = fv, acc = a) and
    // E_vv = (|fv|^2 - 1) / 2 with gradient D_vq fv (c = 1; f = fv, g = fu, acc = bb).
    auto stretch = [&](int c, V4& f, V4& g, double Sff, V4& acc) {
      const double alpha = ih2 * T.ia[c];
      const double f2 = dot(f, f);
      const double denom = alpha + Sff * f2;
      if (denom < 1e-20) return;
      const double lam = L ? L[c] : 0.0;
      const double dl = (-0.5 * (f2 - 1) - alpha * lam) / denom;
      if (L) L[c] = lam + dl;
      acc += dl * f;
      g += (dl * Suv) * f;
      f *= 1 + dl * Sff;
    };
    stretch(0, fu, fv, Suu, a);
    stretch(1, fv, fu, Svv, bb);
    // E_uv = fu . fv / 2, gradient (D_uq fv + D_vq fu) / 2.
    {
      const double alpha = ih2 * T.ia[2];
      const double uv = dot(fu, fv);
      const double denom = alpha + 0.25 * (Suu * dot(fv, fv) + 2 * Suv * uv + Svv * dot(fu, fu));
      if (denom >= 1e-20) {
        const double lam = L ? L[2] : 0.0;
        const double dl = (-0.5 * uv - alpha * lam) / denom;
        if (L) L[2] = lam + dl;
        a += (0.5 * dl) * fv;
        bb += (0.5 * dl) * fu;
      }
    }
    for (int q = 0; q < 3; ++q)
      if (wq[q] > 0) {
        P4& xq = x[T.v[q]];
        store(xq, load(xq) + wq[q] * (D[2 * q] * a + D[2 * q + 1] * bb));
      }
  }
}

// Bending block r: C_a = sum_j v_aj x_j (a = 0, 1, 2); A dl = -C - alpha l with A^-1 cached.
void project_rows(const RowBlocks& rb, int b, int e, const double* w, P4* x, double ihb,
                  double* lambda) {
  for (int r = b; r < e; ++r) {
    const double* ai = rb.ai + 6 * r;
    if (ai[0] == 0) continue;  // every vertex fixed (or A singular)
    V4 C0{}, C1{}, C2{};
    const int k0 = rb.off[r], k1 = rb.off[r + 1];
    for (int k = k0; k < k1; ++k) {
      const V4 xj = load(x[rb.colv[k]]);
      const double* v = rb.val + 3 * k;
      C0 += v[0] * xj;
      C1 += v[1] * xj;
      C2 += v[2] * xj;
    }
    double* lam = lambda ? lambda + 9 * r : nullptr;
    if (lam) {
      const double* ik = rb.ik + 3 * r;
      const V4 l0 = make(lam[0], lam[1], lam[2]), l1 = make(lam[3], lam[4], lam[5]),
               l2 = make(lam[6], lam[7], lam[8]);
      C0 += (ihb * ik[0]) * l0;
      C1 += (ihb * ik[1]) * l1;
      C2 += (ihb * ik[2]) * l2;
    }
    // dl_a = -sum_b Ai_ab (C_b + alpha_b l_b): one vector per row a.
    const V4 d0 = -(ai[0] * C0 + ai[1] * C1 + ai[2] * C2);
    const V4 d1 = -(ai[1] * C0 + ai[3] * C1 + ai[4] * C2);
    const V4 d2 = -(ai[2] * C0 + ai[4] * C1 + ai[5] * C2);
    if (lam)
      for (int c = 0; c < 3; ++c) {
        lam[c] += lane(d0, c);
        lam[3 + c] += lane(d1, c);
        lam[6 + c] += lane(d2, c);
      }
    for (int k = k0; k < k1; ++k) {
      const int j = rb.colv[k];
      const double wj = w[j];
      if (wj == 0) continue;
      const double* v = rb.val + 3 * k;
      store(x[j], load(x[j]) + wj * (v[0] * d0 + v[1] * d1 + v[2] * d2));
    }
  }
}

void pack(const double* x, P4* p, int b, int e) {
  for (int i = b; i < e; ++i) {
    p[i].c[0] = x[3 * i];
    p[i].c[1] = x[3 * i + 1];
    p[i].c[2] = x[3 * i + 2];
    p[i].c[3] = 0;
  }
}

void unpack(const P4* p, double* x, int b, int e) {
  for (int i = b; i < e; ++i)
    for (int c = 0; c < 3; ++c) x[3 * i + c] = p[i].c[c];
}
