#include "solver/Newton.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <sstream>

namespace tp {

namespace {
using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}
}  // namespace

StaticSolver::StaticSolver(Model& model, SolverOptions options)
    : model_(model), options_(options) {
  if (std::getenv("TP_NEWTON_VERBOSE")) options_.verbose = true;  // debugging aid
}

bool StaticSolver::pcg(const SparsePattern& pattern, const std::vector<double>& values,
                       const Eigen::VectorXd& rhs, Eigen::VectorXd& sol, double relTol,
                       int& iterations) {
  const double target = relTol * rhs.norm();
  sol.setZero(rhs.size());
  Eigen::VectorXd r = rhs, z, p, q;
  chol_.solveSinglePrecision(r, z);
  p = z;
  double rz = r.dot(z);
  q.resize(rhs.size());
  for (int k = 0; k < options_.maxPcgIterations; ++k) {
    symmetricMultiply(pattern, values, p.data(), q.data());
    const double pq = p.dot(q);
    if (!(pq > 0)) return false;  // negative curvature: leave it to the shifted factorisation
    const double a = rz / pq;
    sol += a * p;
    r -= a * q;
    ++iterations;
    if (r.norm() <= target) return true;
    chol_.solveSinglePrecision(r, z);
    const double rzNew = r.dot(z);
    p = z + (rzNew / rz) * p;
    rz = rzNew;
  }
  return false;
}

double StaticSolver::timeFactorization() {
  if (analyzedFor_ != &model_.pattern()) {
    chol_.analyze(model_.pattern());
    analyzedFor_ = &model_.pattern();
    analyzedNnz_ = model_.pattern().nnz();
  }
  if (!ev_.hasHessian) {
    if (lastX_.cols() != model_.complex().vertexCount()) return 0;
    model_.evaluate(lastX_, ev_, true);
  }
  double maxDiag = 0;
  for (int j = 0; j < model_.pattern().n; ++j)
    maxDiag = std::max(maxDiag, std::abs(ev_.hessian[model_.pattern().colPtr[j + 1] - 1]));
  const auto tick = Clock::now();
  chol_.factorize(ev_.hessian, lastShift_ > 0 ? lastShift_ : 1e-12 * maxDiag);
  return seconds(tick);
}

bool StaticSolver::factorizeTangent(double& shift, double maxDiag, int& factorizations,
                                    const std::function<void()>& projectContact,
                                    std::string& why) {
  bool projected = false;
  for (int attempt = 0; attempt < 40; ++attempt) {
    ++factorizations;
    const auto start = Clock::now();
    const auto st = chol_.factorize(ev_.hessian, shift);
    if (st == CholmodSolver::Status::Ok) {
      factorSeconds_ = seconds(start);
      return true;
    }
    if (st == CholmodSolver::Status::NonFinite || st == CholmodSolver::Status::Failed) {
      why = chol_.lastMessage();
      return false;
    }
    // Not positive definite. The usual culprit is the contact: the sphere's curvature makes
    // its Hessian indefinite. Keep only its positive part for this iteration (an exact
    // Newton step whenever the true tangent is positive definite, which it is at a stable
    // equilibrium); then, if needed, shift the diagonal.
    if (!projected && !ev_.contactProjected && options_.projectContactHessian &&
        ev_.contactTriangles > 0 && projectContact) {
      projected = true;
      projectContact();
      continue;
    }
    shift = shift == 0 ? 1e-8 * maxDiag : shift * 10.0;
    if (shift > 1e6 * maxDiag) break;
  }
  why = "tangent matrix could not be made positive definite";
  return false;
}

bool StaticSolver::tangentSolve(const Points& x, const Eigen::VectorXd& load,
                                Eigen::VectorXd& displacement) {
  const DofMap& dofs = model_.dofs();
  const int n = dofs.freeCount();
  if (load.size() != dofs.fullCount() || n == 0) return false;
  if (analyzedFor_ != &model_.pattern() || analyzedNnz_ != model_.pattern().nnz()) {
    chol_.analyze(model_.pattern());
    analyzedFor_ = &model_.pattern();
    analyzedNnz_ = model_.pattern().nnz();
  }
  const auto tick = Clock::now();
  model_.evaluate(x, ev_, true);
  lastX_ = x;
  totals_.assemblySeconds += seconds(tick);
  double maxDiag = 0;
  for (int j = 0; j < n; ++j)
    maxDiag = std::max(maxDiag, std::abs(ev_.hessian[model_.pattern().colPtr[j + 1] - 1]));
  if (!(maxDiag > 0)) return false;
  double shift = lastShift_;
  int factorizations = 0;
  std::string why;
  const auto start = Clock::now();
  const bool ok = factorizeTangent(shift, maxDiag, factorizations, {}, why);
  totals_.factorizations += factorizations;
  totals_.factorSeconds += seconds(start);
  if (!ok) return false;
  lastPcgIterations_ = 0;
  lastPcgSeconds_ = 0;
  lastPcgFailed_ = false;
  // The pattern may carry a bending term's edge unknowns after the positions (Model::pattern()):
  // they take a zero right-hand side and their part of the solution is not used.
  Eigen::VectorXd f = Eigen::VectorXd::Zero(model_.pattern().n), u;
  for (int i = 0; i < n; ++i) f[i] = load[dofs.freeDofs()[i]];
  chol_.solve(f, u);
  displacement.setZero(dofs.fullCount());
  for (int i = 0; i < n; ++i) displacement[dofs.freeDofs()[i]] = u[i];
  return displacement.allFinite();
}

