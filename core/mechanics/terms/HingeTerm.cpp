// Discrete-shell hinge bending (Grinspun et al. 2003, with rest angles), calibrated to the
// plate rigidity D on a cylinder; no Poisson coupling (mechanics/Bending.h). Units: µm, pJ.
#include "mechanics/terms/HingeElements.h"
#include "mechanics/terms/Terms.h"

namespace tp {

namespace {

class HingeTerm final : public HingeElementTerm<HingeRest, hingeRest, hingeEnergy> {
 public:
  using HingeElementTerm::HingeElementTerm;
  std::string name() const override { return "hinge bending"; }
};

}  // namespace

std::unique_ptr<EnergyTerm> makeHingeTerm(const TermContext& c) {
  if (c.material.bending != BendingModel::Hinge) return nullptr;
  return std::make_unique<HingeTerm>(c);
}

}  // namespace tp
