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
// A CG iteration's cost in flops of the factorisation per nonzero of L (newtonDirection).
constexpr double kPcgIterationFlopsPerNonzero = 13.0;
double seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}
}  // namespace

StaticSolver::StaticSolver(Model& model, SolverOptions options)
    : model_(model), options_(options) {
  if (std::getenv("TP_NEWTON_VERBOSE")) options_.verbose = true;  // debugging aid
}

// The preconditioner of CG: the lagged single-precision factor, and when the pressed triangles'
// block of the current tangent is held (local_), a symmetric multiplicative Schwarz step around
// it — the exact local solve, the lagged factor on what is left, the local solve again
// (Smith, Bjørstad & Gropp, "Domain Decomposition", 1996, §1.3). The factor misses the stiffness
// of triangles that entered the contact since it was computed; the local block has it.
void StaticSolver::precondition(const Eigen::VectorXd& r, Eigen::VectorXd& z) {
  if (!local_.active()) {
    chol_.solveSinglePrecision(r, z);
    return;
  }
  Eigen::VectorXd w = Eigen::VectorXd::Zero(r.size());
  local_.correct(r, w);
  Eigen::VectorXd t = r;
  Eigen::VectorXd wl(local_.size());
  for (int a = 0; a < local_.size(); ++a) wl[a] = w[local_.unknowns()[a]];
  local_.subtractProduct(wl, t);  // r − A w
  chol_.solveSinglePrecision(t, z);
  z += w;
  local_.correct(r, z);
}

bool StaticSolver::pcg(const SparsePattern& pattern, const std::vector<double>& values,
                       const Eigen::VectorXd& rhs, Eigen::VectorXd& sol, double relTol,
                       int& iterations, int maxIterations) {
  const double target = relTol * rhs.norm();
  sol.setZero(rhs.size());
  Eigen::VectorXd r = rhs, z, p, q;
  precondition(r, z);
  p = z;
  double rz = r.dot(z);
  if (!(rz > 0)) return false;  // the preconditioner is not positive definite here
  q.resize(rhs.size());
  for (int k = 0; k < maxIterations; ++k) {
    symmetricMultiply(pattern, values, p.data(), q.data());
    const double pq = p.dot(q);
    if (!(pq > 0)) return false;  // negative curvature: leave it to the shifted factorisation
    const double a = rz / pq;
    sol += a * p;
    r -= a * q;
    ++iterations;
    if (r.norm() <= target) return true;
    precondition(r, z);
    const double rzNew = r.dot(z);
    if (!(rzNew > 0)) return false;
    p = z + (rzNew / rz) * p;
    rz = rzNew;
  }
  return false;
}

void StaticSolver::analyze() {
  if (analyzedFor_ == &model_.pattern() && analyzedNnz_ == model_.pattern().nnz()) return;
  chol_.analyze(model_.pattern(), model_.orderingNodes());
  analyzedFor_ = &model_.pattern();
  analyzedNnz_ = model_.pattern().nnz();
}

double StaticSolver::timeFactorization() {
  analyze();
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
    const auto st = chol_.factorize(ev_.hessian, shift);
    if (st == CholmodSolver::Status::Ok) return true;
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
    // The first shift is 1e-4 of the largest diagonal entry, as in "Cholesky with added
    // multiple of the identity" (Nocedal & Wright, Numerical Optimization, 2nd ed., Alg. 3.3,
    // which starts at 1e-3 of the matrix norm), then ten times more per failure. Starting at
    // 1e-8 cost six failed factorisations in the turgid rest state of every tissue (it needs
    // about 1e-3: pressure against walls with no tension yet), 4 s of a 10 s site pick on the
    // real flower; a shift that turns out larger than needed costs at most an iteration or two,
    // since each full step divides it by ten.
    shift = shift == 0 ? 1e-4 * maxDiag : shift * 10.0;
    if (shift > 1e6 * maxDiag) break;
  }
  why = "tangent matrix could not be made positive definite";
  return false;
}

