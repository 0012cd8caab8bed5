#include "mechanics/terms/PressureTerm.h"

#include <cmath>
#include <stdexcept>

#include "mechanics/Model.h"
#include "mechanics/Pressure.h"
#include "mechanics/terms/Terms.h"

namespace tp {

PressureTerm::PressureTerm(const TermContext& c)
    : cc_(c.complex), cellPressure_(c.complex.cellCount(), 0.0) {}

void PressureTerm::setCellPressures(std::vector<double> pressures) {
  if (static_cast<int>(pressures.size()) != cc_.cellCount())
    throw std::invalid_argument("setCellPressures: expected one pressure per cell");
  for (double p : pressures)
    if (!std::isfinite(p)) throw std::invalid_argument("setCellPressures: non-finite pressure");
  cellPressure_ = std::move(pressures);
  loads_.clear();
  for (int t = 0; t < cc_.triangleCount(); ++t) {
    const Wall& w = cc_.walls[cc_.triangleWall[t]];
    const double pin = w.cell >= 0 ? cellPressure_[w.cell] : 0.0;
    const double pout = w.neighbor >= 0 ? cellPressure_[w.neighbor] : 0.0;
    if (pin != pout) loads_.emplace_back(t, pin - pout);
  }
}

double PressureTerm::evaluate(const Points& x, const EvalOptions& o, TermSink& sink) const {
  Vec9 g;
  Mat9 H;
  double energy = 0;
  double* load = sink.out->loadGradient.data();
  for (const auto& [t, dp] : loads_) {
    const auto& tri = cc_.triangles[t];
    const double w = pressureEnergy(dp, x.col(tri[0]), x.col(tri[1]), x.col(tri[2]), &g,
                                    o.hessian ? &H : nullptr);
    energy += w;
    sink.out->energy.magnitude += std::abs(w);
    scatterElement<9>(&layout_->triangleVerts[3 * t], layout_->triangleSlots.element(t), g,
                      o.hessian ? &H : nullptr, sink.gradient, sink.hessian);
    for (int i = 0; i < 9; ++i) load[3 * tri[i / 3] + i % 3] += g[i];
  }
  return energy;
}

double PressureTerm::energy(const Points& x, double& magnitude) const {
  double e = 0;
  for (const auto& [t, dp] : loads_) {
    const auto& tri = cc_.triangles[t];
    const double w = pressureEnergy(dp, x.col(tri[0]), x.col(tri[1]), x.col(tri[2]), nullptr, nullptr);
    e += w;
    magnitude += std::abs(w);
  }
  return e;
}

std::unique_ptr<EnergyTerm> makePressureTerm(const TermContext& c) {
  return std::make_unique<PressureTerm>(c);
}

}  // namespace tp
