#include "experiment/Sensitivity.h"

#include <cmath>

namespace tp {

namespace {

// −∂g/∂E, −∂g/∂p, −∂g/∂h at x (3V each), from the terms evaluated alone.
Eigen::MatrixXd parameterLoads(Model& model, const Points& x) {
  const int n3 = static_cast<int>(x.size());
  Eigen::VectorXd gMembrane = Eigen::VectorXd::Zero(n3), gBending = Eigen::VectorXd::Zero(n3),
                  gContact = Eigen::VectorXd::Zero(n3), dVdx = Eigen::VectorXd::Zero(n3);
  Evaluation ev;
  const auto& terms = model.terms();
  for (int t = 0; t < static_cast<int>(terms.size()); ++t) {
    const EnergyPart part = terms[t]->part();
    if (part == EnergyPart::Membrane || part == EnergyPart::Bending ||
        part == EnergyPart::Contact) {
      model.evaluate(x, ev, EvalOptions{.hessian = false, .onlyTerm = t});
      (part == EnergyPart::Membrane  ? gMembrane
       : part == EnergyPart::Bending ? gBending
                                     : gContact) += ev.gradient;
    }
  }
  // −∂V/∂x: the turgor term's gradient at unit pressure.
  const std::vector<double> pressures = model.cellPressures();
  model.setUniformPressure(1.0);
  for (int t = 0; t < static_cast<int>(terms.size()); ++t)
    if (terms[t]->part() == EnergyPart::Pressure) {
      model.evaluate(x, ev, EvalOptions{.hessian = false, .onlyTerm = t});
      dVdx += ev.gradient;
    }
  model.setCellPressures(pressures);
  const Material& mat = model.material();
  Eigen::MatrixXd loads(n3, 3);
  loads.col(0) = -(gMembrane + gBending + gContact) / mat.youngModulus;
  loads.col(1) = -dVdx;
  loads.col(2) = -(gMembrane + 3.0 * gBending + gContact) / mat.thickness;
  return loads;
}

}  // namespace

TurgidResponse turgidResponse(Indentation& ind) {
  TurgidResponse r;
  Model& model = ind.model();
  const std::optional<Probe> probe = model.probe();
  model.clearProbe();
  r.ok = ind.solver().tangentSolve(ind.turgidState(),
                                   parameterLoads(model, ind.turgidState()), r.u);
  if (probe) model.setProbe(*probe);
  return r;
}

ForceSensitivity forceSensitivity(Indentation& ind, const TurgidResponse* turgid) {
  ForceSensitivity s;
  Model& model = ind.model();
  const Points& x = ind.state();
  const Vec3 axis = ind.placement().axis;
  const int n3 = static_cast<int>(x.size());
  if (!model.probe()) return s;

  // At the indented state, with the probe's centre c held, by the adjoint of the force
  // (e.g. Giles & Pierce, "An introduction to the adjoint approach to design", 2000): with
  // B = ∂²W/∂x∂c (the probe's coupling, from the assembly that builds the tangent K) the force
  // changes by dF = (B a)·dx + a·∂²W/∂c² dc + its explicit part, and K dx = L dθ − B dc with
  // L = −∂g/∂θ. One solve K w = B a (K symmetric) gives every derivative: dF/dθ_k = w·L_k
  // (+ explicit), dF/dc = a·∂²W/∂c² − Bᵀw — one right-hand side per point instead of six.
  Eigen::MatrixXd probeCoupling;
  Vec3 probeGradient = Vec3::Zero();
  Mat3 probeHessian = Mat3::Zero();
  auto loadsAt = [&](const Evaluation& ev) -> Eigen::MatrixXd {
    if (ev.probeCoupling.rows() != n3) return {};
    probeCoupling = ev.probeCoupling;
    probeGradient = ev.probeGradient;
    probeHessian = ev.probeHessian;
    return Eigen::MatrixXd(ev.probeCoupling * axis);  // ∂F/∂x, F = a·∂W/∂c
  };
  Eigen::MatrixXd solution;
  if (!ind.solver().tangentSolve(x, loadsAt, solution)) return s;
  const Eigen::VectorXd adjoint = solution.col(0);  // K⁻¹ B a
  const Eigen::MatrixXd loads = parameterLoads(model, x);
  s.force = axis.dot(probeGradient);
  // The contact law's stiffness is κ = 1e3 E h (mechanics/terms/ContactTerm.cpp): the contact
  // energy, and F with it, scale with E and h explicitly too.
  const Material& mat = model.material();
  const double explicitPart[3] = {s.force / mat.youngModulus, 0.0, s.force / mat.thickness};
  double held[3];
  for (int k = 0; k < 3; ++k) held[k] = explicitPart[k] + adjoint.dot(loads.col(k));
  // The total derivative of F with the probe's centre, the tissue in equilibrium.
  const Vec3 dFdc = probeHessian.transpose() * axis - probeCoupling.transpose() * adjoint;
  s.dDepth = dFdc.dot(axis);

  // The depth counts from first contact with the turgid state, which θ moves too. The probe
  // comes along the line through the site's material point s (moving with the turgid state by
  // u_s) and stops at c0 = s + t a, touching the surface at q (moving by u_q) with unit normal
  // n_q = (c0 − q)/R: n_q·(c0 − q) = R gives n_q·(ds + dt a − u_q) = 0, so
  // dc0 = ds + a n_q·(u_q − ds)/(n_q·a), and the force at a given depth changes by dF/dc·dc0.
  const Points& xt = ind.turgidState();
  const Vec3 c0 = ind.placement().contactCenter;
  int triQ = -1;
  const Vec3 q = nearestSurfacePoint(model, xt, c0, &triQ);
  const int triS = ind.placement().triangle;
  if (triQ < 0 || triS < 0 || !((c0 - q).norm() > 0)) return s;
  const Vec3 nq = (c0 - q).normalized();
  if (!(std::abs(nq.dot(axis)) > 1e-6)) return s;
  const TurgidResponse own = turgid ? TurgidResponse{} : turgidResponse(ind);
  if (!(turgid ? *turgid : own).ok) return s;
  const Eigen::MatrixXd& ut = (turgid ? *turgid : own).u;
  // The motion of a material point of triangle `tri` at the point p of the turgid state.
  auto motion = [&](int tri, const Vec3& p, int k) {
    const auto& t = model.complex().triangles[tri];
    const Vec3 a = xt.col(t[0]), b = xt.col(t[1]), c = xt.col(t[2]);
    const Vec3 n = (b - a).cross(c - a);
    const double n2 = n.squaredNorm();
    Vec3 w((c - b).cross(p - b).dot(n) / n2, (a - c).cross(p - c).dot(n) / n2, 0.0);
    w[2] = 1.0 - w[0] - w[1];
    Vec3 m = Vec3::Zero();
    for (int j = 0; j < 3; ++j) m += w[j] * ut.col(k).segment<3>(3 * t[j]);
    return m;
  };
  const Vec3 site = ind.placement().site;
  // A site given as a material point moves with it; one given as a point in space is the
  // surface point nearest to it, which moves along the surface normal only (to first order).
  // Nearest to the target T: T − s = D n, so n·ds = n·u_s and the point slides by −D dn (the
  // triangle's normal turning with its vertices' motion), to first order.
  const bool material = ind.settings().restSite.has_value();
  const auto& ts = model.complex().triangles[triS];
  const Vec3 e1 = xt.col(ts[1]) - xt.col(ts[0]), e2 = xt.col(ts[2]) - xt.col(ts[0]);
  const Vec3 area2 = e1.cross(e2);
  const Vec3 ns = area2.normalized();
  const double D = material || !ind.settings().site ? 0.0 : (*ind.settings().site - site).dot(ns);
  double total[3];
  for (int k = 0; k < 3; ++k) {
    const Vec3 us = motion(triS, site, k), uq = motion(triQ, q, k);
    Vec3 ds = us;
    if (!material) {
      auto v = [&](int j) { return Vec3(ut.col(k).segment<3>(3 * ts[j])); };
      const Vec3 dArea = (v(1) - v(0)).cross(e2) + e1.cross(v(2) - v(0));
      const Vec3 dn = (dArea - ns * ns.dot(dArea)) / area2.norm();
      ds = ns * ns.dot(us) - D * dn;
    }
    const Vec3 dc0 = ds + axis * (nq.dot(uq - ds) / nq.dot(axis));
    total[k] = held[k] + dFdc.dot(dc0);
  }
  s.dE = total[0];
  s.dp = total[1];
  s.dh = total[2];
  s.ok =
      std::isfinite(s.dE) && std::isfinite(s.dp) && std::isfinite(s.dh) && std::isfinite(s.dDepth);
  return s;
}

}  // namespace tp
