#pragma once
// Parallel regions of one thread, run without libgomp's team (core/solver/OpenMpRegions.cpp).

#include <cstdint>

namespace tp {

/// How many OpenMP parallel regions of one thread the calling thread has run directly, without
/// a team (OpenMpRegions.cpp defines libgomp's GOMP_parallel entry for the whole process:
/// CHOLMOD's regions come through it too). For tests and benchmarks.
std::uint64_t serialRegionsRunDirectly();

}  // namespace tp
