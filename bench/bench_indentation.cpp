// Speed of an indentation on the shipped default meristem, as the CLI and the application run
// it (core/experiment/Experiment.h): picking a site (refinement, rest state, first contact), the
// pieces of a Newton iteration, warm-started equilibria, whole 50-step curves to 0.5 µm at the
// tissue's own mesh (level 0) and at the converged default (levels 3 and 4), and the published
// method (implicit Euler + CG) on the same curve and mesh.
// Run: build/bin/bench_indentation [--benchmark_filter=...]; see bench/README.md.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <cmath>
#include <cstdlib>
#include <thread>
#include <vector>

#include "BenchCommon.h"
#include "experiment/Drag.h"
#include "experiment/Map.h"
#include "io/Centroids.h"
#include "solver/CholmodSolver.h"
#include "solver/Newton.h"
#include "solver/OpenMpRegions.h"
#include "tissue/RealTissue.h"

using namespace tp;
using namespace tp::bench;

namespace {

using Clock = std::chrono::steady_clock;

void addSizeCounters(benchmark::State& state, const Model& m) {
  state.counters["vertices"] = m.complex().vertexCount();
  state.counters["triangles"] = m.complex().triangleCount();
  state.counters["unknowns"] = m.dofs().freeCount();
  state.counters["nonzeros"] = static_cast<double>(m.pattern().nnz());  // of the tangent's upper triangle
}

// Picking a site, as the application does once the tissue is loaded (its rest state under turgor
// solved then): refinement around the site, the refined rest state, first contact. Sites on a
// ring around the top, a new one each time.
void pickSites(benchmark::State& state, std::shared_ptr<const CellComplex> tissue) {
  ExperimentSettings settings = defaultSettings();
  Experiment e(tissue, settings);
  e.prepareBase();
  const Vec3 top = e.restSite();
  int k = 0, vertices = 0;
  double refine = 0, rest = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const double angle = 0.7 * k++;
    settings.indentation.restSite = top + Vec3(6 * std::cos(angle), 6 * std::sin(angle), 0);
    e.setSettings(settings);
    state.ResumeTiming();
    const auto site = e.prepareSite(settings.mesh.level);
    state.PauseTiming();
    vertices = site->complex->vertexCount();
    refine += site->seconds;
    rest += site->rest.iterations;
    state.ResumeTiming();
  }
  state.counters["vertices"] = vertices;
  state.counters["rest_iterations"] = rest / state.iterations();
  state.counters["level"] = settings.mesh.level;
}

void BM_PickSite(benchmark::State& state) { pickSites(state, defaultMeristem()); }

// The same on the real flower of ../shared/data (1308 cells built from its centroids).
void BM_PickSiteRealFlower(benchmark::State& state) {
  static std::shared_ptr<const CellComplex> flower;
  if (!flower) {
    const std::string path =
        std::string(TP_SHARED_DATA_DIR) + "/refahi2021_flower_stage4/cells.csv";
    try {
      const CentroidTable table = readCentroids(path, CentroidColumns::parse("label,x,y,z"));
      flower = std::make_shared<const CellComplex>(tissueFromCentroids(table, {}));
    } catch (const std::exception& e) {
      state.SkipWithError(("no real flower: " + std::string(e.what())).c_str());
      return;
    }
  }
  pickSites(state, flower);
}

// Gradient and Hessian of the whole tissue at the turgid state, with the default bending (Koiter)
// and, for the comparison issue 11 asks for, with the hinge model.
void assembly(benchmark::State& state, BendingModel bending) {
  ExperimentSettings settings = defaultSettings();
  settings.material.bending = bending;
  Setup s = prepare(static_cast<int>(state.range(0)), settings);
  Evaluation ev;
  for (auto _ : state) {
    s.model().evaluate(s.indentation().turgidState(), ev, true);
    benchmark::DoNotOptimize(ev.hessian.data());
  }
  addSizeCounters(state, s.model());
}
void BM_Assembly(benchmark::State& state) { assembly(state, BendingModel::Koiter); }
void BM_AssemblyHinge(benchmark::State& state) { assembly(state, BendingModel::Hinge); }