bool StaticSolver::tangentSolve(const Points& x, const LoadsAt& loadsAt,
                                Eigen::MatrixXd& displacements) {
  const DofMap& dofs = model_.dofs();
  const int n = dofs.freeCount();
  if (n == 0) return false;
  const bool reanalyse =
      analyzedFor_ != &model_.pattern() || analyzedNnz_ != model_.pattern().nnz();
  analyze();
  const auto tick = Clock::now();
  model_.evaluate(x, ev_, true);
  lastX_ = x;
  totals_.assemblySeconds += seconds(tick);
  double maxDiag = 0;
  for (int j = 0; j < n; ++j)
    maxDiag = std::max(maxDiag, std::abs(ev_.hessian[model_.pattern().colPtr[j + 1] - 1]));
  if (!(maxDiag > 0)) return false;
  const Eigen::MatrixXd loads = loadsAt(ev_);  // from the evaluation K(x) is built on
  if (loads.rows() != dofs.fullCount() || loads.cols() == 0) return false;
  // The pattern may carry a bending term's edge unknowns after the positions (Model::pattern()):
  // they take a zero right-hand side and their part of the solution is not used.
  const int nAll = model_.pattern().n;
  std::vector<Eigen::VectorXd> f(loads.cols(), Eigen::VectorXd::Zero(nAll)), u(loads.cols());
  for (Eigen::Index c = 0; c < loads.cols(); ++c)
    for (int i = 0; i < n; ++i) f[c][i] = loads(dofs.freeDofs()[i], c);

  // First, conjugate gradients on the exact K(x) preconditioned with the factor held from the
  // last solve (usually of a nearby state: the last Newton iterations, a depth before), to a
  // relative residual of 1e-12 — as accurate as the direct solve for the derivatives of a fit
  // (ForceSensitivity's finite-difference tests) — within the operation count of one
  // factorisation over all the loads (the rule of newtonDirection: a CG iteration costs about
  // 13 flops per nonzero of L). An indefinite K(x), or a preconditioner too far from it, ends
  // CG early: then the factorisation, as before.
  bool solved = false;
  if (options_.reuseFactorization && !reanalyse && chol_.factored() && chol_.factorFlops() > 0) {
    const int budget = static_cast<int>(chol_.factorFlops() /
                                        (kPcgIterationFlopsPerNonzero * chol_.factorNonzeros()));
    const auto start = Clock::now();
    solved = true;
    int used = 0;
    for (size_t c = 0; c < f.size() && solved; ++c) {
      int its = 0;
      solved = f[c].norm() == 0
                   ? (u[c].setZero(nAll), true)
                   : pcg(model_.pattern(), ev_.hessian, f[c], u[c], 1e-12, its, budget - used);
      used += its;
    }
    totals_.pcgIterations += used;
    totals_.pcgSeconds += seconds(start);
  }
  if (!solved) {
    double shift = 0;  // the exact tangent: derivatives of an equilibrium (fit sensitivities)
    int factorizations = 0;
    std::string why;
    const auto start = Clock::now();
    const bool ok = factorizeTangent(shift, maxDiag, factorizations, {}, why);
    totals_.factorizations += factorizations;
    totals_.factorSeconds += seconds(start);
    if (!ok) return false;
    lastPcgIterations_ = 0;
    lastPcgFailed_ = false;
    for (size_t c = 0; c < f.size(); ++c) chol_.solve(f[c], u[c]);
  }
  displacements.setZero(dofs.fullCount(), loads.cols());
  for (Eigen::Index c = 0; c < loads.cols(); ++c)
    for (int i = 0; i < n; ++i) displacements(dofs.freeDofs()[i], c) = u[c][i];
  return displacements.allFinite();
}

SolveReport StaticSolver::solve(Points& x, ForceControl* fc) {
  SolveReport rep = solveImpl(x, fc);
  ++totals_.solves;
  totals_.iterations += rep.iterations;
  totals_.factorizations += rep.factorizations;
  totals_.pcgIterations += rep.pcgIterations;
  return rep;
}

