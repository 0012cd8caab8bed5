#include "experiment/Drag.h"

#include <algorithm>
#include <cmath>

namespace tp {

DragStep DragFollower::toward(Indentation& ind, double depth) {
  SolverOptions& solver = ind.solver().options();
  struct Restore {  // the solver's own settings, whatever happens
    SolverOptions& o;
    double tolerance;
    bool renewedChord;
    ~Restore() {
      o.tolerance = tolerance;
      o.renewedChordFirst = renewedChord;
    }
  } restore{solver, solver.tolerance, solver.renewedChordFirst};
  solver.tolerance = std::max(restore.tolerance, options_.tolerance);
  solver.renewedChordFirst = options_.renewedChord;

  const double radius = ind.settings().probeRadius;
  const double smallest = options_.minRadii * radius;
  if (!(step_ > 0)) step_ = options_.startRadii * radius;
  const double gap = depth - ind.depth();
  const bool partial = std::abs(gap) > step_;
  const double target = partial ? ind.depth() + std::copysign(step_, gap) : depth;
  DragStep out;
  out.point = ind.goToDepth(target);
  const bool canShrink = step_ > smallest * 1.0001;
  const int its = out.point.iterations;
  if (out.point.converged && its <= options_.growAtMost)
    step_ = std::min(1.5 * step_, options_.maxRadii * radius);
  else if (!out.point.converged || its > options_.shrinkAbove)
    step_ = std::max(0.5 * step_, smallest);
  if (!out.point.converged)
    out.more = std::abs(gap) > smallest && canShrink;  // tried again with a smaller step
  else
    out.more = partial;
  return out;
}

}  // namespace tp
