// Speed of the pieces of an indentation on the shipped default meristem, unrefined and refined at
// the probe to levels 1–3, and of the published method (implicit Euler + CG) on the same curve.
// Run: build/bin/bench_indentation [--benchmark_filter=...]; see bench/README.md.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <vector>

#include "BenchCommon.h"
#include "solver/CholmodSolver.h"
#include "solver/Newton.h"

using namespace tp;
using namespace tp::bench;

namespace {

void addSizeCounters(benchmark::State& state, const Model& m) {
  state.counters["vertices"] = m.complex().vertexCount();
  state.counters["triangles"] = m.complex().triangleCount();
  state.counters["unknowns"] = m.dofs().freeCount();
}

// Gradient and Hessian of the whole tissue at the turgid state.
void BM_Assembly(benchmark::State& state) {
  Setup s = prepare(refinedMeristem(static_cast<int>(state.range(0))));
  Evaluation ev;
  for (auto _ : state) {
    s.model->evaluate(s.indentation->turgidState(), ev, true);
    benchmark::DoNotOptimize(ev.hessian.data());
  }
  addSizeCounters(state, *s.model);
}

// One numeric CHOLMOD factorisation of that tangent (symbolic analysis done once, outside).
void BM_Factorization(benchmark::State& state) {
  Setup s = prepare(refinedMeristem(static_cast<int>(state.range(0))));
  Evaluation ev;
  s.model->evaluate(s.indentation->turgidState(), ev, true);
  CholmodSolver chol;
  chol.analyze(s.model->pattern());
  for (auto _ : state) {
    const auto st = chol.factorize(ev.hessian, 0.0);
    if (st != CholmodSolver::Status::Ok) state.SkipWithError("tangent not positive definite");
  }
  addSizeCounters(state, *s.model);
  state.counters["factor_nonzeros"] = chol.factorNonzeros();
}

// One full Newton iteration: assembly, factorisation, solve, one energy evaluation.
void BM_NewtonIteration(benchmark::State& state) {
  Setup s = prepare(refinedMeristem(static_cast<int>(state.range(0))));
  const Points& x = s.indentation->turgidState();
  Evaluation ev;
  CholmodSolver chol;
  chol.analyze(s.model->pattern());
  const auto& freeDofs = s.model->dofs().freeDofs();
  Eigen::VectorXd g(freeDofs.size()), dx;
  for (auto _ : state) {
    s.model->evaluate(x, ev, true);
    for (size_t i = 0; i < freeDofs.size(); ++i) g[i] = ev.gradient[freeDofs[i]];
    chol.factorize(ev.hessian, 0.0);
    chol.solve(g, dx);
    benchmark::DoNotOptimize(s.model->energy(x));
  }
  addSizeCounters(state, *s.model);
}

// One equilibrium after a depth step of 1 % of a cell size, warm-started from the previous one
// (from 5 % of a cell size on, each step 1 % deeper), with the median step time compared with one
// numeric factorisation of the same tangent measured in the same run.
void BM_EquilibriumStep(benchmark::State& state) {
  auto cc = refinedMeristem(static_cast<int>(state.range(0)));
  Setup s = prepare(cc);
  const double cell = cellSize(*refinedMeristem(0));
  std::string error;
  const double median = medianStepSeconds(*s.indentation, 0.05 * cell, 0.01 * cell,
                                          [&] { return state.KeepRunning(); }, error);
  if (!error.empty()) state.SkipWithError(error.c_str());
  auto& solver = dynamic_cast<StaticSolver&>(s.indentation->solver());
  std::vector<double> factor;
  for (int k = 0; k < 5; ++k) factor.push_back(solver.timeFactorization());
  std::sort(factor.begin(), factor.end());
  const double f = factor[factor.size() / 2];
  addSizeCounters(state, *s.model);
  state.counters["median_step_ms"] = 1e3 * median;
  state.counters["factorization_ms"] = 1e3 * f;
  state.counters["step_over_factorization"] = median / f;
}

// A whole 50-step loading curve to a depth of 10 % of a cell size (turgid state and placement
// excluded: they are solved before the clock starts). `predictor`: each step starts from the
// polynomial through the last equilibria (ours) or from the last equilibrium with the probe moved
// (the published method).
void curve(benchmark::State& state, SolverKind kind, bool predictor) {
  auto cc = refinedMeristem(static_cast<int>(state.range(0)));
  const double cell = cellSize(*refinedMeristem(0));
  IndentationSettings settings;
  settings.maxDepth = 0.1 * cell;
  settings.steps = 50;
  settings.predictor = predictor;
  SolverOptions options;
  options.kind = kind;
  double force = 0;
  int solverIterations = 0, cg = 0, factorizations = 0;
  SolverTotals spent;
  for (auto _ : state) {
    state.PauseTiming();
    Setup s = prepare(cc, options, settings);
    const SolverTotals before = s.indentation->solver().totals();
    state.ResumeTiming();
    const auto points = s.indentation->run();
    state.PauseTiming();
    if (!points.back().converged) state.SkipWithError(s.indentation->lastMessage().c_str());
    force = points.back().force;
    const SolverTotals after = s.indentation->solver().totals();
    solverIterations = after.iterations - before.iterations;
    cg = after.pcgIterations - before.pcgIterations;
    factorizations = after.factorizations - before.factorizations;
    spent.assemblySeconds = after.assemblySeconds - before.assemblySeconds;
    spent.factorSeconds = after.factorSeconds - before.factorSeconds;
    spent.pcgSeconds = after.pcgSeconds - before.pcgSeconds;
    spent.lineSearchSeconds = after.lineSearchSeconds - before.lineSearchSeconds;
    state.ResumeTiming();
  }
  state.counters["final_force_uN"] = force;
  state.counters["iterations"] = solverIterations;
  state.counters["cg_iterations"] = cg;
  state.counters["factorizations"] = factorizations;
  state.counters["depth_um"] = settings.maxDepth;
  state.counters["assembly_s"] = spent.assemblySeconds;
  state.counters["factorization_s"] = spent.factorSeconds;
  state.counters["cg_s"] = spent.pcgSeconds;
  state.counters["gradients_s"] = spent.lineSearchSeconds;
}

void BM_LoadingCurve(benchmark::State& state) { curve(state, SolverKind::Newton, true); }
// The published method: implicit Euler + CG relaxed to rest from the last equilibrium.
void BM_ReferenceCurve(benchmark::State& state) {
  curve(state, SolverKind::ImplicitEulerCG, false);
}
// What each half of the difference is worth: Newton without the predictor, and the reference
// with it.
void BM_LoadingCurveNoPredictor(benchmark::State& state) {
  curve(state, SolverKind::Newton, false);
}
void BM_ReferenceCurveWithPredictor(benchmark::State& state) {
  curve(state, SolverKind::ImplicitEulerCG, true);
}

}  // namespace

BENCHMARK(BM_Assembly)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Factorization)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NewtonIteration)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EquilibriumStep)->DenseRange(0, 3)->Iterations(21)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LoadingCurve)->DenseRange(0, 3)->Iterations(1)->Unit(benchmark::kSecond);
// The reference takes minutes per curve: levels 0 and 1 by default, all with TP_BENCH_ALL=1.
BENCHMARK(BM_ReferenceCurve)
    ->DenseRange(0, std::getenv("TP_BENCH_ALL") ? 3 : 1)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK(BM_LoadingCurveNoPredictor)->Arg(0)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_ReferenceCurveWithPredictor)->Arg(0)->Iterations(1)->Unit(benchmark::kSecond);

BENCHMARK_MAIN();
