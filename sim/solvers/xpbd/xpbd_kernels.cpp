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
void RowPackDataT<T, L>::assign(const int* boff, const int* bcol, const double* bval,
                                const double* bik, const std::vector<int>& col, int scratch,
                                int shares, ThreadPool* pool, std::vector<int>& pack_col) {
  // The packs first (their first block, their colour's end, their padding vertex) and their
  // entries' offsets: a pass over the block offsets alone.
  struct Pack {
    int r0, e, pad;
  };
  std::vector<Pack> packs;
  clear();
  pack_col.assign(1, 0);
  const int colours = static_cast<int>(col.size()) - 1;
  const int blocks = colours > 0 ? col[colours] : 0;
  packs.reserve(static_cast<size_t>(blocks / L + colours));
  for (int c = 0; c < colours; ++c) {
    pause_point();
    const int b = col[c], e = col[c + 1], cnt = (e - b + L - 1) / L;
    for (int r0 = b; r0 < e; r0 += L) {
      int len = 0;
      for (int r = r0; r < std::min(e, r0 + L); ++r) len = std::max(len, boff[r + 1] - boff[r]);
      packs.push_back({r0, e, scratch + share_of((r0 - b) / L, cnt, shares)});
      off.push_back(off.back() + len);
    }
    pack_col.push_back(static_cast<int>(packs.size()));
  }
  const int np = static_cast<int>(packs.size());
  const size_t entries = static_cast<size_t>(off.back());
  colv.resize(L * entries);
  val.resize(3 * L * entries);
  ik.resize(3 * static_cast<size_t>(L) * np);
  blk.resize(static_cast<size_t>(L) * np);
  ai.assign(6 * static_cast<size_t>(L) * np, T(0));
  slot.assign(blocks, -1);
  // Each pack as append() writes it; the packs write disjoint entries.
  auto fill = [&](int pb, int pe) {
    for (int p = pb; p < pe; ++p) {
      const int r0 = packs[p].r0, lanes = std::min(L, packs[p].e - r0), pad = packs[p].pad;
      const int len = off[p + 1] - off[p];
      for (int i = 0; i < len; ++i) {
        const size_t k = static_cast<size_t>(off[p]) + i;
        for (int l = 0; l < L; ++l) {
          const int r = r0 + l;
          const bool real = l < lanes && i < boff[r + 1] - boff[r];
          colv[L * k + l] = real ? bcol[boff[r] + i] : pad;
          for (int a = 0; a < 3; ++a)
            val[3 * L * k + L * a + l] = real ? static_cast<T>(bval[3 * (boff[r] + i) + a]) : T(0);
        }
      }
      for (int a = 0; a < 3; ++a)
        for (int l = 0; l < L; ++l)
          ik[3 * L * static_cast<size_t>(p) + L * a + l] =
              l < lanes ? static_cast<T>(bik[3 * (r0 + l) + a]) : T(0);
      for (int l = 0; l < L; ++l) {
        blk[L * static_cast<size_t>(p) + l] = l < lanes ? r0 + l : -1;
        if (l < lanes) slot[r0 + l] = L * p + l;
      }
    }
  };
  if (pool)
    pool->parallel_for(np, [&](int pb, int pe, int) { fill(pb, pe); });
  else
    fill(0, np);
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
