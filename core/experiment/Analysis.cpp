#include "experiment/Analysis.h"

#include <cmath>
#include <limits>

namespace tp {

double hertzApparentModulus(const std::vector<CurvePoint>& curve, double probeRadius, double nu) {
  // F = c δ^{3/2}: c = Σ F δ^{3/2} / Σ δ³ minimises Σ (F − c δ^{3/2})².
  double num = 0, den = 0;
  for (const auto& p : curve) {
    if (!p.converged || p.unloading || !(p.depth > 0) || !std::isfinite(p.force)) continue;
    const double d15 = std::pow(p.depth, 1.5);
    num += p.force * d15;
    den += d15 * d15;
  }
  if (!(den > 0) || !(probeRadius > 0)) return std::numeric_limits<double>::quiet_NaN();
  const double c = num / den;
  return 3.0 * c * (1.0 - nu * nu) / (4.0 * std::sqrt(probeRadius));
}

double secantStiffness(const std::vector<CurvePoint>& curve) {
  for (auto it = curve.rbegin(); it != curve.rend(); ++it)
    if (it->converged && !it->unloading && it->depth > 0 && std::isfinite(it->force))
      return it->force / it->depth;
  return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace tp
