#pragma once
// What every equilibrium solver shares: options, force control, reports, the interface the
// indentation protocol drives, and the factory. Two solvers exist: Newton with CHOLMOD (the
// default, solver/Newton.h) and the published method as a reference (implicit Euler with
// Rayleigh damping and conjugate gradients run until rest, solver/ImplicitEuler.h).

#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "mechanics/Model.h"

namespace tp {

enum class SolverKind { Newton, ImplicitEulerCG };
SolverKind parseSolverKind(const std::string& name);  // "newton" | "implicit-euler-cg"
std::string toString(SolverKind k);

struct SolverOptions {
  SolverKind kind = SolverKind::Newton;
  double tolerance = 1e-8;     // converged when ‖residual‖ ≤ tolerance · load scale
  int maxIterations = 60;      // Newton iterations
  int maxLineSearch = 40;      // halvings before the line search gives up
  double maxProbeStep = 0;     // cap on |Δs| per iteration under force control (µm); 0 = r/4
  bool reuseFactorization = true;  // try CG preconditioned by the last factor before refactoring
  double pcgTolerance = 1e-3;  // loosest relative residual of those CG solves (inexact Newton)
  int maxPcgIterations = 25;   // beyond this the tangent is factorised afresh
  int refactorAfterPcg = 6;    // refactorise when the last CG solve took more iterations and
  double refactorFraction = 0.25;         // more than this fraction of a factorisation's
  double refactorFractionContact = 0.15;  // operations (this one with the contact's block)
  bool projectContactHessian = true;  // when the tangent is not positive definite, first retry
                                      // with the positive part of each contact element's Hessian
  bool relaxContact = true;    // the contact patch's own solves between and inside Newton
                               // iterations (solver/ContactRelaxation.h): its vertices relaxed,
                               // chord steps, its block in CG's preconditioner
  bool renewedChordFirst = false;  // a start near the solution takes its first direction on
                                   // the tangent held from the last assembly, its contact part
                                   // renewed (StaticSolver::renewedHeldTangent); drags use it
  bool verbose = false;        // print one line per iteration to stderr

  // Reference solver (implicit Euler, Rayleigh damping, CG), with SOFA's usual settings.
  double timeStep = 0.01;          // s
  double density = 1e-15;          // wall density, kg/µm³ (1000 kg/m³); mass unit kg = µN·s²/µm
  double rayleighMass = 0.1;       // α in C = α M + β K (1/s)
  double rayleighStiffness = 0.1;  // β (s)
  int cgIterations = 25;           // per time step
  double cgTolerance = 1e-5;       // relative residual of each CG solve
  int maxTimeSteps = 200000;       // per equilibrium
  double maxSeconds = 600;         // per equilibrium (wall clock)
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
  int iterations = 0;     // Newton iterations, or time steps of the reference solver
  double residual = 0;    // ‖∂W/∂u‖ over the unknowns at the end (µN)
  double loadScale = 0;   // µN
  double energy = 0;      // pJ
  int factorizations = 0;
  int pcgIterations = 0;  // conjugate-gradient iterations
  double maxShift = 0;    // largest diagonal shift used
  std::string message;
  double relativeResidual() const { return loadScale > 0 ? residual / loadScale : residual; }
};

/// Totals over every solve of one solver (benchmarks, reports).
struct SolverTotals {
  int solves = 0, iterations = 0, factorizations = 0, pcgIterations = 0;
  int assemblies = 0;     // tangents assembled in Newton iterations
  int renewedChords = 0;  // first directions on the held tangent, its contact part renewed
  double assemblySeconds = 0, factorSeconds = 0, pcgSeconds = 0, lineSearchSeconds = 0;
};

class EquilibriumSolver {
 public:
  virtual ~EquilibriumSolver() = default;
  /// Solves for equilibrium starting from x (3×V, clamped columns are kept). On success x (and
  /// fc->travel) hold the equilibrium; on failure they are left exactly as given.
  virtual SolveReport solve(Points& x, ForceControl* fc = nullptr) = 0;
  /// The linear response at x: solves K(x) u = load (3V components; clamped ones ignored, and 0
  /// in u) with the tangent K at x. False when this solver has no tangent (or it fails).
  virtual bool tangentSolve(const Points& x, const Eigen::VectorXd& load,
                            Eigen::VectorXd& displacement) {
    Eigen::MatrixXd u;
    if (!tangentSolve(x, Eigen::MatrixXd(load), u)) return false;
    displacement = u.col(0);
    return true;
  }
  /// The same for several loads (one per column) with K(x) unshifted (an equilibrium's tangent
  /// is positive definite; a diagonal shift is added only if it is not). Solved to round-off:
  /// by conjugate gradients preconditioned with the factor the solver holds when that converges
  /// within the cost of a factorisation, else with one factorisation of K(x).
  virtual bool tangentSolve(const Points& x, const Eigen::MatrixXd& loads,
                            Eigen::MatrixXd& displacements) {
    return tangentSolve(
        x, [&](const Evaluation&) { return loads; }, displacements);
  }
  /// The loads computed from the model's evaluation at x (gradient, Hessian, the probe's
  /// coupling), which the solver makes anyway to build K(x): one assembly, not two.
  using LoadsAt = std::function<Eigen::MatrixXd(const Evaluation&)>;
  virtual bool tangentSolve(const Points& /*x*/, const LoadsAt& /*loadsAt*/,
                            Eigen::MatrixXd& /*displacements*/) {
    return false;
  }
  /// The model evaluated at the last iterate (at the equilibrium after a successful solve).
  virtual const Evaluation& lastEvaluation() const = 0;
  virtual SolverOptions& options() = 0;
  virtual const SolverTotals& totals() const = 0;
  /// Call after the model's clamped unknowns change.
  virtual void patternChanged() {}
  /// Does now what the first solve would do first and what depends on the model's sparsity
  /// pattern only (a direct solver's symbolic analysis), e.g. on a thread of its own while
  /// something else is computed. Optional: a solve does it when it has not been done.
  virtual void analyze() {}
  /// A flag checked at every iteration: when set, the solve stops and fails with "cancelled"
  /// (the state is left as given). Null: never cancelled.
  void setCancelFlag(const std::atomic<bool>* flag) { cancel_ = flag; }

 protected:
  const std::atomic<bool>* cancel_ = nullptr;
};

std::unique_ptr<EquilibriumSolver> makeSolver(Model& model, const SolverOptions& options);

/// Load scale and residual conventions shared by the solvers: the residual floor below which a
/// state without load counts as converged, and the round-off floor of nodal forces (µN).
double loadFreeFloor(const Model& model);
double roundOffFloor(const Model& model, int unknowns);
/// The round-off floor of nodal forces when walls lie far from the origin compared with their
/// edges (µN): a residual that full Newton steps no longer reduce counts as converged below a
/// hundred times this.
double positionRoundOffFloor(const Model& model, int unknowns);

}  // namespace tp
