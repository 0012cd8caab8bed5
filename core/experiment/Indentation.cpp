#include "experiment/Indentation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace tp {

namespace {

bool fullyClamped(const CellComplex& cc, int t) {
  const auto& tri = cc.triangles[t];
  return cc.fixed[tri[0]] && cc.fixed[tri[1]] && cc.fixed[tri[2]];
}

double surfaceDistance(const Model& model, const Points& x, const Vec3& p) {
  const CellComplex& cc = model.complex();
  double best = std::numeric_limits<double>::infinity();
  for (int t : model.topology().outerTriangles) {
    const auto& tri = cc.triangles[t];
    best = std::min(best, pointTriangleDistance2(p, x.col(tri[0]), x.col(tri[1]), x.col(tri[2]),
                                                 nullptr, nullptr, nullptr));
  }
  return std::sqrt(best);
}

}  // namespace

Vec3 nearestSurfacePoint(const Model& model, const Points& x, const Vec3& target, int* triangle) {
  const CellComplex& cc = model.complex();
  double best = std::numeric_limits<double>::infinity();
  Vec3 bestPoint = target;
  int bestTri = -1;
  for (int t : model.topology().outerTriangles) {
    if (fullyClamped(cc, t)) continue;
    const auto& tri = cc.triangles[t];
    Vec3 y;
    const double d2 = pointTriangleDistance2(target, x.col(tri[0]), x.col(tri[1]), x.col(tri[2]),
                                             nullptr, nullptr, nullptr, &y);
    if (d2 < best) {
      best = d2;
      bestPoint = y;
      bestTri = t;
    }
  }
  if (bestTri < 0) throw std::runtime_error("the tissue has no free outer surface to indent");
  if (triangle) *triangle = bestTri;
  return bestPoint;
}

Vec3 topSurfacePoint(const Model& model, const Points& x, int* triangle) {
  // The highest point of the outer surface on the vertical through the surface's area-weighted
  // centre: the apex of a dome, usually inside a wall rather than on a cell junction.
  const CellComplex& cc = model.complex();
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double area = 0;
  for (int t : model.topology().outerTriangles) {
    if (fullyClamped(cc, t)) continue;
    const auto& tri = cc.triangles[t];
    const double a =
        0.5 * (x.col(tri[1]) - x.col(tri[0])).cross(x.col(tri[2]) - x.col(tri[0])).norm();
    centre += a * (x.col(tri[0]) + x.col(tri[1]) + x.col(tri[2])).head<2>() / 3.0;
    area += a;
  }
  if (!(area > 0)) throw std::runtime_error("the tissue has no free outer surface to indent");
  centre /= area;
  double bestZ = -std::numeric_limits<double>::infinity();
  int bestTri = -1;
  for (int t : model.topology().outerTriangles) {
    if (fullyClamped(cc, t)) continue;
    const auto& tri = cc.triangles[t];
    const Eigen::Vector2d a = x.col(tri[0]).head<2>(), b = x.col(tri[1]).head<2>(),
                          c = x.col(tri[2]).head<2>();
    const double det = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (std::abs(det) < 1e-300) continue;
    const Eigen::Vector2d q = centre - a;
    const double u = (q.x() * (c - a).y() - q.y() * (c - a).x()) / det;
    const double v = ((b - a).x() * q.y() - (b - a).y() * q.x()) / det;
    if (u < 0 || v < 0 || u + v > 1) continue;
    const double z = (1 - u - v) * x(2, tri[0]) + u * x(2, tri[1]) + v * x(2, tri[2]);
    if (z > bestZ) bestZ = z, bestTri = t;
  }
  if (bestTri < 0) {  // the vertical misses the surface: take the highest vertex
    int bestV = -1;
    for (int t : model.topology().outerTriangles)
      for (int k = 0; k < 3; ++k) {
        const int v = cc.triangles[t][k];
        if (!cc.fixed[v] && (bestV < 0 || x(2, v) > x(2, bestV))) bestV = v;
      }
    if (bestV < 0) throw std::runtime_error("the tissue has no free outer surface to indent");
    return nearestSurfacePoint(model, x, x.col(bestV), triangle);
  }
  if (triangle) *triangle = bestTri;
  return Vec3(centre.x(), centre.y(), bestZ);
}

