#pragma once
// Shared set-up of the benchmarks: the shipped default meristem, refined at the probe like
// `tissueprobe-cli indent --refine L`, with the default material and a turgid, placed probe.

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "experiment/Indentation.h"

namespace tp::bench {

/// The default parameters of the CLI (E = 100 MPa, ν = 0.49, h = 0.2 µm, p = 0.8 MPa, probe
/// radius 1 µm, hinge bending).
Material defaultMaterial();
constexpr double kPressure = 0.8;
constexpr double kProbeRadius = 1.0;

/// Cube root of the mean cell volume (µm): "a cell size".
double cellSize(const CellComplex& cc);

/// The default tissue refined `level` times around the top of the tissue (radius: the larger of
/// three probe radii and one cell size). Cached.
std::shared_ptr<const CellComplex> refinedMeristem(int level);

/// A prepared indentation (turgid state solved, probe placed at the top) on `cc`.
struct Setup {
  std::shared_ptr<const CellComplex> cc;
  std::unique_ptr<Model> model;
  std::unique_ptr<Indentation> indentation;
};
Setup prepare(std::shared_ptr<const CellComplex> cc, SolverOptions options = {},
              IndentationSettings settings = {});

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
