#include "solver/Solver.h"

#include <algorithm>
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

namespace {
// Nodal forces are differences of terms of size ~ (μ+λ*) h ℓ, each known to ~1e-16 ·
// `length` / ℓ of itself.
double forceRoundOff(const Model& model, double length, int unknowns) {
  const Material& m = model.material();
  return 1e-14 * 2 * (m.mu() + m.lambdaPlaneStress()) * m.thickness * length *
         std::sqrt(static_cast<double>(unknowns));
}
}  // namespace

double roundOffFloor(const Model& model, int unknowns) {
  // Each term known to ~1e-16 of itself.
  return forceRoundOff(model, model.meanEdgeLength(), unknowns);
}

double positionRoundOffFloor(const Model& model, int unknowns) {
  // Each term known only to ~1e-16 |x| / ℓ of itself: an edge is the difference of two positions
  // each rounded to 1e-16 |x|. A cap of a sphere 10 µm from the origin refined to 0.03 µm edges
  // stalled at 7.8e-10 µN (this floor: 5e-10 µN, roundOffFloor 1.5e-12 µN); moved to the origin,
  // at 7e-12 µN. A bound, often far above what is reached.
  const Points& X = model.complex().rest;
  const double extent = X.cols() ? X.cwiseAbs().maxCoeff() : 0.0;
  return forceRoundOff(model, std::max(model.meanEdgeLength(), extent), unknowns);
}

}  // namespace tp
