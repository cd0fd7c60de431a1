// XPBD's two hot loops (membrane triangles, tensor-bending blocks: ~60 % of a substep at 128^2,
// measured with perf), vectorised ACROSS elements: the elements of one colour (which share no
// vertex) are packed, each SIMD lane computing one of them, so the divisions, dot products and
// 3x3 solves of a pack run side by side instead of as one long dependency chain.
// Two precisions: four doubles per pack, positions padded to four doubles (P4) with the inverse
// mass in the fourth lane (a 4x4 transpose of four vertices gives the lanes' x, y, z and w); or
// (the solver's default, XpbdOptions::single_precision) eight floats per pack on 16-byte P4f
// displacements from double anchors, the state itself staying double.
// The same source (sim/solvers/xpbd/xpbd_kernels.inl) is compiled three times: portable (x86-64
// baseline: SSE2, or any other target) and, on x86-64, with AVX2+FMA and with AVX-512 (F, VL, DQ,
// BW); kernels() picks the widest build the CPU has at run time. Results differ by round-off only
// (FMA contraction). In single precision the AVX-512 build packs sixteen triangles, the others
// eight (Kernels::tri_lanes); bending blocks are packed eight per pack in every build.
// No Eigen here: an inline Eigen function instantiated in the AVX2 unit could be the copy the
// linker keeps for the whole program.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sim/core/thread_pool.hpp"