// One solve's state, shared by the named steps of an iteration.
struct StaticSolver::Run {
  Run(Points& x_, ForceControl* fc_, const Model& model)
      : x(x_), fc(fc_), dofs(model.dofs()), pattern(model.pattern()), n(dofs.freeCount()),
        nAll(pattern.n), freeDofs(dofs.freeDofs()), x0(x_), travel0(fc_ ? fc_->travel : 0.0),
        travel(travel0), xt(x_) {}
  Points& x;
  ForceControl* fc;
  SolveReport rep;
  const DofMap& dofs;
  const SparsePattern& pattern;
  // Vectors span the whole pattern: the free position components, then any own unknowns of the
  // terms (Model::pattern()), which take a zero right-hand side; only the position part of a
  // solution moves the tissue.
  const int n, nAll;
  const std::vector<int>& freeDofs;
  std::vector<int> diagPos;  // of each unknown's diagonal entry in the values
  const Points x0;
  const double travel0;
  double travel;
  double stiffScale = 0, floor = 0, noiseFloor = 0, stallFloor = 0, maxProbeStep = 0;
  Eigen::VectorXd g, dx, z2, b;  // residual, Newton step, K⁻¹b, b = ∂²W/∂x∂s
  double gs = 0;                 // the residual of the probe's travel under force control
  double shift = 0, maxDiag = 0;
  bool projectContact = false;   // the contact Hessian's positive part for the rest of the solve
  // After a full step taken with a shifted factor: factorise the exact tangent first
  // (newtonDirection); not again in this solve once that has failed.
  bool tryExact = false, exactFailed = false;
  double lastResidual = 0;  // at the previous iteration of this solve (0 at the first)
  bool relaxed = false;     // this iteration started with a kept contact relaxation
  bool nearStart = false;   // the solve started within 1e4 × the target: exact tangent at once
  bool renewedChord = false;   // this iteration's direction on the held tangent, contact renewed
  const char* direction = "";  // how the last direction was found (verbose output)
  Points xt, stepPoints;
};

