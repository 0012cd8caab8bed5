#pragma once
// Parallel regions of one thread, run without libgomp's team (core/solver/OpenMpRegions.cpp).

#include <cstdint>

namespace tp {

/// The calling thread's OpenMP team size (nthreads-var) set for the scope's lifetime and put
/// back at its end, also when an exception leaves it: where a computation must run on one thread
/// (a stiffness map's worker, whose bits must not depend on the cores; a pick's relaxation beside
/// the analysis on the other core).
class OmpThreadsScope {
 public:
  explicit OmpThreadsScope(int threads);
  ~OmpThreadsScope();
  OmpThreadsScope(const OmpThreadsScope&) = delete;
  OmpThreadsScope& operator=(const OmpThreadsScope&) = delete;

 private:
  int restore_;
};

/// How many OpenMP parallel regions of one thread the calling thread has run directly, without
/// a team (OpenMpRegions.cpp defines libgomp's GOMP_parallel entry for the whole process:
/// CHOLMOD's regions come through it too). For tests and benchmarks.
std::uint64_t serialRegionsRunDirectly();

}  // namespace tp