Vec3 inwardNormal(const Model& model, const Points& x, const Vec3& site, int triangle,
                  double radius) {
  const CellComplex& cc = model.complex();
  Vec3 n = Vec3::Zero();
  for (int t : model.topology().outerTriangles) {
    const auto& tri = cc.triangles[t];
    const Vec3 a = x.col(tri[0]), b = x.col(tri[1]), c = x.col(tri[2]);
    if (t != triangle &&
        pointTriangleDistance2(site, a, b, c, nullptr, nullptr, nullptr) > radius * radius)
      continue;
    n += 0.5 * (b - a).cross(c - a);  // outward, area-weighted
  }
  if (n.norm() == 0) throw std::runtime_error("cannot compute a surface normal at the site");
  return -n.normalized();
}

Vec3 firstContactCenter(const Model& model, const Points& x, const Vec3& site, const Vec3& axis,
                        double radius) {
  const double tol = 1e-10 * std::max(radius, model.meanEdgeLength());
  Vec3 p = site - radius * axis;
  // Back off while the sphere overlaps the surface somewhere (a concave site).
  double gap = surfaceDistance(model, x, p) - radius;
  for (int i = 0; i < 200 && gap < -tol; ++i) {
    p -= (radius + std::abs(gap)) * axis;
    gap = surfaceDistance(model, x, p) - radius;
  }
  if (gap < -tol) throw std::runtime_error("cannot place the probe outside the tissue");
  // Sphere tracing forward: the distance is 1-Lipschitz, so a step of `gap` never penetrates.
  for (int i = 0; i < 10000 && gap > tol; ++i) {
    p += gap * axis;
    gap = surfaceDistance(model, x, p) - radius;
    if (gap > 1e6 * radius) throw std::runtime_error("the probe axis misses the tissue");
  }
  return p;
}

Vec3 restPositionOf(const Model& model, const Points& x, const Vec3& site, int triangle) {
  const CellComplex& cc = model.complex();
  if (triangle < 0 || triangle >= cc.triangleCount())
    throw std::invalid_argument("restPositionOf: no triangle");
  const auto& t = cc.triangles[triangle];
  const Vec3 a = x.col(t[0]), b = x.col(t[1]), c = x.col(t[2]);
  const Vec3 n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (!(n2 > 0)) return cc.rest.col(t[0]);
  const double wa = (c - b).cross(site - b).dot(n) / n2;
  const double wb = (a - c).cross(site - c).dot(n) / n2;
  const double wc = 1.0 - wa - wb;
  return wa * cc.rest.col(t[0]) + wb * cc.rest.col(t[1]) + wc * cc.rest.col(t[2]);
}

Indentation::Indentation(Model& model, IndentationSettings settings, SolverOptions solverOptions)
    : model_(model), settings_(std::move(settings)), solver_(makeSolver(model, solverOptions)) {
  if (!(settings_.probeRadius > 0))
    throw std::invalid_argument("probe radius must be positive (got " +
                                std::to_string(settings_.probeRadius) + " µm)");
  if (settings_.steps < 1) throw std::invalid_argument("steps must be at least 1");
}

SolveReport Indentation::prepare(const Points* start) {
  prepared_ = false;
  model_.clearProbe();
  const std::vector<double> pressures = model_.cellPressures();
  Points x = model_.complex().rest;
  // Turgid rest state, by continuation in the pressure when one step is too much.
  SolveReport rep;
  double reached = 0, step = 1.0;
  if (start && start->cols() == x.cols() && start->allFinite()) {
    Points guess = *start;
    rep = solver_->solve(guess);
    if (rep.converged) {
      x = guess;
      reached = 1.0;
    }
  }
  int level = 0;
  bool anyPressure = std::any_of(pressures.begin(), pressures.end(), [](double p) { return p != 0; });
  if (!anyPressure && reached < 1.0) {
    rep = solver_->solve(x);
    reached = 1.0;
  }
  while (reached < 1.0) {
    const double next = std::min(1.0, reached + step);
    std::vector<double> scaled(pressures);
    for (double& p : scaled) p *= next;
    model_.setCellPressures(scaled);
    rep = solver_->solve(x);
    if (rep.converged) {
      reached = next;
    } else if (level < settings_.maxSubdivisions + 3) {
      step *= 0.5;
      ++level;
    } else {
      model_.setCellPressures(pressures);
      message_ = "the turgid state did not converge: " + rep.message;
      return rep;
    }
  }
  model_.setCellPressures(pressures);
  if (!rep.converged) {
    message_ = "the rest state did not converge: " + rep.message;
    return rep;
  }
  turgid_ = x;
  x_ = x;

  // Site, axis and first contact on the turgid state.
  ProbePlacement& pl = placement_;
  if (settings_.restSite) {
    const Points& X = model_.complex().rest;
    int t = -1;
    const Vec3 onRest = nearestSurfacePoint(model_, X, *settings_.restSite, &t);
    const auto& tri = model_.complex().triangles[t];
    const Vec3 a = X.col(tri[0]), b = X.col(tri[1]), c = X.col(tri[2]);
    const Vec3 nrm = (b - a).cross(c - a);
    const double n2 = std::max(nrm.squaredNorm(), 1e-300);
    const double wa = (c - b).cross(onRest - b).dot(nrm) / n2;
    const double wb = (a - c).cross(onRest - c).dot(nrm) / n2;
    pl.site = wa * x.col(tri[0]) + wb * x.col(tri[1]) + (1 - wa - wb) * x.col(tri[2]);
    pl.triangle = t;
  } else {
    pl.site = settings_.site ? nearestSurfacePoint(model_, x, *settings_.site, &pl.triangle)
                             : topSurfacePoint(model_, x, &pl.triangle);
  }
  if (settings_.axis) {
    if (!(settings_.axis->norm() > 0) || !settings_.axis->allFinite())
      throw std::invalid_argument("the probe axis must be a non-zero vector");
    pl.axis = settings_.axis->normalized();
  } else {
    pl.axis = inwardNormal(model_, x, pl.site, pl.triangle, settings_.probeRadius);
  }
  pl.contactCenter = firstContactCenter(model_, x, pl.site, pl.axis, settings_.probeRadius);
  ContactLaw law = model_.contactLaw();
  // A soft onset over a tenth of the probe radius: triangles entering the contact patch one by
  // one on a fine mesh then change the tangent gradually (a fifth fewer Newton iterations than
  // 1e-3 R; the force moves by 0.1 %, far below the discretisation error).
  law.smoothing = 0.1 * settings_.probeRadius;
  model_.setContactLaw(law);
  model_.setProbe({pl.contactCenter, settings_.probeRadius});
  depth_ = load_ = 0;
  history_.clear();
  remember();
  forceMode_ = false;
  prepared_ = true;
  message_.clear();
  return rep;
}

