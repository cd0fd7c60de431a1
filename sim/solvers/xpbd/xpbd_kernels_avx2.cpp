// XPBD's hot loops built for AVX2+FMA (sim/solvers/xpbd/xpbd_kernels.hpp); compiled with -mavx2
// -mfma on x86-64 only (sim/CMakeLists.txt) and called only when the CPU reports both.
#include <algorithm>
#include <cstring>

#include "sim/solvers/xpbd/xpbd_kernels.hpp"

#if defined(DRAPE_XPBD_AVX2)
namespace drape::sim::xpbd::avx2 {
#include "sim/solvers/xpbd/xpbd_kernels.inl"
extern const Kernels kKernels;
const Kernels kKernels = make_kernels("avx2", 8);
}  // namespace drape::sim::xpbd::avx2
#endif
