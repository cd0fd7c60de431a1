// XPBD's hot loops built for AVX-512 (sim/solvers/xpbd/xpbd_kernels.hpp); compiled with -mavx512f
// -mavx512vl -mavx512dq -mavx512bw -mavx2 -mfma on x86-64 only (sim/CMakeLists.txt) and called only
// when the CPU reports all of them. It packs sixteen triangles per single-precision pack
// (Kernels::tri_lanes).
#if defined(__GNUC__) && !defined(__clang__)
// GCC 12's _mm512_extractf32x4_ps passes _mm_undefined_ps() as its (unused) merge source, which
// -Wmaybe-uninitialized reports once inlined.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <immintrin.h>

#include <algorithm>
#include <cstring>

#include "sim/solvers/xpbd/xpbd_kernels.hpp"

#if defined(DRAPE_XPBD_AVX2)
namespace drape::sim::xpbd::avx512 {
#include "sim/solvers/xpbd/xpbd_kernels.inl"
extern const Kernels kKernels;
const Kernels kKernels = make_kernels("avx512", 16);
}  // namespace drape::sim::xpbd::avx512
#endif
