#pragma once
// Static equilibrium: Newton's method on the total potential energy with a backtracking line
// search, a CHOLMOD factorisation whose symbolic analysis is reused across iterations and steps,
// and a diagonal shift that grows when the tangent is not positive definite (compressed walls,
// pressure). Convergence is judged relative to the load scale (‖load forces‖ + |applied force|).
// Under force control the probe's travel s along its axis is an extra unknown with the potential
// −F·s; it borders the tissue's matrix and is eliminated by a Schur complement, so the sparse
// pattern never changes. A solve that does not converge restores the starting state.

#include <string>

#include "mechanics/Model.h"
#include "solver/CholmodSolver.h"

namespace tp {

struct SolverOptions {
  double tolerance = 1e-9;     // converged when ‖residual‖ ≤ tolerance · load scale
  int maxIterations = 60;
  int maxLineSearch = 40;      // halvings before the line search gives up
  double maxProbeStep = 0;     // cap on |Δs| per iteration under force control (µm); 0 = r/4
  bool verbose = false;        // print one line per iteration to stderr
};

/// Force control: probe centre = origin + travel·axis, with `travel` unknown and `force` applied.
struct ForceControl {
  Vec3 origin = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();  // unit, pointing into the tissue
  double force = 0;           // µN
  double travel = 0;          // µm (initial guess in, solution out)
};

struct SolveReport {
  bool converged = false;
  int iterations = 0;
  double residual = 0;    // ‖∂W/∂u‖ over the unknowns at the end (µN)
  double loadScale = 0;   // µN
  double energy = 0;      // pJ
  int factorizations = 0;
  double maxShift = 0;    // largest diagonal shift used
  std::string message;
  double relativeResidual() const { return loadScale > 0 ? residual / loadScale : residual; }
};

class StaticSolver {
 public:
  explicit StaticSolver(Model& model, SolverOptions options = {});

  /// Solves for equilibrium starting from x (3×V, clamped columns are kept). On success x (and
  /// fc->travel) hold the equilibrium; on failure they are left exactly as given.
  SolveReport solve(Points& x, ForceControl* fc = nullptr);

  SolverOptions& options() { return options_; }
  const Evaluation& lastEvaluation() const { return ev_; }
  /// Call after the model's clamped unknowns change (rebuilds the symbolic analysis).
  void patternChanged() { analyzedFor_ = nullptr; }

 private:
  double totalEnergy(const Points& x, const ForceControl* fc, double travel, double* magnitude);
  double residualNorm(const Points& x, const ForceControl* fc, double travel);

  Model& model_;
  SolverOptions options_;
  CholmodSolver chol_;
  const SparsePattern* analyzedFor_ = nullptr;
  int analyzedNnz_ = -1;
  Evaluation ev_;
  double lastShift_ = 0;
};

}  // namespace tp