SolveReport StaticSolver::solve(Points& x, ForceControl* fc) {
  SolveReport rep = solveImpl(x, fc);
  ++totals_.solves;
  totals_.iterations += rep.iterations;
  totals_.factorizations += rep.factorizations;
  totals_.pcgIterations += rep.pcgIterations;
  return rep;
}

SolveReport StaticSolver::solveImpl(Points& x, ForceControl* fc) {
  SolveReport rep;
  const DofMap& dofs = model_.dofs();
  const SparsePattern& pattern = model_.pattern();
  const int n = dofs.freeCount();
  const auto& freeDofs = dofs.freeDofs();
  if (fc && !model_.probe()) throw std::logic_error("force control needs a probe on the model");
  if (analyzedFor_ != &pattern || analyzedNnz_ != pattern.nnz()) {
    chol_.analyze(pattern);
    analyzedFor_ = &pattern;
    analyzedNnz_ = pattern.nnz();
  }
  // Vectors span the whole pattern: the free position components, then any edge unknowns of the
  // bending term (Model::pattern()), which take a zero right-hand side; only the position part of
  // a solution moves the tissue.
  const int nAll = pattern.n;
  std::vector<int> diagPos(nAll);
  for (int j = 0; j < nAll; ++j) diagPos[j] = pattern.colPtr[j + 1] - 1;  // row == col comes last

  const Points x0 = x;
  const double travel0 = fc ? fc->travel : 0.0;
  double travel = travel0;
  const Material& mat = model_.material();
  const double stiffScale = mat.youngModulus * mat.thickness;          // µN/µm
  const double floor = loadFreeFloor(model_);
  const double noiseFloor = roundOffFloor(model_, n);
  const double maxProbeStep =
      options_.maxProbeStep > 0 ? options_.maxProbeStep
                                : (model_.probe() ? 0.25 * model_.probe()->radius : 0.0);

  Eigen::VectorXd g = Eigen::VectorXd::Zero(nAll), dx(nAll), z2(nAll), b = Eigen::VectorXd::Zero(nAll);
  double shift = lastShift_ > 0 ? lastShift_ * 0.1 : 0.0;
  auto fail = [&](const std::string& why) {
    x = x0;
    if (fc) {
      fc->travel = travel0;
      Probe p = *model_.probe();
      p.center = fc->origin + travel0 * fc->axis;
      model_.setProbe(p);
    }
    rep.converged = false;
    rep.message = why;
    return rep;
  };

  // Evaluates the model at (x, probe travel); the Hessian only when a Newton direction is needed
  // (a gradient costs about a tenth of a full assembly, and most load steps converge in one
  // iteration, so the state they end in never needs its Hessian).
  auto evaluateAt = [&](const Points& at, double trav, bool withHessian, Evaluation& e,
                        bool projectContact = false) {
    if (fc) {
      Probe p = *model_.probe();
      p.center = fc->origin + trav * fc->axis;
      model_.setProbe(p);
    }
    const auto tick = Clock::now();
    model_.evaluate(at, e, EvalOptions{.hessian = withHessian, .projectContact = projectContact});
    (withHessian ? totals_.assemblySeconds : totals_.lineSearchSeconds) += seconds(tick);
  };
  // Energy (with the work of the applied force), residual and load scale of an evaluation.
  double gs = 0;
  auto measure = [&](const Evaluation& e, double trav, double& energy, double& residual,
                     double& loadScale) {
    double loadNorm2 = 0;
    for (int i = 0; i < n; ++i) {
      g[i] = e.gradient[freeDofs[i]];
      loadNorm2 += e.loadGradient[freeDofs[i]] * e.loadGradient[freeDofs[i]];
    }
    gs = fc ? fc->axis.dot(e.probeGradient) - fc->force : 0.0;
    energy = e.energy.total() - (fc ? fc->force * trav : 0.0);
    loadScale = std::sqrt(loadNorm2) + (fc ? std::abs(fc->force) : 0.0) + floor;
    residual = std::sqrt(g.squaredNorm() + gs * gs);
  };

  Points xt = x;
  double bestResidual = std::numeric_limits<double>::infinity();
  int stalled = 0;
  bool projectContact = projectedLastSolve_;
  struct Remember {
    bool& from;
    bool& to;
    ~Remember() { to = from; }
  } remember{projectContact, projectedLastSolve_};
  evaluateAt(x, travel, false, ev_);
  // Contact that cannot be lost: start clear of the walls and keep the clearance at every step.
  if (model_.probe() && !(model_.probeDistance(x) > model_.contactClearance()))
    return fail("the probe starts within half its radius of a wall (a step too large for the "
                "contact to be followed)");
  Points stepPoints;
  for (int it = 0;; ++it) {
    measure(ev_, travel, rep.energy, rep.residual, rep.loadScale);
    rep.iterations = it;
    if (options_.verbose)
      std::fprintf(stderr,
                   "  newton %2d  E=%.12g  |g|=%.3e  rel=%.3e  shift=%.2e  contact=%d  "
                   "factorisations=%d  cg=%d\n",
                   it, rep.energy, rep.residual, rep.relativeResidual(), shift,
                   ev_.contactTriangles, rep.factorizations, rep.pcgIterations);
    if (!std::isfinite(rep.energy)) return fail("energy is not finite");
    if (!std::isfinite(rep.residual)) return fail("residual is not finite");
    // Stagnation: when full Newton steps no longer reduce the residual and it is already within
    // a hundred times the target, it sits on the round-off floor of the forces (sliver
    // triangles far from the origin make that floor higher than roundOffFloor() says): the
    // state is as converged as the arithmetic allows.
    const double goal = std::max(options_.tolerance * rep.loadScale, noiseFloor);
    if (rep.residual < 0.5 * bestResidual) {
      bestResidual = rep.residual;
      stalled = 0;
    } else if (it > 0) {
      ++stalled;
    }
    const bool atFloor = stalled >= 3 && rep.residual <= 100 * goal;
    if (cancel_ && cancel_->load()) return fail("cancelled");
    if (rep.residual <= goal || atFloor) {
      if (atFloor && rep.residual > goal)
        rep.message = "converged to the round-off floor of the forces";
      rep.converged = true;
      lastX_ = x;
      if (fc) fc->travel = travel;
      lastShift_ = shift;
      return rep;
    }
    if (it >= options_.maxIterations) {
      std::ostringstream s;
      s << "did not converge in " << it << " iterations (relative residual "
        << rep.relativeResidual() << ")";
      return fail(s.str());
    }
    // The first iteration of a solve uses the positive part of each contact element's Hessian
    // (the sphere's curvature makes it indefinite: robust, and the lagged factor stays a good
    // preconditioner); later iterations use the exact tangent, so convergence is quadratic,
    // unless the exact tangent has already failed to be positive definite in this solve or the
    // last one: then the positive part again (one factorisation per iteration instead of two,
    // at the price of a linear rate in the contact's curvature term, which is small).
    const bool projectFirst = options_.projectContactHessian && (it == 0 || projectContact);
    if (!ev_.hasHessian || (projectFirst != ev_.contactProjected && ev_.contactTriangles > 0)) {
      evaluateAt(x, travel, true, ev_, projectFirst);
    }
    auto tick = Clock::now();

    // Newton direction. First by conjugate gradients preconditioned with the last Cholesky
    // factor (from an earlier iteration or load step: the tangent changes little between them),
    // which costs a few triangular solves instead of a factorisation; if that does not converge
    // quickly, or meets negative curvature, factorise the current tangent with a diagonal shift
    // that grows until the factorisation succeeds.
    double maxDiag = 0;
    for (int j = 0; j < nAll; ++j) maxDiag = std::max(maxDiag, std::abs(ev_.hessian[diagPos[j]]));
    if (maxDiag == 0) maxDiag = stiffScale;
    if (fc)
      for (int i = 0; i < n; ++i) b[i] = ev_.probeCoupling.row(freeDofs[i]).dot(fc->axis);
    bool solved = false;
    // A factor whose last CG solve failed, or took more than refactorAfterPcg iterations and
    // more than a quarter of a factorisation's time, has drifted too far from the tangent: it is
    // refactorised straight away. (On the default meristem a factorisation costs about as much as
    // 40 CG iterations; on large meshes the triangular solves get relatively cheaper, so more CG
    // iterations are worth doing before refactorising.)
    const bool factorDrifted =
        lastPcgFailed_ || (lastPcgIterations_ > options_.refactorAfterPcg &&
                           lastPcgSeconds_ > 0.25 * factorSeconds_);
    if (options_.reuseFactorization && chol_.factored() && shift == 0 && !factorDrifted) {
      // Inexact Newton: solve just accurately enough for this step to reach the tolerance
      // (a tenth of the remaining reduction), never looser than pcgTolerance.
      const double target = std::max(options_.tolerance * rep.loadScale, noiseFloor);
      const double eta = std::clamp(0.1 * target / rep.residual, 1e-12, options_.pcgTolerance);
      int its = 0;
      tick = Clock::now();
      solved = pcg(pattern, ev_.hessian, g, dx, eta, its) &&
               (!fc || pcg(pattern, ev_.hessian, b, z2, eta, its));
      lastPcgSeconds_ = seconds(tick);
      totals_.pcgSeconds += lastPcgSeconds_;
      rep.pcgIterations += its;
      lastPcgIterations_ = its / (fc ? 2 : 1);
      lastPcgFailed_ = !solved;
    }
    if (!solved) {
      tick = Clock::now();
      std::string why;
      const auto refresh = [&] {
        // The contact Hessian's positive part, for this iteration (see factorizeTangent) and
        // the rest of this solve.
        projectContact = true;
        evaluateAt(x, travel, true, ev_, true);
        if (fc)
          for (int i = 0; i < n; ++i) b[i] = ev_.probeCoupling.row(freeDofs[i]).dot(fc->axis);
      };
      if (!factorizeTangent(shift, maxDiag, rep.factorizations, refresh, why)) return fail(why);
      lastPcgIterations_ = 0;
      lastPcgSeconds_ = 0;
      lastPcgFailed_ = false;
      rep.maxShift = std::max(rep.maxShift, shift);
      chol_.solve(g, dx);
      if (fc) chol_.solve(b, z2);
      totals_.factorSeconds += seconds(tick);
    }
    dx = -dx;
    double ds = 0;
    if (fc) {
      const double kss = fc->axis.dot(ev_.probeHessian * fc->axis);
      double schur = kss - b.dot(z2);
      const double schurFloor = 1e-3 * stiffScale;
      if (!(schur > schurFloor)) schur = std::max(schur, 0.0) + schurFloor + shift;
      // [K b; bᵀ kss][dx; ds] = −[g; gs], with K⁻¹g = −dx from above.
      ds = -(gs + b.dot(dx)) / schur;
      dx -= z2 * ds;
    }
    const double slope = g.dot(dx) + gs * ds;
    if (!(slope < 0)) return fail("Newton direction is not a descent direction");

    double alphaMax = 1.0;
    if (fc && maxProbeStep > 0 && std::abs(ds) > maxProbeStep) alphaMax = maxProbeStep / std::abs(ds);
    if (model_.probe()) {
      stepPoints.setZero(3, x.cols());
      for (int i = 0; i < n; ++i) stepPoints.data()[freeDofs[i]] = dx[i];
      const double bound = model_.contactStepBound(x, stepPoints, fc ? Vec3(ds * fc->axis) : Vec3::Zero());
      if (!(bound > 1e-12 * alphaMax))
        return fail("no step keeps the probe clear of the walls (contact would be lost)");
      alphaMax = std::min(alphaMax, bound);
    }

    // Backtracking line search on the energy (Armijo). When the energy change is within its
    // round-off (the energy is a sum of terms far larger than their total), a step is judged by
    // the residual instead, which stays accurate. Each trial state is evaluated with its
    // gradient, so the accepted one needs no new evaluation.
    const double noise = 1e-13 * (ev_.energy.magnitude + (fc ? std::abs(fc->force * travel) : 0.0));
    const double energy0 = rep.energy, residual0 = rep.residual;
    double alpha = alphaMax;
    bool accepted = false;
    for (int ls = 0; ls < options_.maxLineSearch; ++ls) {
      xt = x;
      for (int i = 0; i < n; ++i) xt.data()[freeDofs[i]] += alpha * dx[i];
      evaluateAt(xt, travel + alpha * ds, false, trial_);
      double et, rt, lt;
      measure(trial_, travel + alpha * ds, et, rt, lt);
      if (std::isfinite(et) && (et <= energy0 + 1e-4 * alpha * slope ||
                                (et <= energy0 + noise && rt <= 0.9 * residual0))) {
        accepted = true;
        break;
      }
      alpha *= 0.5;
    }
    if (!accepted) return fail("line search failed to decrease the energy");
    x = xt;
    travel += alpha * ds;
    std::swap(ev_, trial_);
    // A shift that worked is tried smaller next time; full steps suggest it is not needed.
    shift = (alpha == 1.0) ? shift * 0.1 : shift;
    if (shift < 1e-12 * maxDiag) shift = 0;
  }
}

}  // namespace tp
