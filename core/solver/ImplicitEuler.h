#pragma once
// The published method, kept as a reference to measure against: pseudo-dynamics with implicit
// (backward) Euler, Rayleigh damping C = α M + β K and a lumped mass M (wall density × h × area/3
// per vertex), each time step's linear system (M + h C + h² K) v' = M v − h ∇W solved by
// unpreconditioned conjugate gradients with a fixed iteration budget (as SOFA's
// EulerImplicitSolver + CGLinearSolver), stepped until the structure is at rest, i.e. the same
// residual tolerance as the Newton solver. Displacement control only. Units: µm, µN, s, kg.

#include "solver/Solver.h"

namespace tp {

class ImplicitEulerSolver final : public EquilibriumSolver {
 public:
  ImplicitEulerSolver(Model& model, SolverOptions options);

  SolveReport solve(Points& x, ForceControl* fc = nullptr) override;
  const Evaluation& lastEvaluation() const override { return ev_; }
  SolverOptions& options() override { return options_; }
  const SolverTotals& totals() const override { return totals_; }

 private:
  Model& model_;
  SolverOptions options_;
  Evaluation ev_;
  SolverTotals totals_;
  Eigen::VectorXd mass_;  // lumped, per free unknown (kg)
};

}  // namespace tp
