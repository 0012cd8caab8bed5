#pragma once
// Point loads f (µN) on vertices: W = −Σ f·x (pJ).

#include <utility>
#include <vector>

#include "mechanics/EnergyTerm.h"

namespace tp {

class PointForceTerm final : public EnergyTerm {
 public:
  explicit PointForceTerm(const TermContext&) {}
  std::string name() const override { return "point forces"; }
  EnergyPart part() const override { return EnergyPart::External; }
  bool isLoad() const override { return true; }
  double evaluate(const Points& x, const EvalOptions& o, TermSink& sink) const override;
  double energy(const Points& x, double& magnitude) const override;
  void setForces(std::vector<std::pair<int, Vec3>> forces) { forces_ = std::move(forces); }

 private:
  std::vector<std::pair<int, Vec3>> forces_;
};

}  // namespace tp