namespace drape::sim::xpbd {

// A vertex position padded to 32 bytes; the fourth lane is the vertex's inverse mass (0: fixed
// or frozen), which the kernels read and never change.
struct alignas(32) P4 {
  double c[4];
};
// The single-precision form (XpbdOptions::single_precision): 16 bytes, the displacement from an
// anchor position (pack8) and the inverse mass.
struct alignas(16) P4f {
  float c[4];
};

// One membrane triangle: the three strain constraints E_uu, E_vv, E_uv of F = sum_k x_k D_k.
struct Tri {
  int32_t v[3];
  double D[6];   // F = sum_k x_k (D[2k], D[2k+1])
  double ia[3];  // 1 / (k A) for E_uu, E_vv, E_uv
};

// L triangles of one colour (scalar T), lane l holding triangle k[l] (-1: padding, whose vertices
// are the scratch vertex and whose coefficients are 0). TriPack: four doubles; TriPack8: eight
// floats.
template <class T, int L>
struct alignas(32) TriPackT {
  T D[6][L];
  T ia[3][L];
  int32_t v[3][L];
  int32_t k[L];
};
using TriPack = TriPackT<double, 4>;
using TriPack8 = TriPackT<float, 8>;
using TriPack16 = TriPackT<float, 16>;

// A colour's cnt packs in S shares, one per thread that runs them: share t is
// [share_begin(cnt, t, S), share_begin(cnt, t + 1, S)). Padding in share t uses the scratch
// vertex scratch + t (extra positions whose inverse mass is 0), so that two threads never read
// and write back the same one.
inline int share_begin(int cnt, int t, int shares) {
  return part_begin(cnt, t, shares);
}
// The share of the pack at position pos of cnt.
inline int share_of(int pos, int cnt, int shares) {
  int t = 0;
  while (t + 1 < shares && share_begin(cnt, t + 1, shares) <= pos) ++t;
  return t;
}

// Appends triangles [b, e) (one colour) as packs of L; padding lanes use the scratch vertex of
// their pack's share (share_begin).
template <class T, int L>
void pack_triangles(const Tri* tris, int b, int e, int scratch, std::vector<TriPackT<T, L>>& out,
                    int shares = 1);
inline void pack_triangles(const Tri* tris, int b, int e, int scratch, std::vector<TriPack>& out,
                           int shares = 1) {
  pack_triangles<double, 4>(tris, b, e, scratch, out, shares);
}

// Tensor-bending blocks (three linear vector constraints sharing one stencil each; see
// XpbdSolver::cook) packed L per pack, one block per lane: pack p's stencil entries are
// [off[p], off[p + 1]) (the longest of its blocks; shorter ones are padded with the scratch
// vertex and coefficient 0). Entry k: vertices colv[L k + l], coefficients val[3L k + L a + l] of
// rows a = 0, 1, 2. Per pack: the inverse stiffnesses ik[3L p + L a + l], the inverse of the 3x3
// system matrix ai[6L p + L m + l] (m: 00 01 02 11 12 22; all 0: the lane does nothing) and the
// block index blk[L p + l] (-1: padding).
template <class T>
struct RowPacksT {
  const int* off;
  const int32_t* colv;
  const T* val;
  const T* ik;
  const T* ai;
  const int32_t* blk;
};
using RowPacks = RowPacksT<double>;

template <class T, int L>
struct RowPackDataT {
  std::vector<int> off{0};
  std::vector<int32_t> colv, blk;
  std::vector<T> val, ik, ai;
  std::vector<int> slot;  // per block: L * pack + lane
  void clear();
  // Packs the blocks of the CSR (boff, bcol, bval: 3 per entry; bik: 3 per block), colour by
  // colour (colour c: blocks [col[c], col[c + 1])), L blocks of one colour a pack, the packs of a
  // colour in `shares` shares whose padding uses the share's scratch vertex (share_begin). The
  // packs are filled on `pool` (null: on this thread; the same arrays either way). pack_col:
  // each colour's first pack, and the packs in all (size colours + 1).
  void assign(const int* boff, const int* bcol, const double* bval, const double* bik,
              const std::vector<int>& col, int scratch, int shares, ThreadPool* pool,
              std::vector<int>& pack_col);
  int packs() const { return static_cast<int>(off.size()) - 1; }
  // The inverse system matrix entry m of a block.
  T& ai_of(int block, int m) {
    const int s = slot[block];
    return ai[6 * L * (s / L) + L * m + s % L];
  }
  RowPacksT<T> view() const {
    return RowPacksT<T>{off.data(), colv.data(), val.data(), ik.data(), ai.data(), blk.data()};
  }
};
using RowPackData = RowPackDataT<double, 4>;
using RowPackData8 = RowPackDataT<float, 8>;
using RowPackData16 = RowPackDataT<float, 16>;

struct Kernels {
  const char* name;  // "avx512", "avx2" or "portable"
  // The single-precision triangle pack width this build runs fastest: 16 (AVX-512, 1.4x the
  // eight-lane kernel at 128^2, measured) or 8. Every build has the kernels of both widths
  // (tris8/rows8, tris16/rows16), so that builds and widths can be compared. Bending blocks are
  // packed in eights by every build: a block gathers and scatters ~10 vertices for ~20
  // multiply-adds, and the sixteen-lane kernel measured 1.1x slower at 128^2; rows16 stays for
  // that comparison.
  int tri_lanes;
  // Projects triangle packs [b, e) once (Gauss-Seidel within a triangle: E_uu, E_vv, E_uv one
  // after the other). lambda: the triangles' multipliers (3 per triangle index), or null when
  // they are reset every substep.
  void (*tris)(const TriPack* packs, int b, int e, P4* x, double ih2, double* lambda);
  // Projects bending packs [b, e) once; lambda: 3 vectors (9 doubles) per block, or null.
  void (*rows)(const RowPacks& rp, int b, int e, P4* x, double ihb, double* lambda);
  // Positions (3 doubles per vertex) and inverse masses to and from the padded form, [b, e).
  void (*pack)(const double* x, const double* w, P4* p, int b, int e);
  void (*unpack)(const P4* p, double* x, int b, int e);
  // The same in single precision, eight elements per pack, on each position's displacement from
  // a double anchor a: p = float(x - a). (XpbdSolver takes the positions at a frame's start as
  // anchors and renews them once a vertex is 5 cm from its own, so a float resolves p to
  // <= 3.7e-9 m.) What the anchors contribute is summed in double when they are set
  // (anchor_triangles, anchor_rows: fa = each triangle's F at the anchors, 48 floats per pack;
  // ca = each bending block's C at the anchors, 72 floats per pack), so the kernels add only
  // displacements: F = F(a) + (d1 - d0) D_1 + (d2 - d0) D_2 (a triangle's D_k sum to 0),
  // C = C(a) + sum_j v_j d_j. unpack8 adds to x the change of each float since pack8
  // (x += p - float(x - a), in double), so a vertex the kernels did not move keeps its double
  // bits.
  void (*tris8)(const TriPack8* packs, const float* fa, int b, int e, P4f* x, double ih2,
                double* lambda);
  void (*rows8)(const RowPacksT<float>& rp, const float* ca, int b, int e, P4f* x, double ihb,
                double* lambda);
  void (*pack8)(const double* x, const double* w, const double* a, P4f* p, int b, int e);
  void (*unpack8)(const P4f* p, const double* a, double* x, int b, int e);
  // XpbdSolver's per-vertex steps of a substep for vertices [b, e) of one piece (settling scale
  // `scale`), written as its own loops are (the same arithmetic, bit for bit) so that they
  // vectorise: the prediction, x_prev = x and, where w > 0, x += h v + (h^2 / (scale m)) (m g);
  // the velocities, v = (damp / h) (x - x_prev) where w > 0, 0 where frozen (flags & frozen).
  void (*predict)(double* x, double* x_prev, const double* v, const double* w, const double* mass,
                  double scale, double h, const double* g, int b, int e);
  void (*velocities)(const double* x, const double* x_prev, double* v, const double* w,
                     const uint8_t* flags, uint8_t frozen, double damp, double h, int b, int e);
  // The motion sums over the free vertices (w > 0) of [b, e), in vertex order, v2 = |v|^2:
  // out = {max v2, sum m v2, sum m min(v2, slow2), sum m}; returns how many are free.
  int (*motion)(const double* v, const double* w, const double* mass, double slow2, int b, int e,
                double* out);
  // The anchor terms for packs [b, e), summed in double from the anchors a (3 per vertex,
  // including the scratch vertex of padding lanes) and the packs' own float coefficients.
  void (*anchor_triangles)(const TriPack8* packs, int b, int e, const double* a, float* fa);
  void (*anchor_rows)(const RowPacksT<float>& rp, int b, int e, const double* a, float* ca);
  // The same, sixteen elements per pack (96 and 144 anchor floats per pack).
  void (*tris16)(const TriPack16* packs, const float* fa, int b, int e, P4f* x, double ih2,
                 double* lambda);
  void (*rows16)(const RowPacksT<float>& rp, const float* ca, int b, int e, P4f* x, double ihb,
                 double* lambda);
  void (*anchor_triangles16)(const TriPack16* packs, int b, int e, const double* a, float* fa);
  void (*anchor_rows16)(const RowPacksT<float>& rp, int b, int e, const double* a, float* ca);
};

// The widest SIMD build kernels() may choose, process-wide: set by an executable's option
// (--simd) before the first solver is made; later calls have no effect on kernels().
enum class SimdLimit { kNone, kAvx2, kWidest };
void limit_simd(SimdLimit limit);
// Parses "0"/"none", "avx2", "avx512"/"widest"; nullopt for anything else.
std::optional<SimdLimit> parse_simd_limit(const std::string& name);

// The fastest build this CPU runs within the limit (AVX-512, then AVX2+FMA); simd = false: the
// portable one (tests compare them).
const Kernels& kernels(bool simd = true);
// Every build this CPU runs, the portable one first.
std::vector<const Kernels*> all_kernels();

}  // namespace drape::sim::xpbd
