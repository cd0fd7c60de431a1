// XPBD's hot loops, portable build, the packing of elements into lanes, and the run-time choice
// between the portable and the AVX2 build.
#include "sim/solvers/xpbd/xpbd_kernels.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>

namespace drape::sim::xpbd {

namespace portable {
#include "sim/solvers/xpbd/xpbd_kernels.inl"
const Kernels kKernels = make_kernels("portable", 8);
}  // namespace portable

template <class T, int L>
void pack_triangles(const Tri* tris, int b, int e, int scratch, std::vector<TriPackT<T, L>>& out,
                    int shares) {
  const int cnt = (e - b + L - 1) / L;
  out.reserve(out.size() + cnt);
  for (int k0 = b; k0 < e; k0 += L) {
    TriPackT<T, L> P{};  // padding lanes: coefficients 0
    const int pad = scratch + share_of((k0 - b) / L, cnt, shares);
    for (int l = 0; l < L; ++l) {
      const int k = k0 + l;
      P.k[l] = k < e ? k : -1;
      for (int q = 0; q < 3; ++q) P.v[q][l] = k < e ? tris[k].v[q] : pad;
      if (k >= e) continue;
      for (int j = 0; j < 6; ++j) P.D[j][l] = static_cast<T>(tris[k].D[j]);
      for (int a = 0; a < 3; ++a) P.ia[a][l] = static_cast<T>(tris[k].ia[a]);
    }
    out.push_back(P);
  }
}
template void pack_triangles<double, 4>(const Tri*, int, int, int, std::vector<TriPack>&, int);
template void pack_triangles<float, 8>(const Tri*, int, int, int, std::vector<TriPack8>&, int);
template void pack_triangles<float, 16>(const Tri*, int, int, int, std::vector<TriPack16>&, int);

template <class T, int L>
void RowPackDataT<T, L>::clear() {
  off.assign(1, 0);
  colv.clear();
  blk.clear();
  val.clear();
  ik.clear();
  ai.clear();
  slot.clear();
}

template <class T, int L>
void RowPackDataT<T, L>::append(const int* boff, const int* bcol, const double* bval,
                                const double* bik, int b, int e, int scratch, int shares) {
  if (static_cast<int>(slot.size()) < e) slot.resize(e, -1);
  const int cnt = (e - b + L - 1) / L;
  // Sized once, then written in place (growing by push_back cost ~10 ms at 128^2).
  size_t entries = 0;
  for (int r0 = b; r0 < e; r0 += L) {
    int len = 0;
    for (int r = r0; r < std::min(e, r0 + L); ++r) len = std::max(len, boff[r + 1] - boff[r]);
    entries += len;
  }
  const size_t e0 = colv.size(), p0 = blk.size() / L;
  colv.resize(e0 + L * entries);
  val.resize(3 * (e0 + L * entries));
  ik.resize(3 * L * (p0 + cnt));
  blk.resize(L * (p0 + cnt));
  ai.resize(6 * L * (p0 + cnt), T(0));
  size_t k = e0 / L;  // the next entry (L lanes each)
  for (int r0 = b; r0 < e; r0 += L) {
    const int p = packs();
    const int lanes = std::min(L, e - r0);
    const int pad = scratch + share_of((r0 - b) / L, cnt, shares);
    int len = 0;
    for (int l = 0; l < lanes; ++l) len = std::max(len, boff[r0 + l + 1] - boff[r0 + l]);
    for (int i = 0; i < len; ++i, ++k) {
      for (int l = 0; l < L; ++l) {
        const int r = r0 + l;
        const bool real = l < lanes && i < boff[r + 1] - boff[r];
        colv[L * k + l] = real ? bcol[boff[r] + i] : pad;
        for (int a = 0; a < 3; ++a)
          val[3 * L * k + L * a + l] = real ? static_cast<T>(bval[3 * (boff[r] + i) + a]) : T(0);
      }
    }
    off.push_back(off.back() + len);
    for (int a = 0; a < 3; ++a)
      for (int l = 0; l < L; ++l)
        ik[3 * L * p + L * a + l] = l < lanes ? static_cast<T>(bik[3 * (r0 + l) + a]) : T(0);
    for (int l = 0; l < L; ++l) {
      blk[L * p + l] = l < lanes ? r0 + l : -1;
      if (l < lanes) slot[r0 + l] = L * p + l;
    }
  }
}
template struct RowPackDataT<double, 4>;
template struct RowPackDataT<float, 8>;
template struct RowPackDataT<float, 16>;

namespace {
std::atomic<SimdLimit>& limit_store() {
  static std::atomic<SimdLimit> limit{SimdLimit::kWidest};
  return limit;
}
SimdLimit simd_limit() {
  return limit_store().load(std::memory_order_relaxed);
}
}  // namespace

void limit_simd(SimdLimit limit) {
  limit_store().store(limit, std::memory_order_relaxed);
}

std::optional<SimdLimit> parse_simd_limit(const std::string& name) {
  if (name == "0" || name == "none") return SimdLimit::kNone;
  if (name == "avx2") return SimdLimit::kAvx2;
  if (name == "avx512" || name == "widest") return SimdLimit::kWidest;
  return std::nullopt;
}

#if defined(DRAPE_XPBD_AVX2)
namespace avx2 {
extern const Kernels kKernels;
}
namespace avx512 {
extern const Kernels kKernels;
}

namespace {
// The SIMD builds this CPU runs within the limit, narrowest first.
std::vector<const Kernels*> simd_builds() {
  std::vector<const Kernels*> out;
  if (simd_limit() == SimdLimit::kNone) return out;
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) return out;
  out.push_back(&avx2::kKernels);
  if (simd_limit() == SimdLimit::kAvx2) return out;
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
      __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw"))
    out.push_back(&avx512::kKernels);
  return out;
}
}  // namespace
#endif

const Kernels& kernels(bool simd) {
#if defined(DRAPE_XPBD_AVX2)
  static const std::vector<const Kernels*> builds = simd_builds();
  if (simd && !builds.empty()) return *builds.back();
#else
  (void)simd;
#endif
  return portable::kKernels;
}

std::vector<const Kernels*> all_kernels() {
  std::vector<const Kernels*> out{&portable::kKernels};
#if defined(DRAPE_XPBD_AVX2)
  for (const Kernels* k : simd_builds()) out.push_back(k);
#endif
  return out;
}

}  // namespace drape::sim::xpbd