void Indentation::returnToFirstContact() {
  if (!prepared_) throw std::logic_error("Indentation::prepare() must succeed first");
  x_ = turgid_;
  model_.setProbe({placement_.contactCenter, settings_.probeRadius});
  depth_ = load_ = 0;
  history_.clear();
  remember();
  forceMode_ = false;
  message_.clear();
}

double Indentation::probeForce() const {
  return placement_.axis.dot(solver_->lastEvaluation().probeGradient);
}

SolveReport Indentation::solveUnderForce(Points& x, double force, double& travel) {
  ForceControl fc;
  fc.origin = placement_.contactCenter;
  fc.axis = placement_.axis;
  fc.force = force;
  fc.travel = travel;
  const SolveReport rep = solver_->solve(x, &fc);
  travel = fc.travel;
  return rep;
}

bool Indentation::solveAt(double target, bool forceControl, int& iterations, double& residual) {
  // Predictor: the polynomial through the last (up to three) equilibria of this control with
  // distinct loads (unloading revisits loads), evaluated at the target (Lagrange), for the state
  // and the probe travel.
  std::vector<const Equilibrium*> pts;
  for (auto it = history_.rbegin(); it != history_.rend(); ++it) {
    bool seen = false;
    for (const Equilibrium* q : pts) seen = seen || q->load == it->load;
    if (!seen) pts.push_back(&*it);
  }
  std::vector<double> w(pts.size(), 1.0);
  for (size_t i = 0; i < pts.size(); ++i)
    for (size_t j = 0; j < pts.size(); ++j)
      if (j != i) w[i] *= (target - pts[j]->load) / (pts[i]->load - pts[j]->load);
  const bool canExtrapolate = settings_.predictor && pts.size() >= 2;
  // Without two earlier equilibria to extrapolate from (the first step into the tissue), the
  // tissue's linear response to a point load at the site, scaled to the probe's travel (or to
  // the force asked): the probe then starts against a dimple of about the right depth instead
  // of deep inside a flat surface, where a stiff contact term would throw Newton far off.
  const bool canRespond =
      settings_.predictor && !canExtrapolate && std::abs(target) > std::abs(load_);
  for (int attempt = canExtrapolate || canRespond ? 0 : 1; attempt < 2; ++attempt) {
    const bool predict = attempt == 0;
    Points x = x_;
    double travelGuess = depth_;
    if (predict && canRespond) {
      Eigen::VectorXd u;
      double along = 0;  // µm per µN at the site
      if (!siteResponse(u, along)) continue;
      const double scale = forceControl ? target - load_ : (target - depth_) / along;  // µN
      x = x_ + scale * Eigen::Map<const Points>(u.data(), 3, x_.cols());
      travelGuess = depth_ + scale * along;
      if (!x.allFinite()) continue;
    } else if (predict) {
      x.setZero();
      travelGuess = 0;
      for (size_t i = 0; i < pts.size(); ++i) {
        x += w[i] * pts[i]->x;
        travelGuess += w[i] * pts[i]->depth;
      }
      // The predictor must not move clamped components.
      const auto& fixed = model_.complex().fixed;
      for (int v = 0; v < x.cols(); ++v)
        if (fixed[v]) x.col(v) = x_.col(v);
    }
    SolveReport rep;
    double travel = depth_;
    if (forceControl) {
      // First the equilibrium at the predicted travel (displacement control is the robust
      // one: the probe cannot run ahead of the tissue), then the force from there.
      if (predict) {
        model_.setProbe({placement_.contactCenter + travelGuess * placement_.axis,
                         settings_.probeRadius});
        Points y = x;
        const SolveReport at = solver_->solve(y);
        iterations += at.iterations;
        if (at.converged) x = y;
      }
      travel = travelGuess;
      rep = solveUnderForce(x, target, travel);
    } else {
      model_.setProbe({placement_.contactCenter + target * placement_.axis, settings_.probeRadius});
      rep = solver_->solve(x);
      travel = target;
    }
    iterations += rep.iterations;
    residual = rep.relativeResidual();
    if (rep.converged && !forceControl && target > 0 && !(probeForce() > 0)) {
      // The probe is below the first contact and nothing pushes back: it has lost the surface
      // (through a wall, or off its side). Never a converged point.
      std::ostringstream why;
      why << "contact lost at depth " << target << " µm (no force on the probe)";
      rep.converged = false;
      rep.message = why.str();
    }
    if (rep.converged) {
      x_ = x;
      depth_ = travel;
      load_ = target;
      remember();
      return true;
    }
    message_ = rep.message;
  }
  // Leave the probe where the last equilibrium has it.
  model_.setProbe({placement_.contactCenter + depth_ * placement_.axis, settings_.probeRadius});
  return false;
}

