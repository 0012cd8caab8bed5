// Scaling of one equilibrium with the number of unknowns: a 750-cell meristem (about 10k
// unknowns) and its globally refined copies (each triangle into four: about 40k, 160k, 640k),
// time per equilibrium (warm-started depth steps of 1 % of a cell size) and peak memory.
// bench/fit_exponent.py fits time ∝ unknowns^k to the JSON output (see bench/README.md).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <vector>

#include "BenchCommon.h"
#include "solver/Newton.h"
#include "tissue/Meristem.h"
#include "tissue/Refine.h"

using namespace tp;
using namespace tp::bench;

namespace {

using Clock = std::chrono::steady_clock;

void BM_EquilibriumScaling(benchmark::State& state) {
  const int level = static_cast<int>(state.range(0));
  MeristemParams p;
  p.cells = 750;
  p.shape.radius = 45;
  p.shape.capHeight = 38;
  const CellComplex base = generateMeristem(p);
  const double inf = std::numeric_limits<double>::infinity();
  auto cc = std::make_shared<const CellComplex>(
      level == 0 ? base : refineNear(base, Vec3::Zero(), inf, level));
  Setup s = prepare(cc);
  const double cell = cellSize(base);
  const double d0 = 0.05 * cell, d1 = 0.06 * cell;
  s.indentation->goToDepth(d0);
  s.indentation->goToDepth(d1);
  std::vector<double> times;
  double depth = d1;
  for (auto _ : state) {
    depth += d1 - d0;  // always a new depth: no step returns to a state already solved
    const auto t = Clock::now();
    const CurvePoint pt = s.indentation->goToDepth(depth);
    times.push_back(std::chrono::duration<double>(Clock::now() - t).count());
    if (!pt.converged) state.SkipWithError("step did not converge");
  }
  std::sort(times.begin(), times.end());
  auto& solver = dynamic_cast<StaticSolver&>(s.indentation->solver());
  state.counters["unknowns"] = s.model->dofs().freeCount();
  state.counters["median_step_s"] = times[times.size() / 2];
  state.counters["factorization_s"] = solver.timeFactorization();
  state.counters["peak_memory_MB"] = peakMemoryMB();
}

}  // namespace

BENCHMARK(BM_EquilibriumScaling)->DenseRange(0, 3)->Iterations(5)->Unit(benchmark::kSecond);

BENCHMARK_MAIN();
