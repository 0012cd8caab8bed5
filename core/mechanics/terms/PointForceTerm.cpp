#include "mechanics/terms/PointForceTerm.h"

#include <cmath>

#include "mechanics/Model.h"
#include "mechanics/terms/Terms.h"

namespace tp {

double PointForceTerm::evaluate(const Points& x, const EvalOptions&, TermSink& sink) const {
  double e = 0;
  for (const auto& [v, f] : forces_) {
    e -= f.dot(x.col(v));
    sink.out->energy.magnitude += std::abs(f.dot(x.col(v)));
    for (int k = 0; k < 3; ++k) {
      sink.gradient[3 * v + k] -= f[k];
      sink.out->loadGradient[3 * v + k] -= f[k];
    }
  }
  return e;
}

double PointForceTerm::energy(const Points& x, double& magnitude) const {
  double e = 0;
  for (const auto& [v, f] : forces_) {
    e -= f.dot(x.col(v));
    magnitude += std::abs(f.dot(x.col(v)));
  }
  return e;
}

std::unique_ptr<EnergyTerm> makePointForceTerm(const TermContext& c) {
  return std::make_unique<PointForceTerm>(c);
}

}  // namespace tp
