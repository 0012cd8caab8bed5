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
  // The step grows by half after a step of at most growAtMost Newton iterations and halves
  // after one of more than shrinkAbove, or a failure: so it settles where an equilibrium takes
  // one iteration, the cheapest there is, and the view gets the most equilibria a second. Under
  // Xvfb (TP_GUI_MEASURE=1 … dragRatesOnTheDefaultMeristem, level 3): 6.6–7.0 equilibria/s, the
  // probe travelling 3.2–3.5 µm in 20 s, against 1.8–2.1 per s and 4.0–4.3 µm with (2, 3) —
  // larger steps of two or three iterations go further per second of solving but show a few
  // frozen frames a second; one iteration each is what makes a drag look live.
  int growAtMost = 1;
  int shrinkAbove = 1;
  // Each step's first Newton direction on the tangent of the last assembly with its contact
  // part renewed (SolverOptions::renewedChordFirst) instead of a new assembly. That step cuts
  // the residual 40–130× instead of 60–250×, so under the rule above the steps settle smaller,
  // and cheaper: BM_DragFixedPath/3 (one thread) 59.9 ms an equilibrium against 78.3, the probe
  // following at 0.30 against 0.31 µm per second of solving; in the application under Xvfb
  // (dragRatesOnTheDefaultMeristem, six runs each, alternated) 9.4–11.5 equilibria/s (median
  // 10.5) against 7.7–10.3 (9.9), the probe shown travelling 3.5–4.2 µm in 20 s against
  // 3.5–5.0 (medians 3.8, 4.6). More equilibria a second, the probe following 5–15 % slower:
  // liveliness, which the rule above puts first. (Not counting the renewed iteration when the rule decides goes the other way:
  // 128 ms an equilibrium, 0.40 µm/s.) Loading curves keep it off: at their tighter tolerance
  // it cost iterations (level 3: 68 → 91).
  bool renewedChord = true;
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
