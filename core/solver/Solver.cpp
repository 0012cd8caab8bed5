#include "solver/Solver.h"

#include <cmath>
#include <stdexcept>

#include "solver/ImplicitEuler.h"
#include "solver/Newton.h"

namespace tp {

SolverKind parseSolverKind(const std::string& name) {
  if (name == "newton") return SolverKind::Newton;
  if (name == "implicit-euler-cg") return SolverKind::ImplicitEulerCG;
  throw std::invalid_argument("unknown solver '" + name +
                              "' (expected newton or implicit-euler-cg)");
}

std::string toString(SolverKind k) {
  return k == SolverKind::Newton ? "newton" : "implicit-euler-cg";
}

std::unique_ptr<EquilibriumSolver> makeSolver(Model& model, const SolverOptions& options) {
  if (options.kind == SolverKind::ImplicitEulerCG)
    return std::make_unique<ImplicitEulerSolver>(model, options);
  return std::make_unique<StaticSolver>(model, options);
}

double loadFreeFloor(const Model& model) {
  const Material& m = model.material();
  return 1e-10 * m.youngModulus * m.thickness * model.meanEdgeLength();
}

double roundOffFloor(const Model& model, int unknowns) {
  // Nodal forces are differences of terms of size ~ (μ+λ*) h ℓ, each known to ~1e-16 of itself.
  const Material& m = model.material();
  return 1e-14 * 2 * (m.mu() + m.lambdaPlaneStress()) * m.thickness * model.meanEdgeLength() *
         std::sqrt(static_cast<double>(unknowns));
}

}  // namespace tp
