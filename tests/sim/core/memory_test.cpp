// sim/core/memory.hpp: with freed memory retained, an array the size of a cook's, freed and
// made again, reuses the pages the first one touched instead of faulting in new ones.
#include "sim/core/memory.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace drape::sim {
namespace {

TEST(RetainFreedMemory, AnArrayFreedAndMadeAgainTouchesNoNewPages) {
  const bool held = retain_freed_memory();
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer's allocator takes no glibc settings (its mallopt refuses them): the call
  // says so, and there are no settings whose effect to measure.
  EXPECT_FALSE(held) << "the settings reported as held under AddressSanitizer's allocator";
  EXPECT_FALSE(retain_freed_memory()) << "a second call reports the same";
  return;
#endif
  ASSERT_TRUE(held) << "glibc refused the settings";
  EXPECT_TRUE(retain_freed_memory()) << "a second call reports the settings as held";
  // 16 MiB: the size of a 128^2 cook's largest arrays (over glibc's default mmap threshold).
  constexpr size_t kDoubles = size_t{2} << 20;
  const long pages = static_cast<long>(kDoubles * sizeof(double) / 4096);
  {
    std::vector<double> a(kDoubles, 1.0);  // touched: its pages faulted in
    ASSERT_EQ(a[kDoubles - 1], 1.0);
  }
  const long f0 = process_page_faults();
  {
    std::vector<double> b(kDoubles, 2.0);
    ASSERT_EQ(b[kDoubles - 1], 2.0);
  }
  const long faults = process_page_faults() - f0;
  std::printf("a %ld-page array made again: %ld page faults\n", pages, faults);
  // Fresh pages would fault once each (4096); the retained heap: none but a few of the test's.
  EXPECT_LT(faults, pages / 20);
}

}  // namespace
}  // namespace drape::sim
