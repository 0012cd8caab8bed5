#include "experiment/Fit.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numeric>
#include <sstream>

#include "experiment/Analysis.h"
#include "experiment/Sensitivity.h"

namespace tp {

const FitValue* FitResult::find(const std::string& key) const {
  for (const FitValue& v : values)
    if (v.key == key) return &v;
  return nullptr;
}

// Not-a-knot ends: the third derivative continuous at the second and the last-but-one node
// (de Boor, "A Practical Guide to Splines", 1978, ch. IV).
Eigen::MatrixXd splineWeights(const std::vector<double>& t, const std::vector<double>& x) {
  const int n = static_cast<int>(t.size()), m = static_cast<int>(x.size());
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(m, n);
  if (n == 1) {
    W.setOnes();
    return W;
  }
  if (n <= 3) {  // Lagrange through all of them
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < n; ++j) {
        double l = 1;
        for (int k = 0; k < n; ++k)
          if (k != j) l *= (x[i] - t[k]) / (t[j] - t[k]);
        W(i, j) = l;
      }
    return W;
  }
  // The second derivatives M = K y: A M = R y, the interior rows the spline's continuity of the
  // first derivative, the end rows not-a-knot.
  std::vector<double> h(n - 1);
  for (int j = 0; j + 1 < n; ++j) h[j] = t[j + 1] - t[j];
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n), R = Eigen::MatrixXd::Zero(n, n);
  A(0, 0) = h[1];
  A(0, 1) = -(h[0] + h[1]);
  A(0, 2) = h[0];
  for (int j = 1; j + 1 < n; ++j) {
    A(j, j - 1) = h[j - 1];
    A(j, j) = 2 * (h[j - 1] + h[j]);
    A(j, j + 1) = h[j];
    R(j, j - 1) = 6 / h[j - 1];
    R(j, j) = -6 / h[j - 1] - 6 / h[j];
    R(j, j + 1) = 6 / h[j];
  }
  A(n - 1, n - 3) = h[n - 2];
  A(n - 1, n - 2) = -(h[n - 3] + h[n - 2]);
  A(n - 1, n - 1) = h[n - 3];
  const Eigen::MatrixXd K = A.partialPivLu().solve(R);
  for (int i = 0; i < m; ++i) {
    int j = 0;
    while (j + 2 < n && t[j + 1] < x[i]) ++j;
    const double a = (t[j + 1] - x[i]) / h[j], b = 1 - a, hh = h[j] * h[j] / 6;
    W(i, j) += a;
    W(i, j + 1) += b;
    W.row(i) += ((a * a * a - a) * hh) * K.row(j) + ((b * b * b - b) * hh) * K.row(j + 1);
  }
  return W;
}

namespace {

// The simulated force of one curve at its points and its exact derivatives (columns: E, p, h,
// depth — ForceSensitivity's dE, dp, dh, dDepth), at one value of what the curve depends on.
// The curve is simulated at a few depths (nodes) spanning its points, and the force at each
// point is their cubic spline (see interpolate()).
struct CurveEvaluation {
  std::array<double, 4> key{};  // E, the curve's turgor, h, its contact-point offset
  bool complete = false;
  std::vector<double> force;  // µN at the points, 0 before contact
  Eigen::MatrixXd sens;       // points × 4
  std::vector<double> nodes;  // µm, the depths simulated (increasing, positive)
  std::vector<double> nodeForce;
  Eigen::MatrixXd nodeSens;   // nodes × 4
  Points turgid;              // the turgid state (the start of the next key's)
  Eigen::MatrixXd response;   // how it moves with E, p, h (TurgidResponse::u; empty if unknown)
  std::vector<Points> states;  // the equilibrium at each node
  double endDepth = 0;         // µm, the deepest node's depth (its state is states.back())
};

// The depths a curve is simulated at: its points' positive depths (after the offset) when
// there are at most `count` of them (or `count` ≤ 0), else `count` depths evenly spread from
// the shallowest of them to the deepest.
std::vector<double> simulatedDepths(const std::vector<double>& depth, double offset, int count) {
  std::vector<double> d;
  for (double x : depth)
    if (x + offset > 0) d.push_back(x + offset);
  if (count <= 0 || static_cast<int>(d.size()) <= count) return d;
  std::vector<double> t(count);
  for (int j = 0; j < count; ++j) t[j] = d.front() + (d.back() - d.front()) * j / (count - 1);
  t.back() = d.back();
  return t;
}

// The force and its derivatives at the points from those at the nodes: the cubic spline through
// the nodes' values, the same linear map for every column, so that the derivatives at the points
// are the exact derivatives of the forces there (the nodes' are exact: Sensitivity.h). With the
// offset the nodes move as the points do (simulatedDepths), so ∂F/∂offset at a point is the
// spline of the nodes' ∂F/∂depth. At the nodes themselves the weights are exactly 0 and 1, so
// depths simulated as the curve's own points are taken as they are. A point before contact has
// no force and moves with nothing.
void interpolate(const std::vector<double>& depth, double offset, CurveEvaluation& ev) {
  const int m = static_cast<int>(depth.size()), n = static_cast<int>(ev.nodes.size());
  ev.force.assign(m, 0.0);
  ev.sens.setZero(m, 4);
  if (n == 0) return;
  std::vector<double> at;
  std::vector<int> row;
  for (int k = 0; k < m; ++k)
    if (depth[k] + offset > 0) {
      at.push_back(depth[k] + offset);
      row.push_back(k);
    }
  const Eigen::MatrixXd W = splineWeights(ev.nodes, at);
  const Eigen::Map<const Eigen::VectorXd> f(ev.nodeForce.data(), n);
  for (size_t i = 0; i < at.size(); ++i) {
    ev.force[row[i]] = W.row(i).dot(f);
    ev.sens.row(row[i]) = W.row(i) * ev.nodeSens;
  }
}

// One measured curve on its mesh (held during a search: a mesh that changed during the search
// would make the objective jump; with the automatic mesh checked at the fitted values after it,
// and the search run again on a finer one if they need it — see fitCurves).
struct CurveModel {
  std::shared_ptr<const RefinedComplex> mesh;  // the tissue refined at the site
  std::shared_ptr<const CellComplex> complex;  // = mesh->complex
  Vec3 restSite = Vec3::Zero(), axis = -Vec3::UnitZ();
  std::optional<Vec3> target;  // a site given in space: the nearest surface point at each θ
  std::optional<double> pressure;
  std::vector<double> depth, force;  // the points used, by increasing depth
  // The last two values of its key evaluated (the last accepted step and the last candidate).
  // Kept per curve: a step that moves only what one curve depends on (the turgor, for a
  // plasmolysed curve beside a turgid one) simulates that curve alone again.
  CurveEvaluation slots[2];
  int newest = 1;
  int level = 0;
  MeshError error;
};

// The parameters searched, in order: E, p, h (those fitted), then the offsets.
struct Layout {
  int E = -1, p = -1, h = -1, offset0 = -1, n = 0;
};

class Problem {
 public:
  Problem(const FitSettings& s, std::vector<CurveModel>& curves, const Layout& layout,
          const Monitor& monitor)
      : s_(s), curves_(curves), layout_(layout), monitor_(monitor) {}

