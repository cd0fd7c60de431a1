// XPBD's hot loops, portable build, and the run-time choice between it and the AVX2 build.
#include "sim/xpbd_kernels.hpp"

#include <cstdlib>
#include <cstring>

namespace drape::sim::xpbd {

namespace portable {
#include "sim/xpbd_kernels.inl"
const Kernels kKernels{"portable", &project_tris, &project_rows, &pack, &unpack};
}  // namespace portable

#if defined(DRAPE_XPBD_AVX2)
namespace avx2 {
extern const Kernels kKernels;
}
#endif

const Kernels& kernels(bool simd) {
#if defined(DRAPE_XPBD_AVX2)
  static const bool use = [] {
    const char* env = std::getenv("DRAPE_XPBD_SIMD");
    if (env && std::strcmp(env, "0") == 0) return false;
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  if (simd && use) return avx2::kKernels;
#else
  (void)simd;
#endif
  return portable::kKernels;
}

}  // namespace drape::sim::xpbd
