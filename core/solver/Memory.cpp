#include "solver/Memory.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace tp {

void keepFreedMemory() {
#if defined(__GLIBC__)
  static const bool done = [] {
    // Measured on the 2-core VM (bench_indentation, builds alternated): BM_PickSite
    // (refinement, rest state, first contact at level 3) 1.37-1.54 s with glibc's defaults,
    // 1.13-1.18 s with these; BM_PickSiteRealFlower 3.86-4.16 s, 2.86 s (bench/README.md,
    // eighth session of 2026-12-05). A refused setting (mallopt returns 0) leaves glibc's own.
    constexpr int kLimit = 1 << 30;
    mallopt(M_MMAP_THRESHOLD, kLimit);
    mallopt(M_TRIM_THRESHOLD, kLimit);
    return true;
  }();
  (void)done;
#endif
}

}  // namespace tp