  int residualCount() const {
    int m = 0;
    for (const CurveModel& c : curves_) m += static_cast<int>(c.depth.size());
    return m;
  }

  // The residuals F_sim − F_measured at theta and (when J is given) their Jacobian.
  bool simulate(const double* theta, std::vector<double>& r, Eigen::MatrixXd* J) {
    const double E = layout_.E >= 0 ? theta[layout_.E] : s_.start.material.youngModulus;
    const double p = layout_.p >= 0 ? theta[layout_.p] : s_.start.pressure;
    const double h = layout_.h >= 0 ? theta[layout_.h] : s_.start.material.thickness;
    if (!(E > 0) || !(h > 0) || !(p >= 0)) return false;
    r.assign(residualCount(), 0.0);
    if (J) J->setZero(residualCount(), layout_.n);
    bool simulated = false;
    int row = 0;
    for (size_t i = 0; i < curves_.size(); ++i) {
      CurveModel& c = curves_[i];
      const double offset = layout_.offset0 >= 0 ? theta[layout_.offset0 + i] : 0.0;
      const CurveEvaluation* ev = evaluate(c, {E, c.pressure.value_or(p), h, offset}, simulated);
      if (!ev) return false;
      for (size_t k = 0; k < c.depth.size(); ++k, ++row) {
        r[row] = ev->force[k] - c.force[k];
        if (!J) continue;
        if (layout_.E >= 0) (*J)(row, layout_.E) = ev->sens(k, 0);
        if (layout_.p >= 0 && !c.pressure) (*J)(row, layout_.p) = ev->sens(k, 1);
        if (layout_.h >= 0) (*J)(row, layout_.h) = ev->sens(k, 2);
        if (layout_.offset0 >= 0) (*J)(row, layout_.offset0 + static_cast<int>(i)) = ev->sens(k, 3);
      }
    }
    evaluations_ += simulated;
    return true;
  }

  // The equilibria to 1e-10 of the load scale: at the usual 1e-8 the probe's force, a small
  // part of the turgor loads, is known to ~1e-5 only, which stalls the search (the costs of
  // one point evaluated twice differ) well before the derivatives run out; 1e-11 is below the
  // round-off floor of deep indentations (the residual stalls near 3e-11 at 5 µm on the
  // default meristem).
  SolverOptions solverOptions() const {
    SolverOptions o = s_.start.solver;
    o.tolerance = std::min(o.tolerance, 1e-10);
    return o;
  }

  bool cancelled() const { return cancelled_; }
  int evaluations() const { return evaluations_; }
  const std::string& message() const { return message_; }

