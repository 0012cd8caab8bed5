#pragma once
// The factories of the terms in this folder, listed in Registry.cpp. Each returns null when the
// term does not apply to the material (a bending model other than the chosen one).

#include <memory>

#include "mechanics/EnergyTerm.h"

namespace tp {

std::unique_ptr<EnergyTerm> makeMembraneTerm(const TermContext&);
std::unique_ptr<EnergyTerm> makeKoiterTerm(const TermContext&);
std::unique_ptr<EnergyTerm> makeHingeTerm(const TermContext&);
std::unique_ptr<EnergyTerm> makeLinearBendingTerm(const TermContext&);
std::unique_ptr<EnergyTerm> makePressureTerm(const TermContext&);
std::unique_ptr<EnergyTerm> makeContactTerm(const TermContext&);
std::unique_ptr<EnergyTerm> makePointForceTerm(const TermContext&);

}  // namespace tp