SolveReport StaticSolver::solveImpl(Points& x, ForceControl* fc) {
  if (fc && !model_.probe()) throw std::logic_error("force control needs a probe on the model");
  Run r(x, fc, model_);
  analyze();  // r.pattern is the model's
  r.diagPos.resize(r.nAll);
  for (int j = 0; j < r.nAll; ++j) r.diagPos[j] = r.pattern.colPtr[j + 1] - 1;  // row == col last
  const Material& mat = model_.material();
  r.stiffScale = mat.youngModulus * mat.thickness;  // µN/µm
  r.floor = loadFreeFloor(model_);
  r.noiseFloor = roundOffFloor(model_, r.n);
  r.stallFloor = positionRoundOffFloor(model_, r.n);
  r.maxProbeStep = options_.maxProbeStep > 0
                       ? options_.maxProbeStep
                       : (model_.probe() ? 0.25 * model_.probe()->radius : 0.0);
  r.g = Eigen::VectorXd::Zero(r.nAll);
  r.b = Eigen::VectorXd::Zero(r.nAll);
  r.dx.resize(r.nAll);
  r.z2.resize(r.nAll);
  r.shift = lastShift_ > 0 ? lastShift_ * 0.1 : 0.0;
  if (options_.relaxContact) patternRows_.build(r.pattern);
  r.projectContact = projectedLastSolve_;
  struct Remember {
    bool& from;
    bool& to;
    ~Remember() { to = from; }
  } remember{r.projectContact, projectedLastSolve_};

  double bestResidual = std::numeric_limits<double>::infinity();
  int stalled = 0;
  evaluateAt(r, x, r.travel, false, ev_);
  // Contact that cannot be lost: start clear of the walls and keep the clearance at every step.
  if (model_.probe() && !(model_.probeDistance(x) > model_.contactClearance()))
    return fail(r, "the probe starts within half its radius of a wall (a step too large for the "
                   "contact to be followed)");
  for (int it = 0;; ++it) {
    SolveReport& rep = r.rep;
    measure(r, ev_, r.travel, rep.energy, rep.residual, rep.loadScale);
    rep.iterations = it;
    if (options_.verbose)
      std::fprintf(stderr,
                   "  newton %2d  E=%.12g  |g|=%.3e  rel=%.3e  shift=%.2e  contact=%d  "
                   "factorisations=%d  cg=%d\n",
                   it, rep.energy, rep.residual, rep.relativeResidual(), r.shift,
                   ev_.contactTriangles, rep.factorizations, rep.pcgIterations);
    if (!std::isfinite(rep.energy)) return fail(r, "energy is not finite");
    if (!std::isfinite(rep.residual)) return fail(r, "residual is not finite");
    // Stagnation: when full Newton steps no longer reduce the residual and it is already within
    // a hundred times the target, or than the floor of positions far from the origin, it sits
    // on the round-off floor of the forces (sliver triangles far from the origin make that floor
    // higher than roundOffFloor() says): the state is as converged as the arithmetic allows.
    const double goal = std::max(options_.tolerance * rep.loadScale, r.noiseFloor);
    if (rep.residual < 0.5 * bestResidual) {
      bestResidual = rep.residual;
      stalled = 0;
    } else if (it > 0) {
      ++stalled;
    }
    const bool atFloor = stalled >= 3 && rep.residual <= 100 * std::max(goal, r.stallFloor);
    if (cancel_ && cancel_->load()) return fail(r, "cancelled");
    const auto succeed = [&] {
      if (rep.residual > goal) rep.message = "converged to the round-off floor of the forces";
      rep.converged = true;
      lastX_ = x;
      if (fc) fc->travel = r.travel;
      lastShift_ = r.shift;
      return rep;
    };
    if (rep.residual <= goal || atFloor) return succeed();
    if (it >= options_.maxIterations) {
      std::ostringstream s;
      s << "did not converge in " << it << " iterations (relative residual "
        << rep.relativeResidual() << ")";
      return fail(r, s.str());
    }
    // The first iteration assembles its tangent at the relaxed state straight away (it always
    // needs one: the predictor leaves ~1e-5 of the load scale, the relaxation a tenth of that).
    // A start already near the solution is in the quadratic regime: the exact tangent from the
    // first iteration reaches the target in one step, where the contact Hessian's positive part
    // (robust further away) leaves a linear rate — a fit's points, started from the last
    // parameters' equilibria moved to first order, went 5e-8 → 1.5e-10 against 1e-10 asked,
    // and needed a second iteration. "Near": within 1e4 × the target before the relaxation
    // (which takes about a tenth off), decided here so that the relaxation assembles the same
    // tangent as newtonDirection uses. Measured (BM_LoadingCurve, alternated thresholds): at
    // level 3, 79 → 68 iterations and 380 → 325 CG with 1e4 or 1e5 (none with 1e3 taken before
    // the relaxation; 1e3 after it cost a second assembly at level 0); level 0 57 either way.
    if (it == 0) r.nearStart = rep.residual <= 1e4 * goal;
    // The contact relaxation works with a tangent held from an earlier evaluation. The first
    // contact solve on a new mesh has none (its rest state was solved without the probe), so
    // this iterate's tangent is assembled first (serving the Newton step if the relaxation is
    // dropped; one more assembly if it is kept): without it level 4's end point for an error
    // estimate (165 pressed triangles) ran CG on the rest state's factor to its 25 iterations
    // and factorised twice, with it once (bench/README.md).
    if (it == 0 && options_.relaxContact && ev_.contactTriangles > 0 && model_.probe() &&
        !relax_.heldTangent(model_))
      evaluateAt(r, r.x, r.travel, true, ev_, options_.projectContactHessian && !r.nearStart);
    // A near start's first direction on the tangent held from the last assembly (an earlier
    // solve's, for a drag the step before), its contact part renewed here: between neighbouring
    // equilibria the walls' tangent changes little, the contact's most (the patch grows and
    // shrinks), and that costs two evaluations of the contact term instead of a whole assembly
    // (a fifth of a drag step at level 3). On the drag replay (BM_DragReplay/3) the step cut
    // the residual 40–130× where the assembled tangent cut it 60–250×, so a drag's steps settle
    // smaller (core/experiment/Drag.h); loading curves, at a tighter tolerance, keep it off. If
    // CG fails on it, newtonDirection assembles.
    r.renewedChord = options_.renewedChordFirst && options_.relaxContact && it == 0 &&
                     r.nearStart && !r.fc && r.shift == 0 && model_.probe() &&
                     relax_.heldTangent(model_);
    r.relaxed = relaxContact(r, goal, it == 0 && !r.renewedChord);
    if (r.relaxed && rep.residual <= goal) return succeed();
    std::string why;
    if (!newtonDirection(r, it, why)) return fail(r, why);
    const double ds = probeStep(r);
    const double slope = r.g.dot(r.dx) + r.gs * ds;
    if (!(slope < 0)) return fail(r, "Newton direction is not a descent direction");
    const double alphaMax = stepLimit(r, ds);
    if (!(alphaMax > 0))
      return fail(r, "no step keeps the probe clear of the walls (contact would be lost)");
    const double alpha = lineSearch(r, ds, slope, alphaMax);
    if (!(alpha > 0)) return fail(r, "line search failed to decrease the energy");
    if (options_.verbose)
      std::fprintf(stderr, "  newton step  alpha=%.3g  (at most %.3g)  |ds|=%.3g  %s\n", alpha,
                   alphaMax, std::abs(ds), r.direction);
    // A shift that worked is tried smaller next time; full steps suggest it is not needed.
    if (alpha == 1.0) r.shift *= 0.1;
    if (r.shift < 1e-12 * r.maxDiag) r.shift = 0;
    r.tryExact = alpha == 1.0 && r.shift > 0 && !r.exactFailed;
    r.lastResidual = rep.residual;
  }
}