 private:
  // Curve c at `key`, with its derivatives: from its cache when computed there, else simulated.
  // The derivatives come with every simulation, asked for or not: Ceres asks for the residuals
  // of a candidate and then, when it accepts it, for the Jacobian there, and at an equilibrium
  // just solved the adjoint takes a few CG iterations on the factor Newton left (at level 2, 25
  // points: 3.0 s for the residuals, 1.7 s more for a Jacobian afterwards from the kept
  // equilibria, 0.4 s more with them). Null when a simulation fails or is cancelled.
  const CurveEvaluation* evaluate(CurveModel& c, const std::array<double, 4>& key,
                                  bool& simulated) {
    for (int slot : {0, 1})
      if (c.slots[slot].complete && c.slots[slot].key == key) {
        c.newest = slot;  // asked again for what was computed (the fit's final Jacobian)
        return &c.slots[slot];
      }
    if (monitor_.cancelled()) {
      cancelled_ = true;
      return nullptr;
    }
    simulated = true;
    // The older slot takes this key (the newer one stays the last complete evaluation until
    // this one completes), starting from the newer one's turgid state.
    const int slot = 1 - c.newest;
    const CurveEvaluation& from = c.slots[c.newest];
    Points guess = from.turgid;
    // To first order in the change of (E, p, h) (a fit's steps are a few per cent: its rest
    // state then needs one or two Newton iterations instead of three or four).
    if (guess.size() && from.response.rows() == guess.size() && from.response.cols() == 3) {
      const Eigen::Vector3d change(key[0] - from.key[0], key[1] - from.key[1],
                                   key[2] - from.key[2]);
      guess.reshaped() += from.response * change;
    }
    CurveEvaluation& out = c.slots[slot];
    out = CurveEvaluation();
    out.key = key;
    const auto [E, p, h, offset] = key;
    Material mat = s_.start.material;
    mat.youngModulus = E;
    mat.thickness = h;
    Model model(c.complex, mat);
    model.setUniformPressure(p);
    IndentationSettings is = s_.start.indentation;
    // The site as `indent` places it: the surface point nearest to a point given in space (at
    // every θ), or a material point (the top, or the settings' rest site).
    if (c.target) {
      is.site = c.target;
      is.restSite.reset();
    } else {
      is.site.reset();
      is.restSite = c.restSite;
    }
    is.axis = c.axis;
    is.control = Control::Depth;
    Indentation ind(model, is, solverOptions());
    ind.solver().setCancelFlag(monitor_.cancel);  // a cancel stops within one iteration
    const SolveReport rest = ind.prepare(guess.size() ? &guess : nullptr);
    if (!rest.converged) {
      message_ = "rest state at E = " + std::to_string(E) + ", p = " + std::to_string(p) + ": " +
                 rest.message;
      return nullptr;
    }
    out.turgid = ind.turgidState();
    // The turgid state's response, shared by the curve's points: solved once, not per point.
    const TurgidResponse turgid = turgidResponse(ind);
    if (!turgid.ok) {
      message_ = "the tangent of the turgid state could not be factorised";
      return nullptr;
    }
    out.response = turgid.u;
    out.nodes = simulatedDepths(c.depth, offset, s_.simulatedDepths);
    const int nodes = static_cast<int>(out.nodes.size());
    out.nodeForce.assign(nodes, 0.0);
    out.nodeSens.setZero(nodes, 4);
    out.states.assign(nodes, Points());
    for (int k = 0; k < nodes; ++k) {
      const double d = out.nodes[k];
      if (monitor_.cancelled()) {
        cancelled_ = true;
        return nullptr;
      }
      // From the last parameters' equilibrium at this depth moved as the depth before moved
      // between the two (the turgid state for the first): what changes with the parameters
      // and with the depth is carried, only their interaction is left to Newton. Else, or
      // if that does not converge, from the depth before by the predictor along the depths.
      CurvePoint pt;
      if (from.complete && static_cast<int>(from.states.size()) == nodes) {
        const bool first = k == 0;
        const Points& now = first ? out.turgid : out.states[k - 1];
        const Points& then = first ? from.turgid : from.states[k - 1];
        if (now.cols() == then.cols())
          pt = ind.solveFrom(d, false, from.states[k] + (now - then), d);
      }
      if (!pt.converged) pt = ind.goToDepth(d);
      if (!pt.converged) {
        message_ = "no equilibrium at depth " + std::to_string(d) + " um: " + ind.lastMessage();
        return nullptr;
      }
      out.nodeForce[k] = pt.force;
      const ForceSensitivity sens = forceSensitivity(ind, &turgid);
      if (!sens.ok) {
        message_ = "the tangent at depth " + std::to_string(d) + " um could not be factorised";
        return nullptr;
      }
      out.nodeSens.row(k) << sens.dE, sens.dp, sens.dh, sens.dDepth;
      out.states[k] = ind.state();
      out.endDepth = d;
    }
    interpolate(c.depth, offset, out);
    out.complete = true;
    c.newest = slot;
    return &out;
  }