bool Indentation::siteResponse(Eigen::VectorXd& u, double& along) {
  const CellComplex& cc = model_.complex();
  const auto& tri = cc.triangles[placement_.triangle];
  // Barycentric weights, in its turgid triangle, of the point the probe is on now.
  const Vec3 a = x_.col(tri[0]), b = x_.col(tri[1]), c = x_.col(tri[2]);
  const Vec3 n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (!(n2 > 0)) return false;
  const Vec3 p = placement_.contactCenter + (depth_ + settings_.probeRadius) * placement_.axis;
  Vec3 w((c - b).cross(p - b).dot(n) / n2, (a - c).cross(p - c).dot(n) / n2, 0.0);
  w[2] = 1.0 - w[0] - w[1];
  w = w.cwiseMax(0.0);
  if (!(w.sum() > 0)) return false;
  w /= w.sum();
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * cc.vertexCount());
  for (int k = 0; k < 3; ++k) f.segment<3>(3 * tri[k]) = w[k] * placement_.axis;
  if (!solver_->tangentSolve(x_, f, u)) return false;
  along = 0;
  for (int k = 0; k < 3; ++k) along += w[k] * placement_.axis.dot(u.segment<3>(3 * tri[k]));
  return along > 0 && std::isfinite(along);
}

void Indentation::remember() {
  history_.push_back({load_, depth_, x_});
  while (history_.size() > 3) history_.pop_front();
}

CurvePoint Indentation::advance(double target, bool forceControl) {
  if (!prepared_) throw std::logic_error("Indentation::prepare() must succeed first");
  if (forceControl != forceMode_) {  // switching control: restate the load in the new terms
    load_ = forceControl ? probeForce() : depth_;
    history_.clear();
    remember();
    forceMode_ = forceControl;
  }
  CurvePoint pt;
  pt.unloading = std::abs(target) < std::abs(load_);
  double step = target - load_;
  int level = 0;
  while (load_ != target) {
    const double next = std::abs(target - load_) <= std::abs(step) ? target : load_ + step;
    if (solveAt(next, forceControl, pt.iterations, pt.residual)) continue;
    if (level >= settings_.maxSubdivisions) {
      std::ostringstream s;
      s << "no equilibrium at " << (forceControl ? "force " : "depth ") << next
        << (forceControl ? " µN" : " µm") << " after " << level << " step halvings: " << message_;
      message_ = s.str();
      pt.converged = false;
      pt.depth = forceControl ? depth_ : target;
      pt.force = std::numeric_limits<double>::quiet_NaN();
      return pt;
    }
    step *= 0.5;
    ++level;
  }
  pt.converged = true;
  pt.depth = depth_;
  pt.force = probeForce();
  return pt;
}