// Nonlinear elimination of the contact vertices (solver/ContactRelaxation.h): the pressed
// triangles' vertices moved to the minimum of the energy over them alone, kept when the model's
// energy does not rise and its residual falls by a tenth or more; r.rep and r.g are then of the
// new state. Costs one evaluation (with the tangent when withTangent) and a small dense solve.
bool StaticSolver::relaxContact(Run& r, double goal, bool withTangent) {
  if (!options_.relaxContact || !model_.probe() || ev_.contactTriangles == 0) return false;
  if (!relax_.relax(model_, patternRows_, r.x, ev_.gradient, 0.1 * goal, r.stepPoints))
    return false;
  if (!(model_.contactStepBound(r.x, r.stepPoints, Vec3::Zero()) >= 1.0)) return false;
  r.xt = r.x + r.stepPoints;
  const bool project =
      withTangent && options_.projectContactHessian && !r.nearStart;  // as newtonDirection
  evaluateAt(r, r.xt, r.travel, withTangent, trial_, project);
  double et, rt, lt;
  measure(r, trial_, r.travel, et, rt, lt);
  const double noise =
      1e-13 * (ev_.energy.magnitude + (r.fc ? std::abs(r.fc->force * r.travel) : 0.0));
  const bool kept = std::isfinite(et) && std::isfinite(rt) && et <= r.rep.energy + noise &&
                    rt <= 0.9 * r.rep.residual;
  if (options_.verbose)
    std::fprintf(stderr, "  contact relaxation  |g| %.3e -> %.3e  %s\n", r.rep.residual, rt,
                 kept ? "kept" : "dropped");
  if (kept) {
    r.x = r.xt;
    std::swap(ev_, trial_);
  }
  measure(r, ev_, r.travel, r.rep.energy, r.rep.residual, r.rep.loadScale);
  return kept;
}

// The held tangent K_h (assembled at x_h with the probe then) with its contact part C renewed
// at x with the probe now: K_h − C(x_h) + C(x), C with the held tangent's projection.
const std::vector<double>* StaticSolver::renewedHeldTangent(const Points& x) {
  const std::vector<double>* held = relax_.heldTangent(model_);
  if (!held || !model_.probe()) return nullptr;
  const auto tick = Clock::now();
  const EvalOptions o{
      .hessian = true, .projectContact = relax_.heldProjected(), .onlyTerm = model_.contactTerm()};
  const Probe now = *model_.probe();
  model_.setProbe(relax_.heldProbe());
  model_.evaluate(relax_.heldPositions(), contactThen_, o);
  model_.setProbe(now);
  model_.evaluate(x, contactNow_, o);
  renewed_.resize(held->size());
  const double *h = held->data(), *c0 = contactThen_.hessian.data(),
               *c1 = contactNow_.hessian.data();
  for (size_t i = 0; i < renewed_.size(); ++i) renewed_[i] = h[i] + (c1[i] - c0[i]);
  totals_.assemblySeconds += seconds(tick);
  ++totals_.renewedChords;
  return &renewed_;
}

SolveReport StaticSolver::fail(Run& r, const std::string& why) {
  r.x = r.x0;
  if (r.fc) {
    r.fc->travel = r.travel0;
    Probe p = *model_.probe();
    p.center = r.fc->origin + r.travel0 * r.fc->axis;
    model_.setProbe(p);
  }
  r.rep.converged = false;
  r.rep.message = why;
  return r.rep;
}

// Evaluates the model at (x, probe travel); the Hessian only when a Newton direction is needed
// (a gradient costs about a tenth of a full assembly, and most load steps converge in one
// iteration, so the state they end in never needs its Hessian).
void StaticSolver::evaluateAt(Run& r, const Points& at, double travel, bool withHessian,
                              Evaluation& e, bool projectContact) {
  if (r.fc) {
    Probe p = *model_.probe();
    p.center = r.fc->origin + travel * r.fc->axis;
    model_.setProbe(p);
  }
  const auto tick = Clock::now();
  model_.evaluate(at, e, EvalOptions{.hessian = withHessian, .projectContact = projectContact});
  if (withHessian && options_.relaxContact && model_.probe())
    relax_.hold(model_, at, e.hessian, e.contactProjected);
  (withHessian ? totals_.assemblySeconds : totals_.lineSearchSeconds) += seconds(tick);
  if (withHessian) ++totals_.assemblies;
}