  const FitSettings& s_;
  std::vector<CurveModel>& curves_;
  Layout layout_;
  const Monitor& monitor_;
  bool cancelled_ = false;
  int evaluations_ = 0;
  std::string message_;
};

// E factored out of the search (variable projection: Golub & Pereyra, "The differentiation of
// pseudo-inverses and nonlinear least squares problems whose variables separate", SIAM J. Numer.
// Anal. 10, 1973). Every energy term is linear in E at fixed p/E and h — the membrane ∝ E h,
// the bending ∝ E h³, the contact law's κ = 1e3 E h, the turgor term ∝ p — so W(x; λE, λp) =
// λ W(x; E, p): the equilibria at (λE, λp) are those at (E, p) and every force is λ times
// theirs. With E and p both fitted (and every held turgor 0, which any λ keeps), the search runs
// over φ = (q = p/E, then h and the offsets as fitted), each curve simulated at the starting
// modulus E_s with p = q E_s (force E_s f(φ)), and E is the least-squares scale of those forces,
// E*(φ) = f·F / f·f, in closed form. One nonlinear parameter fewer, and a curve whose turgor is
// held (plasmolysed) is simulated again only when h or its offset moves.
class ScaledProblem {
 public:
  ScaledProblem(Problem& problem, const Layout& layout, double Es, std::vector<double> measured)
      : problem_(problem), layout_(layout), Es_(Es), measured_(std::move(measured)) {
    if (layout.E != 0 || layout.p != 1) throw std::logic_error("E and p lead the parameters");
  }
  int size() const { return layout_.n - 1; }
  // φ of the full parameters θ (E, p, then the rest).
  std::vector<double> reduced(const std::vector<double>& theta) const {
    std::vector<double> phi(theta.begin() + 1, theta.end());
    phi[0] = theta[layout_.p] / theta[layout_.E];
    return phi;
  }
  // The full parameters simulated for φ: (E_s, q E_s, the rest of φ).
  std::vector<double> simulated(const double* phi) const {
    std::vector<double> theta(layout_.n);
    std::copy(phi, phi + size(), theta.begin() + 1);
    theta[layout_.E] = Es_;
    theta[layout_.p] = phi[0] * Es_;
    return theta;
  }
  // The residuals E* f − F at φ and (when J is given) their Jacobian over φ; `theta` and
  // `Jfull` (when given): the same point in the full parameters, (E*, q E*, …), and the
  // Jacobian there.
  bool evaluate(const double* phi, std::vector<double>& r, Eigen::MatrixXd* J,
                std::vector<double>* theta = nullptr, Eigen::MatrixXd* Jfull = nullptr) {
    std::vector<double> rs;
    Eigen::MatrixXd Js;
    const bool withJ = J || Jfull;
    if (!problem_.simulate(simulated(phi).data(), rs, withJ ? &Js : nullptr)) return false;
    const int m = static_cast<int>(rs.size());
    const Eigen::Map<const Eigen::VectorXd> F(measured_.data(), m);
    const Eigen::VectorXd f = (Eigen::Map<const Eigen::VectorXd>(rs.data(), m) + F) / Es_;
    const double ff = f.squaredNorm();
    const double E = ff > 0 ? f.dot(F) / ff : 0.0;  // µN per (µN/MPa): MPa
    if (!(E > 0)) return false;
    r.resize(m);
    Eigen::Map<Eigen::VectorXd>(r.data(), m) = E * f - F;
    if (theta) {
      *theta = simulated(phi);
      (*theta)[layout_.E] = E;
      (*theta)[layout_.p] = phi[0] * E;
    }
    if (!withJ) return true;
    // ∂f/∂φ: ∂F/∂p itself for q (F(E_s, q E_s) = E_s f(q)), the other columns over E_s.
    Eigen::MatrixXd df(m, size());
    for (int j = 0; j < size(); ++j) df.col(j) = Js.col(j + 1) / (j == 0 ? 1.0 : Es_);
    if (J) {  // ∂E*/∂φ_j = (∂f·F − 2 E* f·∂f) / f·f, the whole derivative (not Kaufman's part)
      J->resize(m, size());
      for (int j = 0; j < size(); ++j)
        J->col(j) = E * df.col(j) + f * ((df.col(j).dot(F) - 2 * E * f.dot(df.col(j))) / ff);
    }
    if (Jfull) {  // F(E, p, …) = E f(p/E, …): ∂F/∂E = f − q ∂f/∂q, ∂F/∂p = ∂f/∂q, the rest E ∂f
      Jfull->resize(m, layout_.n);
      Jfull->col(layout_.E) = f - phi[0] * df.col(0);
      Jfull->col(layout_.p) = df.col(0);
      for (int j = 1; j < size(); ++j) Jfull->col(j + 1) = E * df.col(j);
    }
    return true;
  }

 private:
  Problem& problem_;
  Layout layout_;
  double Es_;
  std::vector<double> measured_;
};

class Cost final : public ceres::CostFunction {
 public:
  using Evaluate_ = std::function<bool(const double*, std::vector<double>&, Eigen::MatrixXd*)>;
  Cost(Evaluate_ evaluate, int m, int n) : evaluate_(std::move(evaluate)), n_(n) {
    set_num_residuals(m);
    mutable_parameter_block_sizes()->push_back(n);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    std::vector<double> r;
    Eigen::MatrixXd J;
    const bool withJ = jacobians && jacobians[0];
    if (!evaluate_(parameters[0], r, withJ ? &J : nullptr)) return false;
    std::copy(r.begin(), r.end(), residuals);
    if (withJ)
      for (int i = 0; i < J.rows(); ++i)
        for (int j = 0; j < n_; ++j) jacobians[0][i * n_ + j] = J(i, j);
    return true;
  }

 private:
  Evaluate_ evaluate_;
  int n_;
};

// Up to `maxPoints` of the measured points, evenly spread by index over increasing depth.
void choosePoints(const MeasuredCurve& m, int maxPoints, CurveModel& c) {
  std::vector<size_t> order(m.depth.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return m.depth[a] < m.depth[b]; });
  const size_t n = order.size(), keep = std::min<size_t>(n, std::max(2, maxPoints));
  for (size_t k = 0; k < keep; ++k) {
    const size_t i = order[keep == 1 ? 0 : (k * (n - 1)) / (keep - 1)];
    if (!c.depth.empty() && m.depth[i] == c.depth.back()) continue;
    c.depth.push_back(m.depth[i]);
    c.force.push_back(m.force[i]);
  }
}

