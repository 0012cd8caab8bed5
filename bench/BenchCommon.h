#pragma once
// Shared set-up of the benchmarks: the shipped default meristem at rest under its turgor, and the
// site at its top prepared on a mesh level exactly as `tissueprobe-cli indent` and the
// application prepare it (core/experiment/Experiment.h), with the default parameters.

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "experiment/Experiment.h"

namespace tp::bench {

/// The shipped default meristem (cached).
std::shared_ptr<const CellComplex> defaultMeristem();

/// The default settings of every front end (E = 100 MPa, ν = 0.49, h = 0.2 µm, p = 0.8 MPa,
/// probe radius 1 µm, hinge bending), with the given schedule and solver.
ExperimentSettings defaultSettings(IndentationSettings schedule = {}, SolverOptions solver = {});

/// A site prepared on a mesh level: the experiment (its rest state is solved once) and the site.
struct Setup {
  std::unique_ptr<Experiment> experiment;
  std::unique_ptr<PreparedSite> site;
  Indentation& indentation() const { return *site->indentation; }
  const Model& model() const { return *site->model; }
};
/// `level` 0 is the tissue as loaded; the default automatic mesh starts at level 3.
Setup prepare(int level, ExperimentSettings settings = defaultSettings(),
              std::shared_ptr<const CellComplex> tissue = defaultMeristem());

/// Times equilibria at successive depths (from `start`, each `step` deeper, warm-started), one per
/// call of `next`, and returns the median (s) when `next` says stop. Fails if a step does not
/// converge (the message is returned in `error`).
template <class Next>
double medianStepSeconds(Indentation& ind, double start, double step, Next&& next,
                         std::string& error);

/// Peak resident memory of this process so far (MB).
double peakMemoryMB();

template <class Next>
double medianStepSeconds(Indentation& ind, double start, double step, Next&& next,
                         std::string& error) {
  using Clock = std::chrono::steady_clock;
  ind.goToDepth(start);
  ind.goToDepth(start + step);
  std::vector<double> times;
  double depth = start + step;
  while (next()) {
    depth += step;  // always a new depth: no step returns to a state already solved
    const auto t = Clock::now();
    const CurvePoint p = ind.goToDepth(depth);
    times.push_back(std::chrono::duration<double>(Clock::now() - t).count());
    if (!p.converged) error = ind.lastMessage();
  }
  if (times.empty()) return 0;
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

}  // namespace tp::bench