// Energy (with the work of the applied force), residual (into r.g, r.gs) and load scale.
void StaticSolver::measure(Run& r, const Evaluation& e, double travel, double& energy,
                           double& residual, double& loadScale) {
  double loadNorm2 = 0;
  for (int i = 0; i < r.n; ++i) {
    r.g[i] = e.gradient[r.freeDofs[i]];
    loadNorm2 += e.loadGradient[r.freeDofs[i]] * e.loadGradient[r.freeDofs[i]];
  }
  r.gs = r.fc ? r.fc->axis.dot(e.probeGradient) - r.fc->force : 0.0;
  energy = e.energy.total() - (r.fc ? r.fc->force * travel : 0.0);
  loadScale = std::sqrt(loadNorm2) + (r.fc ? std::abs(r.fc->force) : 0.0) + r.floor;
  residual = std::sqrt(r.g.squaredNorm() + r.gs * r.gs);
}

// The Newton direction r.dx = −K⁻¹g (and r.z2 = K⁻¹b under force control). First by conjugate
// gradients preconditioned with the last Cholesky factor (from an earlier iteration or load
// step: the tangent changes little between them), which costs a few triangular solves instead
// of a factorisation; if that does not converge quickly, or meets negative curvature, the
// current tangent is factorised with a diagonal shift that grows until it succeeds.
bool StaticSolver::newtonDirection(Run& r, int it, std::string& why) {
  // The first iteration of a solve uses the positive part of each contact element's Hessian
  // (the sphere's curvature makes it indefinite: robust, and the lagged factor stays a good
  // preconditioner); later iterations use the exact tangent, so convergence is quadratic,
  // unless the exact tangent has already failed to be positive definite in this solve or the
  // last one: then the positive part again (one factorisation per iteration instead of two,
  // at the price of a linear rate in the contact's curvature term, which is small).
  // (Or, from a start already near the solution, the exact tangent at once: see solveImpl.)
  const bool projectFirst =
      options_.projectContactHessian && ((it == 0 && !r.nearStart) || r.projectContact);
  // A chord step: once the last iteration cut the residual a hundredfold and the relaxation has
  // taken the contact's nonlinearity, what is left is nearly linear, and the tangent of the last
  // iteration (held by relax_) serves instead of a new assembly (a quarter of a step's time at
  // level 3). If CG fails on it, the tangent here is assembled after all.
  const std::vector<double>* chord =
      r.renewedChord ? renewedHeldTangent(r.x)
      : it >= 1 && !r.fc && r.shift == 0 && r.relaxed && r.rep.residual < 1e-2 * r.lastResidual
          ? relax_.heldTangent(model_)
          : nullptr;
  if (!chord &&
      (!ev_.hasHessian || (projectFirst != ev_.contactProjected && ev_.contactTriangles > 0)))
    evaluateAt(r, r.x, r.travel, true, ev_, projectFirst);
  const std::vector<double>& tangent = chord ? *chord : ev_.hessian;
  const auto coupling = [&] {
    if (r.fc)
      for (int i = 0; i < r.n; ++i) r.b[i] = ev_.probeCoupling.row(r.freeDofs[i]).dot(r.fc->axis);
  };
  r.maxDiag = 0;
  for (int j = 0; j < r.nAll; ++j) r.maxDiag = std::max(r.maxDiag, std::abs(tangent[r.diagPos[j]]));
  if (r.maxDiag == 0) r.maxDiag = r.stiffScale;
  coupling();
  bool solved = false;
  // A factor whose last CG solve failed, or took more than refactorAfterPcg iterations and
  // more than a fraction of a factorisation's cost, has drifted too far from the tangent: it is
  // refactorised straight away. The costs are operation counts, not timings, so that the same
  // input always takes the same path to the same bits (a map's shards and a single run agree
  // byte for byte): a CG iteration (two single-precision triangular solves, memory-bound) takes
  // as long as ~13 flops of the supernodal factorisation per nonzero of L (measured on the
  // 2-core VM of bench/README.md: 1.1 ns per nonzero against 11.6 GFlop/s), so on the default
  // meristem a factorisation costs about as much as 40 CG iterations; on large meshes the
  // triangular solves get relatively cheaper, so more CG iterations are done before
  // refactorising. The fraction is a quarter (refactorFraction), and less when the contact
  // patch's block corrected the preconditioner (refactorFractionContact): with it the solves of
  // a level-3 curve stayed under a quarter to the end, on a factor drifting further (6 → 9
  // iterations a solve); solves without contact (rest states) keep the quarter they were
  // measured with.
  const double fraction =
      lastPcgLocal_ ? options_.refactorFractionContact : options_.refactorFraction;
  const bool factorDrifted =
      lastPcgFailed_ ||
      (lastPcgIterations_ > options_.refactorAfterPcg &&
       lastPcgIterations_ * kPcgIterationFlopsPerNonzero * chol_.factorNonzeros() >
           fraction * chol_.factorFlops());
  if (options_.reuseFactorization && chol_.factored() && r.shift == 0 && !factorDrifted) {
    // Inexact Newton: solve just accurately enough for this step to reach the tolerance
    // (a tenth of the remaining reduction), never looser than pcgTolerance. But while the
    // residual falls slowly (less than tenfold in the last iteration: far from the quadratic
    // regime, as in the first steps of a refined rest state) no step reaches the tolerance
    // whatever the linear accuracy, and that rule asked for 1e-8 where pcgTolerance does as
    // well: CG ran out of iterations and a factorisation followed, at every site pick. There
    // pcgTolerance is used, as Eisenstat and Walker's forcing term would ("Choosing the forcing
    // terms in an inexact Newton method", SIAM J. Sci. Comput. 17, 1996: η_k = 0.9 (‖g_k‖ /
    // ‖g_k−1‖)², above 0.009 for such a fall, capped here). The first iteration has no fall to
    // judge by: a start far from the solution (not nearStart, more than 1e4 × the target) is
    // not in the quadratic regime either, and takes pcgTolerance too, as Eisenstat and Walker's
    // η_0 (0.5 there). The tight rule asked the first iteration of level 4's end point for an
    // error estimate (started from level 3's dimple at 1e-2 of the load scale) for 1.5e-7: CG
    // reached 1.7e-5 in its 25 iterations, a good first step, and was thrown away for a
    // factorisation; with pcgTolerance, 15 iterations, and the solve 18 CG and one
    // factorisation instead of 34 and one (`tissueprobe-cli indent --site
    // 19.5249,-2.0653,42.894 --steps 5 --verbose`). A near start keeps the tight rule: a drag
    // step ends in one iteration.
    const double target = std::max(options_.tolerance * r.rep.loadScale, r.noiseFloor);
    const bool slow = r.lastResidual > 0 ? r.rep.residual > 0.1 * r.lastResidual : !r.nearStart;
    const double eta = slow ? options_.pcgTolerance
                            : std::clamp(0.1 * target / r.rep.residual, 1e-12, options_.pcgTolerance);
    int its = 0;
    const auto tick = Clock::now();
    if (options_.relaxContact && ev_.contactTriangles > 0 && patternRows_.builtFor(r.pattern))
      local_.build(patternRows_, tangent, pressedUnknowns(model_, r.x, patternRows_), true);
    lastPcgLocal_ = local_.active();
    solved = pcg(r.pattern, tangent, r.g, r.dx, eta, its, options_.maxPcgIterations) &&
             (!r.fc || pcg(r.pattern, tangent, r.b, r.z2, eta, its, options_.maxPcgIterations));
    local_.clear();
    totals_.pcgSeconds += seconds(tick);

    r.rep.pcgIterations += its;
    lastPcgIterations_ = its / (r.fc ? 2 : 1);
    lastPcgFailed_ = !solved;
  }
  if (!solved && chord) {
    r.relaxed = false;  // no chord again: the tangent at this iterate
    r.renewedChord = false;
    evaluateAt(r, r.x, r.travel, true, ev_, projectFirst);
    return newtonDirection(r, it, why);
  }
  if (!solved) {
    const auto tick = Clock::now();
    const auto refresh = [&] {
      // The contact Hessian's positive part, for this iteration (see factorizeTangent) and
      // the rest of this solve.
      r.projectContact = true;
      evaluateAt(r, r.x, r.travel, true, ev_, true);
      coupling();
    };
    // With a shift held (the tangent was indefinite a few iterations ago), the exact tangent is
    // tried first once a full step suggests the shift is no longer needed: a refined rest state
    // on the real flower needs a shift at its first iteration only, and the shift, divided by
    // ten per full step, made every later iteration factorise (CG on the held factor is tried
    // only without one): 7–8 factorisations of 0.5–0.8 s for a site. If the exact tangent is
    // not positive definite the shifted factorisation follows as before, and the exact one is
    // not tried again in this solve (a tangent that stays indefinite, as with the probe on a
    // junction of a plasmolysed tissue, costs one failed factorisation, not one per iteration).
    bool exact = false;
    if (r.tryExact && r.shift > 0) {
      r.tryExact = false;
      ++r.rep.factorizations;
      exact = chol_.factorize(ev_.hessian, 0.0) == CholmodSolver::Status::Ok;
      if (exact) r.shift = 0;
      else r.exactFailed = true;
    }
    if (!exact && !factorizeTangent(r.shift, r.maxDiag, r.rep.factorizations, refresh, why))
      return false;
    lastPcgIterations_ = 0;
    lastPcgFailed_ = false;
    r.rep.maxShift = std::max(r.rep.maxShift, r.shift);
    chol_.solve(r.g, r.dx);
    if (r.fc) chol_.solve(r.b, r.z2);
    totals_.factorSeconds += seconds(tick);
  }
  r.direction = r.renewedChord ? "CG on the held tangent, contact renewed"
                : chord        ? "CG on the last tangent (chord)"
                : solved       ? (ev_.contactProjected ? "CG, contact projected" : "CG")
                               : (ev_.contactProjected ? "factor, contact projected" : "factor");
  r.dx = -r.dx;
  return true;
}

