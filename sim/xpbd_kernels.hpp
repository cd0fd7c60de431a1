// XPBD's two hot loops (membrane triangles, tensor-bending blocks: ~70 % of a substep at 128^2,
// measured with perf), vectorised ACROSS elements: four elements of one colour (which share no
// vertex) are one pack and each SIMD lane computes one of them, so the divisions, dot products
// and 3x3 solves of four elements run side by side instead of as one long dependency chain.
// Positions are padded to four doubles (P4) with the inverse mass in the fourth lane: a 4x4
// transpose of four vertices gives the lanes' x, y, z and w.
// The same source (sim/xpbd_kernels.inl) is compiled twice: portable (x86-64 baseline: SSE2, or
// any other target) and, on x86-64, with AVX2+FMA; kernels() picks the AVX2 build at run time
// when the CPU has it. Results of the two differ by round-off only (FMA contraction).
// No Eigen here: an inline Eigen function instantiated in the AVX2 unit could be the copy the
// linker keeps for the whole program.
#pragma once

#include <cstdint>
#include <vector>

namespace drape::sim::xpbd {

// A vertex position padded to 32 bytes; the fourth lane is the vertex's inverse mass (0: fixed
// or frozen), which the kernels read and never change.
struct alignas(32) P4 {
  double c[4];
};

// One membrane triangle: the three strain constraints E_uu, E_vv, E_uv of F = sum_k x_k D_k.
struct Tri {
  int32_t v[3];
  double D[6];   // F = sum_k x_k (D[2k], D[2k+1])
  double ia[3];  // 1 / (k A) for E_uu, E_vv, E_uv
};

// Four triangles of one colour, lane l holding triangle k[l] (-1: padding, whose vertices are the
// scratch vertex and whose coefficients are 0).
struct alignas(32) TriPack {
  double D[6][4];
  double ia[3][4];
  int32_t v[3][4];
  int32_t k[4];
};

// Appends triangles [b, e) (one colour) as packs of four; padding lanes use vertex `scratch`
// (an extra P4 whose inverse mass is 0).
void pack_triangles(const Tri* tris, int b, int e, int scratch, std::vector<TriPack>& out);

// Tensor-bending blocks (three linear vector constraints sharing one stencil each; see
// XpbdSolver::cook) packed four per pack, one block per lane: pack p's stencil entries are
// [off[p], off[p + 1]) (the longest of its blocks; shorter ones are padded with the scratch
// vertex and coefficient 0). Entry k: vertices colv[4k + l], coefficients val[12k + 4a + l] of
// rows a = 0, 1, 2. Per pack: the inverse stiffnesses ik[12p + 4a + l], the inverse of the 3x3
// system matrix ai[24p + 4m + l] (m: 00 01 02 11 12 22; all 0: the lane does nothing) and the
// block index blk[4p + l] (-1: padding).
struct RowPacks {
  const int* off;
  const int32_t* colv;
  const double* val;
  const double* ik;
  const double* ai;
  const int32_t* blk;
};

struct RowPackData {
  std::vector<int> off{0};
  std::vector<int32_t> colv, blk;
  std::vector<double> val, ik, ai;
  std::vector<int> slot;  // per block: 4 * pack + lane
  void clear();
  // Appends blocks [b, e) (one colour) of the CSR (boff, bcol, bval: 3 per entry; bik: 3 per
  // block).
  void append(const int* boff, const int* bcol, const double* bval, const double* bik, int b, int e,
              int scratch);
  int packs() const { return static_cast<int>(off.size()) - 1; }
  // The inverse system matrix entry m of a block.
  double& ai_of(int block, int m) {
    const int s = slot[block];
    return ai[24 * (s / 4) + 4 * m + s % 4];
  }
  RowPacks view() const {
    return RowPacks{off.data(), colv.data(), val.data(), ik.data(), ai.data(), blk.data()};
  }
};

struct Kernels {
  const char* name;  // "avx2" or "portable"
  // Projects triangle packs [b, e) once (Gauss-Seidel within a triangle: E_uu, E_vv, E_uv one
  // after the other). lambda: the triangles' multipliers (3 per triangle index), or null when
  // they are reset every substep.
  void (*tris)(const TriPack* packs, int b, int e, P4* x, double ih2, double* lambda);
  // Projects bending packs [b, e) once; lambda: 3 vectors (9 doubles) per block, or null.
  void (*rows)(const RowPacks& rp, int b, int e, P4* x, double ihb, double* lambda);
  // Positions (3 doubles per vertex) and inverse masses to and from the padded form, [b, e).
  void (*pack)(const double* x, const double* w, P4* p, int b, int e);
  void (*unpack)(const P4* p, double* x, int b, int e);
};

// The fastest build this CPU runs; simd = false: the portable one (tests compare the two).
// DRAPE_XPBD_SIMD=0 in the environment forces the portable build.
const Kernels& kernels(bool simd = true);

}  // namespace drape::sim::xpbd