CurvePoint Indentation::goToDepth(double depth) {
  if (!std::isfinite(depth)) throw std::invalid_argument("depth must be finite");
  return advance(depth, false);
}

CurvePoint Indentation::solveFrom(double target, bool forceControl, Points guess,
                                  double travel) {
  if (!prepared_) throw std::logic_error("Indentation::prepare() must succeed first");
  if (!std::isfinite(target) || !std::isfinite(travel) || guess.cols() != x_.cols() ||
      !guess.allFinite())
    throw std::invalid_argument("solveFrom: a finite target and a guess of this tissue's size");
  const auto& fixed = model_.complex().fixed;
  for (int v = 0; v < guess.cols(); ++v)
    if (fixed[v]) guess.col(v) = x_.col(v);
  if (!forceControl) travel = target;
  // Displacement control at the travel guessed, then (force control) the force from there.
  model_.setProbe({placement_.contactCenter + travel * placement_.axis, settings_.probeRadius});
  SolveReport rep = solver_->solve(guess);
  int iterations = rep.iterations;
  if (rep.converged && forceControl) {
    rep = solveUnderForce(guess, target, travel);
    iterations += rep.iterations;
  }
  if (rep.converged && !forceControl && target > 0 && !(probeForce() > 0)) {
    rep.converged = false;
    rep.message = "contact lost at depth " + std::to_string(target) + " µm (no force on the probe)";
  }
  if (!rep.converged) {  // the guess was not good enough: nothing changes
    model_.setProbe({placement_.contactCenter + depth_ * placement_.axis, settings_.probeRadius});
    message_ = rep.message;
    CurvePoint failed;
    failed.iterations = iterations;
    failed.residual = rep.relativeResidual();
    failed.depth = forceControl ? depth_ : target;
    failed.force = std::numeric_limits<double>::quiet_NaN();
    return failed;
  }
  x_ = guess;
  depth_ = travel;
  load_ = target;
  forceMode_ = forceControl;
  history_.clear();
  remember();
  CurvePoint pt;
  pt.converged = true;
  pt.depth = depth_;
  pt.force = probeForce();
  pt.iterations = iterations;
  pt.residual = rep.relativeResidual();
  return pt;
}

CurvePoint Indentation::applyForce(double force) {
  if (!std::isfinite(force)) throw std::invalid_argument("force must be finite");
  return advance(force, true);
}

void Indentation::setSchedule(const IndentationSettings& s) {
  if (s.steps < 1) throw std::invalid_argument("steps must be at least 1");
  settings_.control = s.control;
  settings_.maxDepth = s.maxDepth;
  settings_.maxForce = s.maxForce;
  settings_.steps = s.steps;
  settings_.unload = s.unload;
}

std::vector<double> scheduleTargets(const IndentationSettings& settings) {
  std::vector<double> targets;
  const double top = settings.control == Control::Force ? settings.maxForce : settings.maxDepth;
  for (int k = 1; k <= settings.steps; ++k) targets.push_back(top * k / settings.steps);
  if (settings.unload)
    for (int k = settings.steps - 1; k >= 0; --k) targets.push_back(top * k / settings.steps);
  return targets;
}

std::vector<CurvePoint> Indentation::run(const PointCallback& onPoint,
                                         const std::atomic<bool>* cancel) {
  const std::vector<double> schedule = scheduleTargets(settings_);
  const bool force = settings_.control == Control::Force;
  solver_->setCancelFlag(cancel);
  struct Reset {
    EquilibriumSolver& s;
    ~Reset() { s.setCancelFlag(nullptr); }
  } reset{*solver_};
  std::vector<CurvePoint> curve;
  if (depth_ != 0.0 || forceMode_) {  // back to first contact (a drag may have left it pressed)
    const CurvePoint start = goToDepth(0.0);
    if (!start.converged) return curve;
  }
  curve.push_back(CurvePoint{0.0, 0.0, 0, 0.0, true, false});
  for (size_t i = 0; i < schedule.size(); ++i) {
    if (cancel && cancel->load()) break;
    CurvePoint pt = force ? applyForce(schedule[i]) : goToDepth(schedule[i]);
    pt.unloading = settings_.unload && i >= static_cast<size_t>(settings_.steps);
    if (!pt.converged && cancel && cancel->load()) break;  // cancelled mid-solve: not a point
    curve.push_back(pt);
    if (onPoint) onPoint(pt, static_cast<int>(i + 1), static_cast<int>(schedule.size()));
    if (!pt.converged) break;
  }
  return curve;
}

}  // namespace tp