// Under force control the probe's travel s borders the tissue's matrix:
// [K b; bᵀ kss][dx; ds] = −[g; gs]. With K⁻¹g = −dx and K⁻¹b = z2 from newtonDirection, the
// Schur complement kss − bᵀK⁻¹b gives ds, and dx is corrected by −z2·ds. Returns ds (0 under
// displacement control).
double StaticSolver::probeStep(Run& r) {
  if (!r.fc) return 0.0;
  const double kss = r.fc->axis.dot(ev_.probeHessian * r.fc->axis);
  double schur = kss - r.b.dot(r.z2);
  const double schurFloor = 1e-3 * r.stiffScale;
  if (!(schur > schurFloor)) schur = std::max(schur, 0.0) + schurFloor + r.shift;
  const double ds = -(r.gs + r.b.dot(r.dx)) / schur;
  r.dx -= r.z2 * ds;
  return ds;
}

// The longest fraction of the step allowed: the probe moves at most maxProbeStep per iteration,
// and no point of the step may bring the probe within its clearance of a wall
// (Model::contactStepBound). 0 when no step keeps the clearance.
double StaticSolver::stepLimit(Run& r, double ds) {
  double alphaMax = 1.0;
  if (r.fc && r.maxProbeStep > 0 && std::abs(ds) > r.maxProbeStep)
    alphaMax = r.maxProbeStep / std::abs(ds);
  if (!model_.probe()) return alphaMax;
  r.stepPoints.setZero(3, r.x.cols());
  for (int i = 0; i < r.n; ++i) r.stepPoints.data()[r.freeDofs[i]] = r.dx[i];
  const double bound =
      model_.contactStepBound(r.x, r.stepPoints, r.fc ? Vec3(ds * r.fc->axis) : Vec3::Zero());
  if (!(bound > 1e-12 * alphaMax)) return 0.0;
  return std::min(alphaMax, bound);
}