// The ratio issue 11 bounds (Koiter ≤ 1.5 × hinge), measured in one process with the two
// assemblies alternated, so that the machine's drifts (on a shared VM the two separate
// benchmarks above move by ±15 % from run to run) fall on both alike: the median of 40 of each
// and the median of the 40 neighbouring ratios.
void BM_AssemblyRatio(benchmark::State& state) {
  ExperimentSettings hinge = defaultSettings();
  hinge.material.bending = BendingModel::Hinge;
  Setup k = prepare(static_cast<int>(state.range(0)));
  Setup h = prepare(static_cast<int>(state.range(0)), hinge);
  Evaluation ek, eh;
  const auto time = [](Setup& s, Evaluation& ev) {
    const auto start = Clock::now();
    s.model().evaluate(s.indentation().turgidState(), ev, true);
    benchmark::DoNotOptimize(ev.hessian.data());
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  };
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::vector<double> tk, th, ratio;
  for (auto _ : state) {
    time(k, ek);  // warm both
    time(h, eh);
    for (int i = 0; i < 40; ++i) {
      tk.push_back(time(k, ek));
      th.push_back(time(h, eh));
      ratio.push_back(tk.back() / th.back());
    }
  }
  state.counters["koiter_ms"] = median(tk);
  state.counters["hinge_ms"] = median(th);
  state.counters["ratio"] = median(ratio);
  state.counters["level"] = static_cast<double>(state.range(0));
}

// The tangent at the turgid state of a site at `level`, analysed by `chol` (not factorised).
struct TurgidTangent {
  Setup setup;
  Evaluation ev;
  TurgidTangent(int level, CholmodSolver& chol) : setup(prepare(level)) {
    setup.model().evaluate(setup.indentation().turgidState(), ev, true);
    chol.analyze(setup.model().pattern());
  }
};

// One numeric factorisation of that tangent (symbolic analysis done once, outside): the
// solver's own in single precision (the default), and CHOLMOD's in double.
void factorization(benchmark::State& state, CholmodSolver::Precision precision) {
  CholmodSolver chol;
  chol.setFactorPrecision(precision);
  TurgidTangent k(static_cast<int>(state.range(0)), chol);
  for (auto _ : state) {
    const auto st = chol.factorize(k.ev.hessian, 0.0);
    if (st != CholmodSolver::Status::Ok) state.SkipWithError("tangent not positive definite");
  }
  addSizeCounters(state, k.setup.model());
  state.counters["factor_nonzeros"] = chol.factorNonzeros();
}
void BM_Factorization(benchmark::State& state) {
  factorization(state, CholmodSolver::Precision::Single);
}
void BM_FactorizationDouble(benchmark::State& state) {
  factorization(state, CholmodSolver::Precision::Double);
}

// One preconditioner application of the conjugate gradients (both triangular solves with the
// single-precision copy of the factor, one thread), on the factor of the turgid tangent.
void BM_PreconditionerSolve(benchmark::State& state) {
  CholmodSolver chol;
  TurgidTangent k(static_cast<int>(state.range(0)), chol);
  if (chol.factorize(k.ev.hessian, 0.0) != CholmodSolver::Status::Ok) {
    state.SkipWithError("tangent not positive definite");
    return;
  }
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(k.setup.model().pattern().n);
  Eigen::VectorXd x;
  for (auto _ : state) {
    chol.solveSinglePrecision(b, x, 1);
    benchmark::DoNotOptimize(x.data());
  }
  addSizeCounters(state, k.setup.model());
  state.counters["factor_nonzeros"] = chol.factorNonzeros();
}

// One equilibrium after a depth step of 0.01 µm, warm-started from the previous one (from
// 0.05 µm on, each step 0.01 µm deeper: what a drag asks), with the median step compared with
// one numeric factorisation of the same tangent measured in the same run.
void BM_EquilibriumStep(benchmark::State& state) {
  Setup s = prepare(static_cast<int>(state.range(0)));
  std::string error;
  const double median = medianStepSeconds(s.indentation(), 0.05, 0.01,
                                          [&] { return state.KeepRunning(); }, error);
  if (!error.empty()) state.SkipWithError(error.c_str());
  auto& solver = dynamic_cast<StaticSolver&>(s.indentation().solver());
  std::vector<double> factor;
  for (int k = 0; k < 5; ++k) factor.push_back(solver.timeFactorization());
  std::sort(factor.begin(), factor.end());
  const double f = factor[factor.size() / 2];
  addSizeCounters(state, s.model());
  state.counters["median_step_ms"] = 1e3 * median;
  state.counters["factorization_ms"] = 1e3 * f;
  state.counters["step_over_factorization"] = median / f;
}

