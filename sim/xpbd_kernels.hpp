// XPBD's two hot loops (membrane triangles, tensor-bending blocks: ~75 % of a substep at 128^2,
// measured with perf) over positions padded to four doubles, so that a vertex is one 256-bit
// vector. The same source (sim/xpbd_kernels.inl) is compiled twice: portable (x86-64 baseline:
// SSE2, or any other target) and, on x86-64, with AVX2+FMA; kernels() picks the AVX2 build at
// run time when the CPU has it. Results of the two differ by round-off only (FMA contraction).
// No Eigen here: an inline Eigen function instantiated in the AVX2 unit could be the copy the
// linker keeps for the whole program.
#pragma once

#include <cstdint>

namespace drape::sim::xpbd {

// A vertex position padded to 32 bytes; the fourth lane is always 0.
struct alignas(32) P4 {
  double c[4];
};

// One membrane triangle: the three strain constraints E_uu, E_vv, E_uv of F = sum_k x_k D_k.
struct Tri {
  int32_t v[3];
  double D[6];   // F = sum_k x_k (D[2k], D[2k+1])
  double ia[3];  // 1 / (k A) for E_uu, E_vv, E_uv
};

// Tensor-bending blocks in CSR form (three linear vector constraints sharing one stencil each;
// see XpbdSolver::cook): block r is sum_k val[3k + a] x[colv[k]] for a = 0, 1, 2 over
// k in [off[r], off[r + 1]); ik its three inverse stiffnesses, ai the inverse of its 3x3 system
// matrix (upper triangle, 6 entries; ai[0] == 0: skip the block).
struct RowBlocks {
  const int* off;
  const int* colv;
  const double* val;
  const double* ik;
  const double* ai;
};

struct Kernels {
  const char* name;  // "avx2" or "portable"
  // Projects triangles [b, e) once (Gauss-Seidel), one constraint after the other. lambda: the
  // triangles' multipliers (3 each), or null when they are reset every substep.
  void (*tris)(const Tri* tris, int b, int e, const double* w, P4* x, double ih2, double* lambda);
  // Projects bending blocks [b, e) once; lambda: 3 vectors (9 doubles) per block, or null.
  void (*rows)(const RowBlocks& rb, int b, int e, const double* w, P4* x, double ihb,
               double* lambda);
  // Positions as 3 doubles per vertex (Vec3 arrays) to and from the padded form, [b, e).
  void (*pack)(const double* x, P4* p, int b, int e);
  void (*unpack)(const P4* p, double* x, int b, int e);
};

// The fastest build this CPU runs; simd = false: the portable one (tests compare the two).
// DRAPE_XPBD_SIMD=0 in the environment forces the portable build.
const Kernels& kernels(bool simd = true);

}  // namespace drape::sim::xpbd
