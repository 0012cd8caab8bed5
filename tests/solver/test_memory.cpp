// The allocator setting of solver/Memory.h: a large block freed and allocated again reuses the
// pages already touched instead of mapping (and faulting in) fresh ones.
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <cstring>
#include <memory>

#include "solver/Memory.h"

namespace {

long minorFaults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TP_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define TP_ASAN 1
#endif

TEST(KeepFreedMemory, ALargeBlockAllocatedAgainDoesNotFaultItsPagesAgain) {
#if defined(TP_ASAN)
  GTEST_SKIP() << "AddressSanitizer replaces the allocator this setting tunes";
#else
  tp::keepFreedMemory();
  tp::keepFreedMemory();  // idempotent
  // 64 MB: above glibc's largest automatic mmap threshold (32 MB), so with its defaults every
  // such block is a fresh mapping and each of its 16,384 pages faults when first written.
  constexpr size_t kBytes = size_t{64} << 20;
  constexpr long kPages = static_cast<long>(kBytes / 4096);
  const auto touch = [] {
    std::unique_ptr<char[]> block(new char[kBytes]);
    std::memset(block.get(), 1, kBytes);
    asm volatile("" : : "r"(block.get()) : "memory");  // the block and its writes are kept
  };
  touch();  // the first time the pages fault in
  const long before = minorFaults();
  touch();
  const long again = minorFaults() - before;
  EXPECT_LT(again, kPages / 20) << again << " page faults for a block of " << kPages << " pages";
#endif
}

}  // namespace
