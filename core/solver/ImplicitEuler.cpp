#include "solver/ImplicitEuler.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace tp {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
}  // namespace

ImplicitEulerSolver::ImplicitEulerSolver(Model& model, SolverOptions options)
    : model_(model), options_(options) {}

SolveReport ImplicitEulerSolver::solve(Points& x, ForceControl* fc) {
  SolveReport rep;
  ++totals_.solves;
  if (fc) {
    rep.message = "the implicit-Euler reference solver supports displacement control only";
    return rep;
  }
  if (model_.pattern().n != model_.dofs().freeCount()) {
    rep.message = "the implicit-Euler reference solver runs the published bending models (hinge, "
                  "linear or none), not Koiter bending";
    return rep;
  }
  const DofMap& dofs = model_.dofs();
  const SparsePattern& pattern = model_.pattern();
  const int n = dofs.freeCount();
  const auto& freeDofs = dofs.freeDofs();
  // Lumped mass: ρ h A/3 per vertex of each triangle (rest areas).
  if (mass_.size() != n) {
    const CellComplex& cc = model_.complex();
    const auto area = triangleAreas(cc, cc.rest);
    Eigen::VectorXd m = Eigen::VectorXd::Zero(3 * cc.vertexCount());
    const double rh = options_.density * model_.material().thickness;
    for (int t = 0; t < cc.triangleCount(); ++t)
      for (int k = 0; k < 3; ++k) m.segment<3>(3 * cc.triangles[t][k]).array() += rh * area[t] / 3;
    mass_.resize(n);
    for (int i = 0; i < n; ++i) mass_[i] = m[freeDofs[i]];
  }
  const double h = options_.timeStep, alpha = options_.rayleighMass, beta = options_.rayleighStiffness;
  const double floor = loadFreeFloor(model_), noise = roundOffFloor(model_, n);
  const Points x0 = x;
  Eigen::VectorXd v = Eigen::VectorXd::Zero(n), g(n), rhs(n), r(n), p(n), q(n), Mv(n);
  std::vector<double> A;
  const auto start = Clock::now();
  for (int step = 0;; ++step) {
    auto tick = Clock::now();
    model_.evaluate(x, ev_,
                    EvalOptions{.hessian = true, .projectContact = options_.projectContactHessian});
    totals_.assemblySeconds += since(tick);
    double load2 = 0;
    for (int i = 0; i < n; ++i) {
      g[i] = ev_.gradient[freeDofs[i]];
      load2 += ev_.loadGradient[freeDofs[i]] * ev_.loadGradient[freeDofs[i]];
    }
    rep.energy = ev_.energy.total();
    rep.loadScale = std::sqrt(load2) + floor;
    rep.residual = g.norm();
    rep.iterations = step;
    if (options_.verbose && step % 100 == 0)
      std::fprintf(stderr, "  implicit euler step %6d  |g|=%.3e  rel=%.3e  cg=%d\n", step,
                   rep.residual, rep.relativeResidual(), rep.pcgIterations);
    if (!std::isfinite(rep.residual)) {
      x = x0;
      rep.message = "residual is not finite";
      return rep;
    }
    // At rest: the same criterion as the Newton solver.
    if (rep.residual <= std::max(options_.tolerance * rep.loadScale, noise)) {
      rep.converged = true;
      break;
    }
    if (cancel_ && cancel_->load()) {
      x = x0;
      rep.message = "cancelled";
      break;
    }
    if (step >= options_.maxTimeSteps || since(start) > options_.maxSeconds) {
      std::ostringstream s;
      s << "not at rest after " << step << " time steps (" << since(start)
        << " s, relative residual " << rep.relativeResidual() << ")";
      x = x0;
      rep.message = s.str();
      break;
    }
    // (M + h C + h² K) v' = M v − h ∇W, C = α M + β K: A = (1 + hα) M + (h² + hβ) K.
    const double cm = 1.0 + h * alpha, ck = h * h + h * beta;
    A.assign(ev_.hessian.begin(), ev_.hessian.end());
    for (double& a : A) a *= ck;
    for (int j = 0; j < n; ++j) A[pattern.colPtr[j + 1] - 1] += cm * mass_[j];  // diagonal
    Mv = mass_.cwiseProduct(v);
    rhs = Mv - h * g;
    // Unpreconditioned CG from the previous velocity, a fixed budget of iterations.
    tick = Clock::now();
    symmetricMultiply(pattern, A, v.data(), q.data());
    r = rhs - q;
    p = r;
    double rr = r.squaredNorm();
    const double target = options_.cgTolerance * options_.cgTolerance * rhs.squaredNorm();
    for (int k = 0; k < options_.cgIterations && rr > target; ++k) {
      symmetricMultiply(pattern, A, p.data(), q.data());
      const double pq = p.dot(q);
      if (!(pq > 0)) break;
      const double a = rr / pq;
      v += a * p;
      r -= a * q;
      const double rrNew = r.squaredNorm();
      p = r + (rrNew / rr) * p;
      rr = rrNew;
      ++rep.pcgIterations;
    }
    totals_.pcgSeconds += since(tick);
    for (int i = 0; i < n; ++i) x.data()[freeDofs[i]] += h * v[i];
  }
  totals_.iterations += rep.iterations;
  totals_.pcgIterations += rep.pcgIterations;
  return rep;
}

}  // namespace tp