// A whole 50-step loading curve to 0.5 µm (the site prepared before the clock starts).
// `predictor`: each step starts from the polynomial through the last equilibria (ours) or from
// the last equilibrium with the probe moved (the published method).
// `bending`: the default (Koiter), or the hinge model for the comparisons with the published
// method (the implicit-Euler reference runs the published models only, so model meets model).
void curve(benchmark::State& state, SolverKind kind, bool predictor,
           BendingModel bending = BendingModel::Koiter) {
  IndentationSettings schedule;
  schedule.maxDepth = 0.5;
  schedule.steps = 50;
  schedule.predictor = predictor;
  SolverOptions options;
  options.kind = kind;
  double force = 0;
  int solverIterations = 0, cg = 0, factorizations = 0;
  SolverTotals spent;
  for (auto _ : state) {
    state.PauseTiming();
    ExperimentSettings settings = defaultSettings(schedule, options);
    settings.material.bending = bending;
    Setup s = prepare(static_cast<int>(state.range(0)), settings);
    const SolverTotals before = s.indentation().solver().totals();
    state.ResumeTiming();
    const auto points = s.indentation().run();
    state.PauseTiming();
    if (!points.back().converged) state.SkipWithError(s.indentation().lastMessage().c_str());
    force = points.back().force;
    const SolverTotals after = s.indentation().solver().totals();
    solverIterations = after.iterations - before.iterations;
    cg = after.pcgIterations - before.pcgIterations;
    factorizations = after.factorizations - before.factorizations;
    spent.assemblySeconds = after.assemblySeconds - before.assemblySeconds;
    spent.factorSeconds = after.factorSeconds - before.factorSeconds;
    spent.pcgSeconds = after.pcgSeconds - before.pcgSeconds;
    spent.lineSearchSeconds = after.lineSearchSeconds - before.lineSearchSeconds;
    addSizeCounters(state, s.model());
    state.ResumeTiming();
  }
  state.counters["final_force_uN"] = force;
  state.counters["iterations"] = solverIterations;
  state.counters["cg_iterations"] = cg;
  state.counters["factorizations"] = factorizations;
  state.counters["depth_um"] = schedule.maxDepth;
  state.counters["assembly_s"] = spent.assemblySeconds;
  state.counters["factorization_s"] = spent.factorSeconds;
  state.counters["cg_s"] = spent.pcgSeconds;
  state.counters["gradients_s"] = spent.lineSearchSeconds;
}

// A probe dragged as in the application's measurement (tests/gui/gui_window, drag rates): the
// cursor moves one pixel per 1/60 s event, 100 pixels (one probe radius, 1 µm) down and back,
// for 20 s, and each equilibrium is one DragFollower step (core/experiment/Drag.h) toward where
// the cursor is when it starts, as the application's worker takes the newest depth asked. When
// the tissue has caught up with the cursor it waits for the next event (as the application
// waits for the next request). Without the drawing, on the one OpenMP thread the application's
// worker uses beside it (BLAS keeps its threads, as there). Counters: equilibria per second,
// the depth the equilibria travelled, the deepest, Newton iterations and factorisations.
void BM_DragReplay(benchmark::State& state) {
  Setup s = prepare(static_cast<int>(state.range(0)));
  Indentation& ind = s.indentation();
  const double radius = ind.settings().probeRadius, event = 1.0 / 60, seconds = 20;
  const auto cursor = [&](double t) {  // µm, at the last event before t
    const int phase = static_cast<int>(std::floor(t / event)) % 200;
    return (phase < 100 ? phase : 200 - phase) * radius / 100;
  };
  const OmpThreadsScope oneThread(1);
  int equilibria = 0, iterations = 0, factorizations = 0;
  double travelled = 0, deepest = 0, elapsed = 0;
  for (auto _ : state) {
    DragFollower drag;
    const SolverTotals before = ind.solver().totals();
    const auto start = Clock::now();
    const auto now = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
    double last = ind.depth();
    while (now() < seconds) {
      const double t = now(), asked = cursor(t);
      if (asked == ind.depth()) {  // caught up: the next mouse event
        const double next = (std::floor(t / event) + 1) * event;
        std::this_thread::sleep_for(std::chrono::duration<double>(next - t));
        continue;
      }
      const DragStep step = drag.toward(ind, asked);
      if (step.failed()) {
        state.SkipWithError(ind.lastMessage().c_str());
        break;
      }
      if (!step.point.converged) continue;
      ++equilibria;
      iterations += step.point.iterations;
      travelled += std::abs(step.point.depth - last);
      deepest = std::max(deepest, step.point.depth);
      last = step.point.depth;
    }
    elapsed = now();
    factorizations = ind.solver().totals().factorizations - before.factorizations;
  }
  state.counters["equilibria_per_s"] = equilibria / elapsed;
  state.counters["travel_um"] = travelled;
  state.counters["deepest_um"] = deepest;
  state.counters["iterations_per_eq"] = equilibria ? double(iterations) / equilibria : 0.0;
  state.counters["factorizations"] = factorizations;
}