// Backtracking line search on the energy (Armijo) from alphaMax. When the energy change is
// within its round-off (the energy is a sum of terms far larger than their total), a step is
// judged by the residual instead, which stays accurate. Each trial state is evaluated with its
// gradient, so the accepted one needs no new evaluation: it becomes the iterate (x, travel,
// ev_). Returns the step taken, 0 when none decreases the energy.
double StaticSolver::lineSearch(Run& r, double ds, double slope, double alphaMax) {
  const double noise =
      1e-13 * (ev_.energy.magnitude + (r.fc ? std::abs(r.fc->force * r.travel) : 0.0));
  const double energy0 = r.rep.energy, residual0 = r.rep.residual;
  double alpha = alphaMax;
  for (int ls = 0; ls < options_.maxLineSearch; ++ls) {
    r.xt = r.x;
    for (int i = 0; i < r.n; ++i) r.xt.data()[r.freeDofs[i]] += alpha * r.dx[i];
    evaluateAt(r, r.xt, r.travel + alpha * ds, false, trial_);
    double et, rt, lt;
    measure(r, trial_, r.travel + alpha * ds, et, rt, lt);
    if (std::isfinite(et) && (et <= energy0 + 1e-4 * alpha * slope ||
                              (et <= energy0 + noise && rt <= 0.9 * residual0))) {
      r.x = r.xt;
      r.travel += alpha * ds;
      std::swap(ev_, trial_);
      return alpha;
    }
    alpha *= 0.5;
  }
  return 0.0;
}

}  // namespace tp