bool converged(const ceres::Solver::Summary& s) {
  return s.IsSolutionUsable() &&
         (s.termination_type == ceres::CONVERGENCE || s.termination_type == ceres::USER_SUCCESS);
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace

FitResult fitCurves(std::shared_ptr<const CellComplex> tissue, const FitSettings& settings,
                    const std::vector<FitCurve>& curves, const Monitor& monitor) {
  if (curves.empty()) throw std::invalid_argument("no measured curve to fit");
  if (!settings.fitE && !settings.fitP && !settings.fitH && !settings.fitOffset)
    throw std::invalid_argument("nothing to fit: choose some of E, p, h, offset");
  bool anyFreePressure = false;
  for (const FitCurve& c : curves) anyFreePressure |= !c.pressure.has_value();
  if (settings.fitP && !anyFreePressure)
    throw std::invalid_argument("p cannot be fitted: every curve holds its own turgor");
  settings.start.validate();

  // Each curve's mesh, site and axis. A fixed level as asked; with the automatic mesh its
  // first level, checked at the fitted values after the search (below). The rest state solved
  // here starts the first simulation.
  std::vector<CurveModel> models(curves.size());
  std::vector<ExperimentSettings> setups(curves.size());
  FitResult result;
  const bool automatic = settings.start.mesh.automatic;
  for (size_t i = 0; i < curves.size(); ++i) {
    const FitCurve& fc = curves[i];
    CurveModel& c = models[i];
    choosePoints(fc.data, settings.maxPoints, c);
    const double deepest = c.depth.empty() ? 0.0 : c.depth.back();
    if (!(deepest > 0))
      throw std::invalid_argument(fc.data.name + ": no point at a positive depth");
    c.pressure = fc.pressure;
    ExperimentSettings& es = setups[i];
    es = settings.start;
    if (fc.site) {  // else the starting settings' site (or material point, or the top)
      es.indentation.site = fc.site;
      es.indentation.restSite.reset();
    }
    es.indentation.control = Control::Depth;
    es.indentation.maxDepth = deepest;
    es.indentation.steps = std::max(4, std::min(10, static_cast<int>(c.depth.size())));
    es.indentation.unload = false;
    if (fc.pressure) es.pressure = *fc.pressure;
    Experiment e(tissue, es);
    monitor.say("Preparing the mesh for " + fc.data.name + "…");
    const auto site = e.prepareSite(es.mesh.level, monitor);
    c.mesh = site->mesh;
    c.complex = site->complex;
    c.level = site->level;
    c.slots[c.newest].turgid = site->indentation->turgidState();
    c.restSite = e.restSite();
    c.axis = e.axis();
    c.target = es.indentation.restSite ? std::nullopt : es.indentation.site;
  }

  Layout layout;
  std::vector<double> theta;
  std::vector<std::string> keys;
  auto add = [&](bool on, int& slot, double value, const std::string& key) {
    if (!on) return;
    slot = static_cast<int>(theta.size());
    theta.push_back(value);
    keys.push_back(key);
  };
  add(settings.fitE, layout.E, settings.start.material.youngModulus, "E");
  add(settings.fitP, layout.p, settings.start.pressure, "p");
  add(settings.fitH, layout.h, settings.start.material.thickness, "h");
  if (settings.fitOffset) {
    layout.offset0 = static_cast<int>(theta.size());
    for (size_t i = 0; i < curves.size(); ++i) {
      theta.push_back(0.0);
      keys.push_back("offset_" + std::to_string(i + 1));
    }
  }
  layout.n = static_cast<int>(theta.size());

  Problem problem(settings, models, layout, monitor);
  const int m = problem.residualCount();
  if (m < layout.n)
    throw std::invalid_argument("fewer measured points (" + std::to_string(m) +
                                ") than values to fit (" + std::to_string(layout.n) + ")");
  // E factored out when E and p are both fitted and no curve holds a turgor other than 0.
  bool scaled = settings.factorOutModulus && settings.fitE && settings.fitP;
  std::vector<double> measured;
  for (size_t i = 0; i < curves.size(); ++i) {
    scaled = scaled && curves[i].pressure.value_or(0.0) == 0.0;
    measured.insert(measured.end(), models[i].force.begin(), models[i].force.end());
  }
  std::optional<ScaledProblem> sp;
  std::vector<double> phi;  // the parameters searched: θ, or φ when E is factored out
  if (scaled) {
    sp.emplace(problem, layout, theta[layout.E], measured);
    phi = sp->reduced(theta);
  } else {
    phi = theta;
  }
  std::vector<double> r0;
  monitor.say("Simulating the curves at the starting values…");
  if (!problem.simulate(scaled ? sp->simulated(phi.data()).data() : theta.data(), r0, nullptr)) {
    if (problem.cancelled() || monitor.cancelled()) throw Cancelled();
    throw SolveFailure("at the starting values: " + problem.message());
  }
  auto rmsOf = [](const std::vector<double>& r) {
    double s = 0;
    for (double x : r) s += x * x;
    return r.empty() ? 0.0 : std::sqrt(s / r.size());
  };
  result.rmsStart = rmsOf(r0);

  // The residuals and Jacobian of the last point Ceres asked a Jacobian at: the point the
  // search stands at (a candidate step is asked for its residuals alone).
  Eigen::MatrixXd lastJ;
  Eigen::VectorXd lastR, lastX;
  Cost::Evaluate_ evaluate = [&](const double* x, std::vector<double>& r, Eigen::MatrixXd* J) {
    const bool ok = scaled ? sp->evaluate(x, r, J) : problem.simulate(x, r, J);
    if (ok && J) {
      lastJ = *J;
      lastR = Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
      lastX = Eigen::Map<const Eigen::VectorXd>(x, J->cols());
    }
    return ok;
  };
  const int searched = static_cast<int>(phi.size());
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = settings.maxIterations;
  // Converged when a step changes the cost by less than 1e-4/(m − n) of it: a hundredth of a
  // standard error. Near the minimum C = C_min + ½ Δθᵀ JᵀJ Δθ, and with cov = σ² (JᵀJ)⁻¹,
  // σ² = 2 C_min/(m − n), a point f standard errors away costs f² C_min/(m − n) more. The
  // equilibria (to 1e-10 of the load scale) make the cost noisy well above 1e-8 of it when the
  // curve is fitted closely (on a 25-point curve fitted to 1e-3 of its force, Ceres went on
  // for twelve iterations of rejected steps at 3.288881e-4 until the parameter tolerance). A
  // curve the model fits exactly still converges on the parameters: its cost falls by orders of
  // magnitude per step down to the noise.
  options.function_tolerance = 1e-4 / std::max(1, m - layout.n);
  options.gradient_tolerance = 1e-14;
  // And when a step would move the parameters by less than 1e-6 of themselves: the simulated
  // forces (equilibria to 1e-10 of the load scale) are known to ~1e-8 of the largest, so a
  // curve fitted exactly (synthetic) has its minimum blurred below that, and a millionth of
  // E or p is far inside any interval a measured curve gives. On BM_FitSpeed's exact curve the
  // steps went 6e-4, 2.5e-7 (rejected by the noise), 2.5e-7 (accepted) of p/E with 1e-10: a
  // simulation more.
  options.parameter_tolerance = 1e-6;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  options.num_threads = 1;
  // No projected line search after each step (Ceres runs one under parameter bounds, a third of
  // all the simulations of a fit): a step that leaves the bounds is projected onto them, one
  // that fails to lower the cost shrinks the trust region, as without bounds.
  options.max_num_line_search_step_size_iterations = 0;
  // Converged, too, when the Gauss–Newton step from where the search stands would lower the
  // cost by less than the function tolerance (a hundredth of a standard error, as above): the
  // model's own distance to the minimum (½‖J δ‖², δ the least-squares step; Dennis & Schnabel,
  // "Numerical Methods for Unconstrained Optimization and Nonlinear Equations", 1983, §7.2).
  // Ceres' function tolerance sees only accepted steps, and on a curve fitted to its own noise
  // (a synthetic one: the cost ~1e-5 µN², noisy at ~1e-5 of itself from the equilibria's 1e-10)
  // every step at the minimum was rejected by that noise, twelve of them, until the parameter
  // tolerance (BM_FitSpeed: 16 simulations where 5 had found the values).
  const double tolerance = options.function_tolerance;
  std::string stoppedBecause;  // which of the two tests below ended the last search
  const auto atMinimum = [&] {
    if (lastJ.size() == 0 || lastJ.rows() != lastR.size()) return false;
    const Eigen::VectorXd step = lastJ.colPivHouseholderQr().solve(lastR);
    const double decrease = 0.5 * (lastJ * step).squaredNorm();
    if (!std::isfinite(decrease)) return false;
    // Or when that step is shorter than the parameter tolerance (Ceres' own test, ‖Δφ‖ ≤
    // ε (‖φ‖ + ε)): the step Ceres would try next, no longer than it, would end the search by
    // that tolerance after a simulation of the candidate whose result it discards. On an exact
    // curve (BM_FitSpeed) the cost at the minimum is the equilibria's noise, which the decrease
    // test above cannot beat: there this is what ends the search, one simulation sooner.
    const double eps = options.parameter_tolerance;
    if (decrease <= tolerance * 0.5 * lastR.squaredNorm()) {
      stoppedBecause = "the Gauss-Newton step would lower the cost by less than " +
                       fixed(tolerance, 3) + " of it";
      return true;
    }
    if (lastX.size() == step.size() && step.norm() <= eps * (lastX.norm() + eps)) {
      stoppedBecause = "the Gauss-Newton step is shorter than " + fixed(eps, 3) +
                       " of the parameters";
      return true;
    }
    return false;
  };
  struct Progress : ceres::IterationCallback {
    const Monitor& monitor;
    std::function<bool()> atMinimum;
    double cost = 0;  // at the point the search stands at
    int done = 0;     // iterations of the searches before this one
    Progress(const Monitor& m, std::function<bool()> f) : monitor(m), atMinimum(std::move(f)) {}
    ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
      // Ceres reports a rejected step with the cost of the point it tried, not of the point it
      // stays at: said as such, so that the cost a user follows never seems to rise.
      const bool moved = s.step_is_successful || s.iteration == 0;
      if (moved) cost = s.cost;
      monitor.say("Fit iteration " + std::to_string(done + s.iteration) + ": cost " +
                  fixed(cost, 6) +
                  (moved ? "" : " (a step to " + fixed(s.cost, 6) + " rejected)"));
      if (monitor.cancelled()) return ceres::SOLVER_ABORT;
      return atMinimum() ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
    }
  } progress(monitor, atMinimum);
  options.callbacks.push_back(&progress);
  ceres::Solver::Summary summary;
  // The search, from φ as it stands; with the automatic mesh, checked at the values found and
  // run again from them on the meshes they need, until every curve's mesh is the one the
  // automatic refinement chooses at the fitted values. The mesh error that matters is the one
  // at the answer, not at the starting values (30 % off in BM_FitSpeed, where they chose level
  // 4 against level 3 at the answer: 139 s against 37.5–45 s, bench/README.md); and the mesh
  // starts at the automatic mesh's first level, so no finer level than the answer needs is
  // solved.
  for (;;) {
    ceres::Problem cp;
    cp.AddResidualBlock(new Cost(evaluate, m, searched), nullptr, phi.data());  // owned by cp
    // The bounds, at the positions of E, p (q when scaled: p/E ≥ 0 too) and h in the search.
    const int shift = scaled ? 1 : 0;
    if (layout.E >= 0 && !scaled) cp.SetParameterLowerBound(phi.data(), layout.E, 1e-3);
    if (layout.p >= 0) cp.SetParameterLowerBound(phi.data(), layout.p - shift, 0.0);
    if (layout.h >= 0) cp.SetParameterLowerBound(phi.data(), layout.h - shift, 1e-3);
    monitor.say("Fitting…");
    ceres::Solve(options, &cp, &summary);
    if (problem.cancelled() || monitor.cancelled()) throw Cancelled();
    result.iterations += static_cast<int>(summary.iterations.size());
    progress.done += static_cast<int>(summary.iterations.size());
    if (!automatic || !converged(summary)) break;
    // The fitted values (a θ just simulated: answered from the curves' slots, and made the
    // newest of each curve's two).
    std::vector<double> rs, fitted = phi;
    if (!(scaled ? sp->evaluate(phi.data(), rs, nullptr, &fitted)
                 : problem.simulate(phi.data(), rs, nullptr)))
      break;  // reported below
    bool refined = false;
    for (size_t i = 0; i < models.size(); ++i) {
      CurveModel& c = models[i];
      const CurveEvaluation& at = c.slots[c.newest];
      if (!(at.endDepth > 0)) continue;  // the offset took every point off the tissue
      // The mesh error at the fitted values, from the next finer level started from this
      // curve's state at its deepest point; then, if that is not within the tolerance, the
      // automatic mesh from the next level on. With E factored out the curve was simulated at
      // (E_s, q E_s): the same states, every force E/E_s times (the energy is homogeneous).
      const double scale =
          layout.E >= 0 ? fitted[layout.E] / at.key[0] : 1.0;  // 1 unless E was factored out
      ExperimentSettings es = setups[i];
      es.material.youngModulus = scale * at.key[0];
      es.pressure = scale * at.key[1];
      es.material.thickness = at.key[2];
      es.indentation.maxDepth = at.endDepth;
      es.indentation.site.reset();  // the material point and axis the mesh was refined at
      es.indentation.restSite = c.restSite;
      es.indentation.axis = c.axis;
      Experiment e(tissue, es);  // the automatic mesh's first level: curveError judges a finer
                                 // one from the level before first, as Experiment::run does
      e.setKeepEstimatedSite(true);  // the next level's site, if the search must go on there
      monitor.say("Checking the mesh of " + curves[i].data.name + " at the fitted values…");
      const Seed seed{c.mesh, at.turgid, at.states.back(), at.endDepth};
      c.error = e.curveError(c.level, scale * at.nodeForce.back(), monitor, &seed);
      if (c.error.estimated() && c.error.relative <= es.mesh.tolerance) continue;
      if (c.level >= es.mesh.maxLevel) continue;  // reported with its error
      es.mesh.level = c.level + 1;
      e.setSettings(es);
      ExperimentResult r = e.run(monitor);
      if (r.cancelled) throw Cancelled();
      if (!r.complete || !r.site)
        throw SolveFailure(curves[i].data.name + " at the fitted values: " + r.message);
      c.error = r.error;
      c.mesh = r.site->mesh;
      c.complex = r.site->complex;
      c.level = r.site->level;
      for (CurveEvaluation& slot : c.slots) slot = CurveEvaluation();
      c.newest = 1;
      c.slots[c.newest].turgid = r.site->indentation->turgidState();
      refined = true;
    }
    if (!refined) break;
    monitor.say("Fitting again on the finer meshes the fitted values need…");
  }
  if (summary.termination_type == ceres::USER_SUCCESS) {  // only atMinimum() says so
    std::string brief = summary.BriefReport();
    const auto at = brief.find("USER_SUCCESS");
    if (at != std::string::npos) brief.replace(at, 12, "CONVERGENCE");
    result.message = brief + " (" + stoppedBecause + ")";
  } else {
    result.message = summary.BriefReport() + " (" + summary.message + ")";
  }
  result.converged = converged(summary);

  // The Jacobian and residuals at the fit: standard errors and correlations.
  std::vector<double> r;
  Eigen::MatrixXd J;
  bool simulated = false;
  if (scaled) {
    simulated = sp->evaluate(phi.data(), r, nullptr, &theta, &J);
  } else {
    theta = phi;
    simulated = problem.simulate(theta.data(), r, &J);
  }
  if (!simulated) {
    result.converged = false;
    result.message += "; the fitted values cannot be simulated: " + problem.message();
    return result;
  }
  result.evaluations = problem.evaluations();
  result.rms = rmsOf(r);
  const int n = layout.n;
  Eigen::VectorXd scale(n);
  for (int j = 0; j < n; ++j) scale[j] = J.col(j).norm() > 0 ? 1.0 / J.col(j).norm() : 1.0;
  const Eigen::MatrixXd Js = J * scale.asDiagonal();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Js, Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  const double cond = sv.size() && sv.minCoeff() > 0 ? sv.maxCoeff() / sv.minCoeff()
                                                     : std::numeric_limits<double>::infinity();
  double rss = 0;
  for (double x : r) rss += x * x;
  const double sigma2 = m > n ? rss / (m - n) : 0.0;
  Eigen::MatrixXd cov = Eigen::MatrixXd::Constant(n, n, std::numeric_limits<double>::infinity());
  if (std::isfinite(cond) && cond < 1e10) {
    const Eigen::MatrixXd V = svd.matrixV();
    const Eigen::VectorXd inv2 = sv.array().square().inverse();
    cov = sigma2 * scale.asDiagonal() * V * inv2.asDiagonal() * V.transpose() * scale.asDiagonal();
  }
  result.fittedKeys = keys;
  result.correlation = Eigen::MatrixXd::Identity(n, n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      if (a != b)
        result.correlation(a, b) = std::isfinite(cov(a, b))
                                       ? cov(a, b) / std::sqrt(cov(a, a) * cov(b, b))
                                       : std::numeric_limits<double>::quiet_NaN();

  auto value = [&](const std::string& key, const std::string& unit, int slot, double held) {
    FitValue v;
    v.key = key;
    v.unit = unit;
    v.fitted = slot >= 0;
    v.value = slot >= 0 ? theta[slot] : held;
    v.error = slot >= 0 ? std::sqrt(cov(slot, slot)) : 0.0;
    result.values.push_back(v);
  };
  value("E", "MPa", layout.E, settings.start.material.youngModulus);
  value("p", "MPa", layout.p, settings.start.pressure);
  value("h", "um", layout.h, settings.start.material.thickness);
  if (layout.offset0 >= 0)
    for (size_t i = 0; i < curves.size(); ++i)
      value("offset_" + std::to_string(i + 1), "um", layout.offset0 + static_cast<int>(i), 0.0);

  // Can the values be told apart? A value known to no better than half of itself, or E and p
  // correlated beyond 0.95, is not determined by these curves.
  std::ostringstream advice;
  for (const FitValue& v : result.values) {
    if (!v.fitted || v.key.rfind("offset", 0) == 0) continue;
    if (!std::isfinite(v.error) || v.error > 0.5 * std::abs(v.value)) {
      result.identifiable = false;
      advice << v.key << " is not determined by these curves (" << fixed(v.value, 4) << " ± "
             << fixed(v.error, 2) << " " << v.unit << "). ";
    }
  }
  if (layout.E >= 0 && layout.p >= 0) {
    const double rho = result.correlation(layout.E, layout.p);
    if (!(std::abs(rho) <= 0.95)) {
      result.identifiable = false;
      advice << "E and p cannot be told apart from these curves (correlation " << fixed(rho, 3)
             << "): a stiffer wall and a higher turgor give nearly the same "
             << "curve. ";
    }
  }
  if (!result.identifiable)
    advice << "To separate them: indent deeper (turgor stiffens the curve linearly, the walls' "
              "bending and stretching add curvature), add a curve at a second site (next to an "
              "anticlinal wall as well as in the middle of an outer wall), or add a plasmolysed "
              "curve of the same site (--curve FILE with p held at 0), which sees E without p.";
  result.advice = advice.str();

  // The curves as used, the simulated forces at the fit, and the Hertz reading of each.
  int row = 0;
  for (size_t i = 0; i < models.size(); ++i) {
    FitResult::Curve out;
    out.depth = models[i].depth;
    out.measured = models[i].force;
    for (size_t k = 0; k < out.depth.size(); ++k, ++row)
      out.simulated.push_back(r[row] + out.measured[k]);
    std::vector<CurvePoint> pts;
    for (size_t k = 0; k < out.depth.size(); ++k)
      pts.push_back(CurvePoint{out.depth[k], out.measured[k], 0, 0.0, true, false});
    out.hertzModulus = hertzApparentModulus(pts, settings.start.indentation.probeRadius,
                                            settings.start.material.poissonRatio);
    const CurveModel& c = models[i];
    out.simulatedDepths = static_cast<int>(c.slots[c.newest].nodes.size());
    out.meshLevel = models[i].level;
    out.meshError = models[i].error;
    result.curves.push_back(std::move(out));
  }
  return result;
}

}  // namespace tp