// The drag's steps on a fixed path, with and without the renewed chord (DragOptions::
// renewedChord), alternated three times each in this process: the cursor moves 6 pixels (0.06
// probe radii) per call, down one radius and back, for 300 calls, whatever the solves take, so
// both follow the same cursor. Counters: milliseconds per equilibrium and the probe's travel
// per second of solving (how fast it follows), medians of the three runs of each.
void BM_DragFixedPath(benchmark::State& state) {
  Setup s = prepare(static_cast<int>(state.range(0)));
  Indentation& ind = s.indentation();
  const double radius = ind.settings().probeRadius;
  const OmpThreadsScope oneThread(1);
  std::vector<double> perEq[2], speed[2];
  for (auto _ : state) {
    for (int run = 0; run < 6; ++run) {
      const int renewed = run % 2;
      ind.returnToFirstContact();
      DragOptions o;
      o.renewedChord = renewed == 1;
      DragFollower drag(o);
      int equilibria = 0;
      double travelled = 0, last = ind.depth();
      const auto start = Clock::now();
      for (int k = 0; k < 300; ++k) {
        const int phase = (6 * k) % 200;
        const double asked = (phase < 100 ? phase : 200 - phase) * radius / 100;
        if (asked == ind.depth()) continue;
        const DragStep step = drag.toward(ind, asked);
        if (step.failed()) {
          state.SkipWithError(ind.lastMessage().c_str());
          return;
        }
        if (!step.point.converged) continue;
        ++equilibria;
        travelled += std::abs(step.point.depth - last);
        last = step.point.depth;
      }
      const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
      perEq[renewed].push_back(1000 * seconds / std::max(equilibria, 1));
      speed[renewed].push_back(travelled / seconds);
    }
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  state.counters["ms_per_eq_renewed"] = median(perEq[1]);
  state.counters["ms_per_eq_assembled"] = median(perEq[0]);
  state.counters["um_per_s_renewed"] = median(speed[1]);
  state.counters["um_per_s_assembled"] = median(speed[0]);
}

void BM_LoadingCurve(benchmark::State& state) { curve(state, SolverKind::Newton, true); }
// Ours and the published method on the same (hinge) model.
void BM_LoadingCurveHinge(benchmark::State& state) {
  curve(state, SolverKind::Newton, true, BendingModel::Hinge);
}
// The published method: implicit Euler + CG relaxed to rest from the last equilibrium.
void BM_ReferenceCurve(benchmark::State& state) {
  curve(state, SolverKind::ImplicitEulerCG, false, BendingModel::Hinge);
}
// What each half of the difference is worth: Newton without the predictor, and the reference
// with it.
void BM_LoadingCurveNoPredictor(benchmark::State& state) {
  curve(state, SolverKind::Newton, false, BendingModel::Hinge);
}
void BM_ReferenceCurveWithPredictor(benchmark::State& state) {
  curve(state, SolverKind::ImplicitEulerCG, true, BendingModel::Hinge);
}

// A stiffness map (core/experiment/Map.h) of the cell middles nearest the top of the default
// meristem, at the converged default (automatic mesh to 3 %, 5 steps to 0.5 µm), with 1 or 2
// workers: sites per second, to extrapolate to the ~170 outer cells (issue 14's < 5 minutes).
void BM_MapCellMiddles(benchmark::State& state) {
  const auto cc = defaultMeristem();
  MapPlan plan;
  plan.tissue = "default meristem";
  plan.tissueDigest = tissueDigest(*cc);
  plan.settings = mapSettings(defaultSettings());
  plan.settings.indentation.steps = 5;
  auto sites = cellMiddleSites(*cc);
  std::sort(sites.begin(), sites.end(),
            [](const MapSite& a, const MapSite& b) { return a.point.z() > b.point.z(); });
  sites.resize(std::min<size_t>(sites.size(), 6));
  plan.sites = sites;
  MapRunOptions options;
  options.jobs = static_cast<int>(state.range(0));
  int done = 0, failed = 0;
  double seconds = 0;
  for (auto _ : state) {
    options.outDir = (std::filesystem::temp_directory_path() / "tp-bench-map").string();
    std::filesystem::remove_all(options.outDir);
    const auto t0 = std::chrono::steady_clock::now();
    const MapRunSummary r = runMap(cc, plan, options);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    done += r.done;
    failed += r.failed;
  }
  std::filesystem::remove_all(options.outDir);
  state.counters["sites"] = done;
  state.counters["failed"] = failed;
  state.counters["sites_per_s"] = seconds > 0 ? done / seconds : 0;
  state.counters["outer_cells"] = static_cast<double>(cellMiddleSites(*cc).size());
}

// The symbolic analysis of the turgid tangent (fill-reducing ordering, supernodes), as the
// solver does it once per mesh (StaticSolver::analyze: METIS on the graph of the vertices and
// Koiter's edge unknowns), and for comparison as cholmod_analyze does it on the graph of the
// unknowns (AMD, then METIS as AMD fills much; the better kept). A map site analyses levels 3, 2
// and often 4, and the added vertices' relaxation at level 3.
void analysis(benchmark::State& state, bool nodes) {
  const Setup s = prepare(static_cast<int>(state.range(0)));
  const std::vector<int> node = s.model().orderingNodes();
  CholmodSolver chol;
  for (auto _ : state) {
    if (nodes)
      chol.analyze(s.model().pattern(), node);
    else
      chol.analyze(s.model().pattern());
  }
  addSizeCounters(state, s.model());
  state.counters["factor_nonzeros"] = chol.factorNonzeros();
}
void BM_Analysis(benchmark::State& state) {
  analysis(state, true);
}
void BM_AnalysisOfUnknowns(benchmark::State& state) {
  analysis(state, false);
}

}  // namespace

