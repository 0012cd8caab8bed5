// GCC's entry to an OpenMP parallel region (libgomp's ABI: `GOMP_parallel`), defined here for
// the whole process so that regions of one thread skip libgomp's team.
//
// libgomp runs a region of one thread — `num_threads(1)`, an `if` clause that is false, or a
// dynamic team size that comes out at one — as a team of one: it sets the team up and ends it
// with a barrier whose last thread wakes the others with a futex system call, though there are
// none (libgomp/config/linux/bar.c, gomp_team_barrier_wait_end). CHOLMOD's supernodal
// factorisation opens such regions for every supernode (`#pragma omp parallel for ... if (size
// above a threshold)` in t_cholmod_super_numeric.c, several per supernode), and with dynamic
// teams (CholmodSolver::factorize) libgomp reads the load average and the affinity mask, two
// more system calls, for each region whose `if` holds. A site of a stiffness map
// (`tissueprobe-cli indent` at a cell middle, one thread) made 536,662 futex calls and 45,000 of
// each of the other two; a region of one thread cost 1.1 µs on the 2-core VM of bench/README.md
// (0.02 µs run directly), and a level-3 factorisation on one thread took 193–247 ms with
// libgomp's teams against 134–177 ms without (BM_Factorization/3, alternated).
//
// The dynamic linker finds this definition before libgomp's (the executable comes first in its
// search order, and the linker exports the definition because the shared libraries linked in,
// CHOLMOD among them, refer to it). A region that libgomp would give one thread, opened outside
// every other region (omp_get_level() 0), runs its body here directly: its one thread sees what
// the one thread of libgomp's team sees — omp_get_thread_num() 0, omp_get_num_threads() 1,
// worksharing loops and barriers of that thread alone (libgomp runs them orphaned), an inactive
// region (omp_in_parallel() false) — except omp_get_level(), 0 instead of 1, which neither
// CHOLMOD nor this code asks. Every other region goes to libgomp's GOMP_parallel.
#include "solver/OpenMpRegions.h"

#include <dlfcn.h>
#include <omp.h>

#include <cstdio>
#include <cstdlib>

namespace tp {

namespace {

thread_local std::uint64_t directRegions = 0;

using ParallelEntry = void (*)(void (*)(void*), void*, unsigned, unsigned);

ParallelEntry libgompParallel() {
  static const ParallelEntry next = [] {
    auto f = reinterpret_cast<ParallelEntry>(dlsym(RTLD_NEXT, "GOMP_parallel"));
    if (!f) {
      std::fprintf(stderr, "TissueProbe: the OpenMP runtime's GOMP_parallel was not found\n");
      std::abort();
    }
    return f;
  }();
  return next;
}

// The team size libgomp would choose is one (gomp_resolve_num_threads): asked for one (an `if`
// that is false passes one), asked for none with this thread's nthreads-var at one, or dynamic
// teams with nthreads-var at one (gomp_dynamic_max_threads caps the processors at nthreads-var).
bool oneThread(unsigned asked) {
  if (asked == 1) return true;
  return omp_get_max_threads() == 1 && (asked == 0 || omp_get_dynamic());
}

}  // namespace

std::uint64_t serialRegionsRunDirectly() { return directRegions; }

OmpThreadsScope::OmpThreadsScope(int threads) : restore_(omp_get_max_threads()) {
  omp_set_num_threads(threads);
}

OmpThreadsScope::~OmpThreadsScope() {
  omp_set_num_threads(restore_);
}

}  // namespace tp

extern "C" void GOMP_parallel(void (*fn)(void*), void* data, unsigned numThreads,
                              unsigned flags) {
  if (tp::oneThread(numThreads) && omp_get_level() == 0) {
    ++tp::directRegions;
    fn(data);
    return;
  }
  tp::libgompParallel()(fn, data, numThreads, flags);
}
