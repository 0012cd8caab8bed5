// Scaling of one equilibrium with the number of unknowns: the shipped default meristem (7k
// unknowns) and its globally refined copies (each triangle into four, every wall at once: 39k,
// 183k, 800k unknowns — a level multiplies the unknowns by about five, not four, because the
// junction edges of the cell complex are shared by three walls), time per equilibrium
// (warm-started depth steps of 1 % of a cell size) and peak memory.
// bench/report.py fits time ∝ unknowns^k to the JSON output (see bench/README.md).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <vector>

#include "BenchCommon.h"
#include "solver/Newton.h"
#include "tissue/Refine.h"

using namespace tp;
using namespace tp::bench;

namespace {

void BM_EquilibriumScaling(benchmark::State& state) {
  const int level = static_cast<int>(state.range(0));
  const CellComplex& base = *defaultMeristem();
  const double inf = std::numeric_limits<double>::infinity();
  auto cc = std::make_shared<const CellComplex>(
      level == 0 ? base : refineNear(base, Vec3::Zero(), inf, level));
  Setup s = prepare(0, defaultSettings(), cc);  // the globally refined copy as the tissue
  const double cell = meanCellSize(base);
  std::string error;
  const double median = medianStepSeconds(s.indentation(), 0.05 * cell, 0.01 * cell,
                                          [&] { return state.KeepRunning(); }, error);
  if (!error.empty()) state.SkipWithError(error.c_str());
  auto& solver = dynamic_cast<StaticSolver&>(s.indentation().solver());
  state.counters["unknowns"] = s.model().dofs().freeCount();
  state.counters["median_step_s"] = median;
  state.counters["factorization_s"] = solver.timeFactorization();
  state.counters["peak_memory_MB"] = peakMemoryMB();
}

}  // namespace

BENCHMARK(BM_EquilibriumScaling)->DenseRange(0, 3)->Iterations(5)->Unit(benchmark::kSecond);

BENCHMARK_MAIN();