BENCHMARK(BM_MapCellMiddles)->Arg(1)->Arg(2)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_PickSite)->Iterations(5)->Unit(benchmark::kSecond);
BENCHMARK(BM_PickSiteRealFlower)->Iterations(3)->Unit(benchmark::kSecond);
BENCHMARK(BM_Assembly)->Arg(0)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AssemblyHinge)->Arg(0)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AssemblyRatio)->Arg(0)->Arg(3)->Arg(4)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Analysis)->Arg(0)->Arg(2)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AnalysisOfUnknowns)->Arg(0)->Arg(2)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Factorization)->Arg(0)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FactorizationDouble)->Arg(0)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PreconditionerSolve)->Arg(0)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EquilibriumStep)->Arg(0)->Arg(3)->Arg(4)->Iterations(21)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DragReplay)->Arg(0)->Arg(3)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_DragFixedPath)->Arg(3)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_LoadingCurve)->Arg(0)->Arg(3)->Arg(4)->Iterations(1)->Unit(benchmark::kSecond);
// The reference takes minutes per curve: level 0 and the default level 3; TP_BENCH_ALL=1 adds 4.
BENCHMARK(BM_LoadingCurveHinge)->Arg(0)->Arg(3)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_ReferenceCurve)->Arg(0)->Arg(3)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_LoadingCurveNoPredictor)->Arg(0)->Arg(3)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_ReferenceCurveWithPredictor)->Arg(0)->Iterations(1)->Unit(benchmark::kSecond);

BENCHMARK_MAIN();
