#pragma once
// Static equilibrium: Newton's method on the total potential energy with a backtracking line
// search, a CHOLMOD factorisation whose symbolic analysis is reused across iterations and steps,
// and a diagonal shift that grows when the tangent is not positive definite (compressed walls,
// pressure). Convergence is judged relative to the load scale (‖load forces‖ + |applied force|).
// Under force control the probe's travel s along its axis is an extra unknown with the potential
// −F·s; it borders the tissue's matrix and is eliminated by a Schur complement, so the sparse
// pattern never changes. A solve that does not converge restores the starting state.

#include <functional>
#include <string>

#include "mechanics/Model.h"
#include "solver/CholmodSolver.h"
#include "solver/ContactRelaxation.h"
#include "solver/Solver.h"

namespace tp {

class StaticSolver final : public EquilibriumSolver {
 public:
  explicit StaticSolver(Model& model, SolverOptions options = {});

  SolveReport solve(Points& x, ForceControl* fc = nullptr) override;
  using EquilibriumSolver::tangentSolve;
  bool tangentSolve(const Points& x, const LoadsAt& loadsAt,
                    Eigen::MatrixXd& displacements) override;
  SolverOptions& options() override { return options_; }
  const SolverTotals& totals() const override { return totals_; }
  const Evaluation& lastEvaluation() const override { return ev_; }
  /// Rebuilds the symbolic analysis at the next solve.
  void patternChanged() override { analyzedFor_ = nullptr; }
  void analyze() override;
  /// The time one numeric factorisation of the last tangent takes (s): the solver's floor.
  double timeFactorization();

 private:
  // One solve, as named steps: each iteration measures the residual, takes a Newton direction
  // (newtonDirection), eliminates the probe's travel under force control (probeStep), limits
  // the step so that contact is kept (stepLimit) and searches along it (lineSearch).
  struct Run;
  SolveReport solveImpl(Points& x, ForceControl* fc);
  SolveReport fail(Run& r, const std::string& why);  // restores the starting state
  void evaluateAt(Run& r, const Points& at, double travel, bool withHessian, Evaluation& e,
                  bool projectContact = false);
  void measure(Run& r, const Evaluation& e, double travel, double& energy, double& residual,
               double& loadScale);
  bool newtonDirection(Run& r, int iteration, std::string& why);
  double probeStep(Run& r);
  double stepLimit(Run& r, double ds);
  double lineSearch(Run& r, double ds, double slope, double alphaMax);
  bool relaxContact(Run& r, double goal, bool withTangent);
  const std::vector<double>* renewedHeldTangent(const Points& x);
  void precondition(const Eigen::VectorXd& r, Eigen::VectorXd& z);
  /// Factorises ev_'s tangent (+ shift·I), first replacing the contact Hessian by its positive
  /// part (projectContact) and then growing the shift while it is not positive definite.
  bool factorizeTangent(double& shift, double maxDiag, int& factorizations,
                        const std::function<void()>& projectContact, std::string& why);
  bool pcg(const SparsePattern& pattern, const std::vector<double>& values,
           const Eigen::VectorXd& rhs, Eigen::VectorXd& sol, double relTol, int& iterations,
           int maxIterations);

  Model& model_;
  SolverOptions options_;
  CholmodSolver chol_;
  const SparsePattern* analyzedFor_ = nullptr;
  int analyzedNnz_ = -1;
  Evaluation ev_, trial_;  // at the current iterate, and at a line-search trial
  Points lastX_;           // where ev_ was evaluated (for timeFactorization)
  double lastShift_ = 0;
  int lastPcgIterations_ = 0;  // of the last CG solve on the lagged factor
  bool lastPcgFailed_ = false;
  bool lastPcgLocal_ = false;  // ... with the contact patch's block in its preconditioner
  bool projectedLastSolve_ = false;  // the last solve needed the contact Hessian's positive part
  SolverTotals totals_;
  // The contact patch's solves (solver/ContactRelaxation.h): the last tangent for the relaxation
  // and chord steps, the current one over the pressed triangles for precondition().
  PatternRows patternRows_;
  ContactRelaxation relax_;
  LocalTangent local_;
  // The held tangent with its contact part renewed, and the contact part's values then and now.
  std::vector<double> renewed_;
  Evaluation contactThen_, contactNow_;
};

}  // namespace tp
