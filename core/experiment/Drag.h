#pragma once
// Following a probe dragged by hand. The depth asked moves while equilibria are solved, so each
// call solves one equilibrium a bounded step toward the newest depth asked and adapts the step
// to how that went: small warm-started steps converge in one or two Newton iterations, a jump
// of half a micrometre in many slower ones. The application's worker calls it for every drag
// request (app/gui/SimulationWorker.cpp); bench_indentation's BM_DragReplay replays a drag with
// it. Units: µm.

#include "experiment/Indentation.h"

namespace tp {

struct DragOptions {
  // A drag shows equilibria rather than measuring them: a residual of 1e-7 of the load scale
  // (forces good to ~1e-5 µN of tens of µN) lets most steps finish in one Newton iteration
  // instead of two. Scheduled curves keep the solver's own tolerance (1e-8).
  double tolerance = 1e-7;
  double startRadii = 0.025;                // the first step, in probe radii
  double minRadii = 0.01, maxRadii = 0.25;  // the step's bounds, in probe radii
  int growAtMost = 2;    // the step grows by half after a step of at most this many iterations,
  int shrinkAbove = 3;   // halves after one of more than this many or a failure
};

/// One drag equilibrium: the point solved (converged or not) and whether to call again.
struct DragStep {
  CurvePoint point;
  bool more = false;  // the depth asked is not reached yet (a partial step, or a failed step to
                      // be retried smaller): call again with the same or a newer depth
  bool failed() const { return !point.converged && !more; }
};

class DragFollower {
 public:
  explicit DragFollower(DragOptions options = {}) : options_(options) {}

  /// One equilibrium at most the current step from the indentation's depth toward `depth`.
  DragStep toward(Indentation& indentation, double depth);
  /// A new drag on a new site or tissue starts from the first step again.
  void reset() { step_ = 0; }
  double step() const { return step_; }  // µm; 0 before the first call
  const DragOptions& options() const { return options_; }

 private:
  DragOptions options_;
  double step_ = 0;
};

}  // namespace tp
