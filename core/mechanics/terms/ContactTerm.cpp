#include "mechanics/terms/ContactTerm.h"

#include <cmath>
#include <stdexcept>

#include "mechanics/Model.h"
#include "mechanics/terms/Terms.h"

namespace tp {

ContactTerm::ContactTerm(const TermContext& c) : cc_(c.complex), topo_(c.topology) {
  law_.stiffness = 1e3 * c.material.youngModulus * c.material.thickness;
  law_.smoothing = 1e-3 * c.meanEdge;
}

void ContactTerm::setProbe(const Probe& probe) {
  if (!(probe.radius > 0) || !probe.center.allFinite())
    throw std::invalid_argument("probe radius must be positive and its centre finite");
  probe_ = probe;
}

// The outer triangles whose bounding box, grown by the radius, holds the probe's centre.
template <class Fn>
void ContactTerm::forNearTriangles(const Points& x, Fn&& fn) const {
  if (!probe_) return;
  const Vec3 p = probe_->center;
  const double r = probe_->radius;
  for (int t : topo_.outerTriangles) {
    const auto& tri = cc_.triangles[t];
    const Vec3 a = x.col(tri[0]), b = x.col(tri[1]), c = x.col(tri[2]);
    const Vec3 lo = a.cwiseMin(b).cwiseMin(c).array() - r;
    const Vec3 hi = a.cwiseMax(b).cwiseMax(c).array() + r;
    if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
    fn(t, a, b, c);
  }
}

double ContactTerm::evaluate(const Points& x, const EvalOptions& o, TermSink& sink) const {
  Evaluation& out = *sink.out;
  double* load = out.loadGradient.data();
  double energy = 0;
  Vec12 g12;
  Mat12 H12;
  forNearTriangles(x, [&](int t, const Vec3& a, const Vec3& b, const Vec3& c) {
    const double w = sphereTriangleEnergy(law_, probe_->center, probe_->radius, a, b, c, &g12,
                                          o.hessian ? &H12 : nullptr);
    if (w == 0.0 && g12.isZero()) return;
    if (o.hessian && o.projectContact) H12 = positivePart(H12);
    ++out.contactTriangles;
    energy += w;
    const Vec9 gx = g12.tail<9>();
    const Mat9 Hx = H12.bottomRightCorner<9, 9>();
    scatterElement<9>(&layout_->triangleVerts[3 * t], layout_->triangleSlots.element(t), gx,
                      o.hessian ? &Hx : nullptr, sink.gradient, sink.hessian);
    const auto& tri = cc_.triangles[t];
    for (int i = 0; i < 9; ++i) load[3 * tri[i / 3] + i % 3] += gx[i];
    out.probeGradient += g12.head<3>();
    if (o.hessian) {
      out.probeHessian += H12.topLeftCorner<3, 3>();
      for (int i = 0; i < 9; ++i) out.probeCoupling.row(3 * tri[i / 3] + i % 3) += H12.block<1, 3>(3 + i, 0);
    }
  });
  out.contactProjected = o.hessian && o.projectContact;
  out.energy.magnitude += std::abs(energy);
  return energy;
}

double ContactTerm::energy(const Points& x, double& magnitude) const {
  double e = 0;
  forNearTriangles(x, [&](int, const Vec3& a, const Vec3& b, const Vec3& c) {
    e += sphereTriangleEnergy(law_, probe_->center, probe_->radius, a, b, c, nullptr, nullptr);
  });
  magnitude += std::abs(e);
  return e;
}

std::vector<int> ContactTerm::touched(const Points& x) const {
  std::vector<int> out;
  forNearTriangles(x, [&](int t, const Vec3& a, const Vec3& b, const Vec3& c) {
    // φ(g) > 0 exactly when the penetration g = r − d is positive (mechanics/Contact.h).
    if (sphereTriangleEnergy(law_, probe_->center, probe_->radius, a, b, c, nullptr, nullptr) > 0)
      out.push_back(t);
  });
  return out;
}

double ContactTerm::probeDistance(const Points& x) const {
  if (!probe_) return std::numeric_limits<double>::infinity();
  double d2 = std::numeric_limits<double>::infinity();
  for (int t : topo_.outerTriangles) {
    const auto& tri = cc_.triangles[t];
    d2 = std::min(d2, pointTriangleDistance2(probe_->center, x.col(tri[0]), x.col(tri[1]),
                                             x.col(tri[2]), nullptr, nullptr, nullptr));
  }
  return std::sqrt(d2);
}

double ContactTerm::stepBound(const Points& x, const Points& dx, const Vec3& dp) const {
  if (!probe_) return 1.0;
  const double clear = clearance();
  const Vec3& p = probe_->center;
  double bound = 1.0;
  for (int t : topo_.outerTriangles) {
    const auto& tri = cc_.triangles[t];
    double speed = 0;  // the largest vertex displacement relative to the probe over the step
    for (int k = 0; k < 3; ++k) speed = std::max(speed, (dx.col(tri[k]) - dp).norm());
    auto distanceAt = [&](double a) {
      return std::sqrt(pointTriangleDistance2(p + a * dp, x.col(tri[0]) + a * dx.col(tri[0]),
                                              x.col(tri[1]) + a * dx.col(tri[1]),
                                              x.col(tri[2]) + a * dx.col(tri[2]), nullptr,
                                              nullptr, nullptr));
    };
    double d = distanceAt(0.0);
    if (!(d > clear)) return 0.0;
    if (d - speed * bound >= clear) continue;  // cannot come within the clearance
    // Advance while the bound guarantees the clearance; stop once within 1 % of it (the
    // distance can then close at most 1 % of the clearance before the next check).
    double a = 0;
    for (int it = 0; it < 50 && a < bound; ++it) {
      const double gap = d - clear;
      if (gap <= 0.01 * clear) break;
      a = std::min(bound, a + gap / speed);
      d = distanceAt(a);
      if (!(d > clear)) {  // round-off at the clearance: step back inside the guarantee
        a = std::max(0.0, a - 0.01 * clear / speed);
        break;
      }
    }
    bound = std::min(bound, a);
  }
  return bound;
}

std::unique_ptr<EnergyTerm> makeContactTerm(const TermContext& c) {
  return std::make_unique<ContactTerm>(c);
}

}  // namespace tp
