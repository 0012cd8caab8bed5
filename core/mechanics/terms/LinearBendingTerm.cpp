// Linear bending (Volino & Magnenat-Thalmann 2006, the bending vector of each hinge), the model
// of the published study (mechanics/Bending.h). Units: µm, pJ.
#include "mechanics/terms/HingeElements.h"
#include "mechanics/terms/Terms.h"

namespace tp {

namespace {

class LinearBendingTerm final
    : public HingeElementTerm<LinearBendingRest, linearBendingRest, linearBendingEnergy> {
 public:
  using HingeElementTerm::HingeElementTerm;
  std::string name() const override { return "linear bending"; }
};

}  // namespace

std::unique_ptr<EnergyTerm> makeLinearBendingTerm(const TermContext& c) {
  if (c.material.bending != BendingModel::Linear) return nullptr;
  return std::make_unique<LinearBendingTerm>(c);
}

}  // namespace tp
