// OpenMP regions of one thread run directly (solver/OpenMpRegions.h): which regions go that way,
// and that their loops, reductions and barriers give what libgomp's team of one gives. That
// CHOLMOD's own regions come through this process's GOMP_parallel: test_cholmod.cpp.
#include <gtest/gtest.h>

#include <omp.h>

#include <vector>

#include "solver/OpenMpRegions.h"

using namespace tp;

namespace {

// GCC compiles a parallel region into a call of GOMP_parallel; clang (the sanitizer build) into
// libomp's __kmpc_fork_call, which the count does not see. CHOLMOD, built by Debian with GCC,
// calls GOMP_parallel either way.
#if defined(__clang__)
constexpr bool kRegionsCounted = false;
#else
constexpr bool kRegionsCounted = true;
#endif

// Restores the calling thread's OpenMP settings.
struct OmpSettings {
  int threads = omp_get_max_threads();
  int dynamic = omp_get_dynamic();
  ~OmpSettings() {
    omp_set_num_threads(threads);
    omp_set_dynamic(dynamic);
  }
};

}  // namespace

TEST(OpenMpRegions, ARegionOfOneThreadRunsDirectlyWithTheSameLoopsAndReductions) {
  OmpSettings keep;
  omp_set_dynamic(0);
  const int n = 1000;
  std::vector<int> visits(n, 0);
  long sum = 0;
  int team = -1, id = -1;
  bool inParallel = true;
  const auto before = serialRegionsRunDirectly();
  const bool big = visits.size() > 1000000;  // false: the `if` clause CHOLMOD uses
#pragma omp parallel if (big) reduction(+ : sum)
  {
    team = omp_get_num_threads();
    id = omp_get_thread_num();
    inParallel = omp_in_parallel();
#pragma omp for schedule(dynamic, 7)
    for (int i = 0; i < n; ++i) {
      ++visits[i];
      sum += i;
    }
#pragma omp barrier
  }
  if (kRegionsCounted) {
    EXPECT_EQ(serialRegionsRunDirectly(), before + 1);
  }
  EXPECT_EQ(team, 1);
  EXPECT_EQ(id, 0);
  EXPECT_FALSE(inParallel);
  EXPECT_EQ(sum, static_cast<long>(n) * (n - 1) / 2);
  for (int i = 0; i < n; ++i) ASSERT_EQ(visits[i], 1) << "item " << i;

  // num_threads(1), and no clause with nthreads-var at one: directly too.
#pragma omp parallel num_threads(1)
  { team = omp_get_num_threads(); }
  EXPECT_EQ(team, 1);
  omp_set_num_threads(1);
#pragma omp parallel
  { team = omp_get_num_threads(); }
  EXPECT_EQ(team, 1);
  if (kRegionsCounted) {
    EXPECT_EQ(serialRegionsRunDirectly(), before + 3);
  }
}

TEST(OpenMpRegions, DynamicTeamsCappedAtOneThreadRunDirectly) {
  OmpSettings keep;
  omp_set_num_threads(1);  // a stiffness map's worker
  omp_set_dynamic(1);      // CholmodSolver::factorize
  int team = -1;
  const auto before = serialRegionsRunDirectly();
#pragma omp parallel num_threads(4)
  { team = omp_get_num_threads(); }
  EXPECT_EQ(team, 1);
  if (kRegionsCounted) {
    EXPECT_EQ(serialRegionsRunDirectly(), before + 1);
  }
}

TEST(OpenMpRegions, TeamsOfSeveralThreadsAndNestedRegionsGoToLibgomp) {
  OmpSettings keep;
  omp_set_dynamic(0);
  const auto before = serialRegionsRunDirectly();
  std::vector<int> ids(3, -1);
  int level = -1;
#pragma omp parallel num_threads(3)
  {
    ids[omp_get_thread_num()] = omp_get_thread_num();
#pragma omp single
    level = omp_get_level();
    // A region of one thread inside another: libgomp's (its level counts the outer one).
    int inner = -1;
#pragma omp parallel num_threads(1)
    { inner = omp_get_level(); }
#pragma omp critical
    EXPECT_EQ(inner, 2);
  }
  EXPECT_EQ(ids, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(level, 1);
  EXPECT_EQ(serialRegionsRunDirectly(), before);
}
